"""``colregs9 chart --draught M --out FILE.gpkg``: the chart in WGS84 for QGIS, written by
GDAL, with every layer there and the navigable water of the verdicts."""

from __future__ import annotations

import json
import subprocess
import sys
import warnings
from pathlib import Path

import pyogrio
import pytest
import shapely
from pyproj import Geod

from colregs9_cli.charts.water import load_chart
from colregs9_cli.jobs.chartinfo import summarise_chart

from fixture_files import SANDIEGO_ENC


@pytest.fixture(scope="module")
def geopackage(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("gpkg") / "sandiego.gpkg"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "colregs9_cli",
            "chart",
            str(SANDIEGO_ENC),
            "--draught",
            "2",
            "--out",
            str(out),
            "--quiet",
        ],
        capture_output=True,
        text=True,
        check=False,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""  # no GDAL or Python warning
    assert "GeoPackage:" not in done.stdout  # the notice goes to stderr, dropped by --quiet
    return out


def test_every_layer_is_there_in_wgs84(geopackage: Path) -> None:
    layers = {str(name): kind for name, kind in pyogrio.list_layers(geopackage)}
    assert set(layers) == {
        "depth_areas",
        "coverage",
        "land",
        "navigable_water",
        "channels",
        "channel_axes",
    }
    for layer in layers:
        info = pyogrio.read_info(geopackage, layer=layer)
        assert info["crs"] == "EPSG:4326"
        assert info["features"] >= 1
    assert pyogrio.read_info(geopackage, layer="depth_areas")["features"] == 469
    assert "DRVAL1" in pyogrio.read_info(geopackage, layer="depth_areas")["fields"]


def test_the_navigable_water_is_the_charts(geopackage: Path) -> None:
    _, _, wkb, _ = pyogrio.raw.read(geopackage, layer="navigable_water")
    (water,) = shapely.from_wkb(wkb)
    area_m2, _ = Geod(ellps="WGS84").geometry_area_perimeter(water)
    expected_km2 = load_chart([SANDIEGO_ENC]).navigable_area_km2(2.0)
    assert abs(area_m2) / 1e6 == pytest.approx(expected_km2, rel=2e-3)


def _square_cell(path: Path, box: tuple[float, float, float, float], depth: float, **detail: int):
    lon0, lat0, lon1, lat1 = box
    ring = [[lon0, lat0], [lon1, lat0], [lon1, lat1], [lon0, lat1], [lon0, lat0]]
    polygon = {"type": "Polygon", "coordinates": [ring]}
    features = [
        {"type": "Feature", "properties": {"OBJL": "DEPARE", "DRVAL1": depth}, "geometry": polygon},
        {
            "type": "Feature",
            "properties": {"OBJL": "M_COVR", "CATCOV": 1, **detail},
            "geometry": polygon,
        },
    ]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


def test_overlapping_cells_show_which_decides_where(tmp_path: Path) -> None:
    # No land at all: the land layer is empty (no GDAL warning about a geometry collection in
    # a MultiPolygon layer); the coverage layer has one feature per chart with its rank, and
    # each depth area names its chart.
    coarse = _square_cell(tmp_path / "coarse.geojson", (9.98, 56.99, 10.02, 57.01), 5.4, INTU=3)
    harbour = _square_cell(
        tmp_path / "harbour.geojson", (9.995, 56.997, 10.005, 57.003), 3.6, INTU=5
    )
    out = tmp_path / "both.gpkg"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        summary = summarise_chart([coarse, harbour], draught_m=5.0, out=out, quiet=True)
    assert "the first decides: harbour.geojson > coarse.geojson" in summary.text
    assert pyogrio.read_info(out, layer="land")["features"] == 0
    _, _, wkb, (names, ranks) = pyogrio.raw.read(out, layer="coverage")
    assert list(names) == ["harbour.geojson", "coarse.geojson"] and list(ranks) == [1, 2]
    harbour_part, coarse_part = shapely.from_wkb(wkb)
    assert shapely.intersection(harbour_part, coarse_part).area < 1e-12  # deg², disjoint
    meta, _, wkb, fields = pyogrio.raw.read(out, layer="depth_areas")
    columns = dict(zip(meta["fields"], fields, strict=True))
    assert sorted(zip(columns["chart"], columns["DRVAL1"], strict=True)) == [
        ("coarse.geojson", 5.4),
        ("harbour.geojson", 3.6),
    ]
    # the 5 m water is the coarse square less the harbour square
    _, _, wkb, _ = pyogrio.raw.read(out, layer="navigable_water")
    (water,) = shapely.from_wkb(wkb)
    assert water.contains(shapely.Point(9.99, 57.0))
    assert not water.intersects(shapely.Point(10.0, 57.0))
