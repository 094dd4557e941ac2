"""``colregs9 chart --draught M --out FILE.gpkg``: the chart in WGS84 for QGIS, written by
GDAL, with every layer there and the navigable water of the verdicts."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pyogrio
import pytest
import shapely
from pyproj import Geod

from colregs9_cli.chart import load_chart

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
    assert f"GeoPackage: {out}" in done.stdout
    return out


def test_every_layer_is_there_in_wgs84(geopackage: Path) -> None:
    layers = {str(name): kind for name, kind in pyogrio.list_layers(geopackage)}
    assert set(layers) == {"depth_areas", "coverage", "land", "navigable_water"}
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
