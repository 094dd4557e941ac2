"""Charts users bring: depth areas with repairable rings, water outside the stated coverage,
draughts whose sum with the clearance is not exact in binary, GeoPackages in feet, and charts
that leave no depth area. Areas are checked against shapely in the same local frame (a 1 km
square is 1 km² there to better than 0.01 %)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyogrio
import pytest
import shapely
from typer.testing import CliRunner

from colregs9_cli.charts.water import load_chart
from colregs9_cli.cli import app
from colregs9_cli.errors import ChartError
from colregs9_cli.geo import LocalFrame

from fixture_files import ROOT

FRAME = LocalFrame(57.0, 10.5)
KM = 1000.0
ANNAPOLIS_ENC = ROOT / "fixtures" / "charts" / "noaa_enc_US5MD1MC.000"


def _ring(east_north: list[tuple[float, float]]) -> list[list[float]]:
    """Local (east, north) metres around the frame's origin, as lon/lat vertices."""
    lat, lon = FRAME.to_geodetic([n for _, n in east_north], [e for e, _ in east_north])
    return [[float(x), float(y)] for x, y in zip(lon, lat, strict=True)]


def _box(e0: float, n0: float, e1: float, n1: float) -> list[tuple[float, float]]:
    return [(e0, n0), (e1, n0), (e1, n1), (e0, n1), (e0, n0)]


def _chart(path: Path, features: list[tuple[dict[str, Any], list[tuple[float, float]]]]) -> Path:
    collection = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": properties,
                "geometry": {"type": "Polygon", "coordinates": [_ring(ring)]},
            }
            for properties, ring in features
        ],
    }
    path.write_text(json.dumps(collection))
    return path


DEEP = {"OBJL": "DEPARE", "DRVAL1": 10.0, "DRVAL2": 20.0}
# A 1 km square with a zero-width spike 300 m long on its top edge: GEOS repairs it into the
# square and a line, a geometry collection.
SPIKED = [(KM, 0), (2 * KM, 0), (2 * KM, KM), (1500, KM), (1500, 1300), (1500, KM), (KM, KM)]


def _water_km2(path: Path, draught_m: float = 5.0, ukc_m: float = 0.0) -> float:
    return load_chart([path], frame=FRAME).navigable_area_km2(draught_m, ukc_m)


def test_a_depth_area_with_a_spike_keeps_its_area(tmp_path: Path) -> None:
    spiked = [*SPIKED, SPIKED[0]]
    assert not shapely.is_valid(shapely.Polygon(spiked))
    two = _chart(tmp_path / "two.geojson", [(DEEP, _box(0, 0, KM, KM)), (DEEP, spiked)])
    assert _water_km2(two) == pytest.approx(2.0, rel=1e-4)  # was 1.0: the square was lost
    alone = _chart(tmp_path / "alone.geojson", [(DEEP, spiked)])
    assert _water_km2(alone) == pytest.approx(1.0, rel=1e-4)  # was a traceback (nanmin of none)


def test_the_water_ends_at_the_stated_coverage(tmp_path: Path) -> None:
    """A single chart's depth areas outside its M_COVR (or in a CATCOV 2 hole) are not water,
    as they are not where several charts are merged."""
    holed = _chart(
        tmp_path / "holed.geojson",
        [
            (DEEP, _box(0, 0, 2 * KM, 2 * KM)),
            ({"OBJL": "M_COVR", "CATCOV": 1}, _box(0, 0, 2 * KM, 2 * KM)),
            ({"OBJL": "M_COVR", "CATCOV": 2}, _box(500, 500, 1500, 1500)),
        ],
    )
    assert _water_km2(holed) == pytest.approx(3.0, rel=1e-4)  # was 4.0
    half = _chart(
        tmp_path / "half.geojson",
        [
            (DEEP, _box(0, 0, 2 * KM, 2 * KM)),
            ({"OBJL": "M_COVR", "CATCOV": 1}, _box(0, 0, KM, 2 * KM)),
        ],
    )
    chart = load_chart([half], frame=FRAME)
    water = chart.navigable_water(5.0)
    assert shapely.area(water) / 1e6 == pytest.approx(2.0, rel=1e-4)
    assert shapely.covers(shapely.buffer(chart.coverage, 1e-6), water)


@pytest.mark.parametrize(("draught_m", "ukc_m"), [(8.8, 0.3), (3.7, 0.4), (0.1, 0.2)])
def test_a_depth_equal_to_draught_plus_clearance_is_navigable(
    tmp_path: Path, draught_m: float, ukc_m: float
) -> None:
    """8.8 + 0.3 is 9.100000000000001 in binary: the areas charted 9.1 m deep were left out."""
    depth = {**DEEP, "DRVAL1": float(f"{draught_m + ukc_m:.1f}")}
    chart = _chart(tmp_path / "exact.geojson", [(depth, _box(0, 0, KM, KM))])
    assert _water_km2(chart, draught_m, ukc_m) == pytest.approx(1.0, rel=1e-4)


def test_the_annapolis_cell_at_8_8_m_plus_0_3_m_is_its_9_1_m_water() -> None:
    chart = load_chart([ANNAPOLIS_ENC])
    assert chart.navigable_area_km2(8.8, 0.3) == pytest.approx(chart.navigable_area_km2(9.1))
    assert chart.navigable_area_km2(9.1) > 0.5


def test_a_geopackage_whose_dsid_gives_feet_is_refused(tmp_path: Path) -> None:
    """As ``ogr2ogr -f GPKG`` writes a cell: its DSID as a table (as a .000 cell in feet is)."""
    chart = tmp_path / "feet.gpkg"
    square = shapely.to_wkb(np.array([shapely.Polygon(_ring(_box(0, 0, KM, KM)))]))
    depth = [np.array(["DEPARE"], dtype=object), np.array([10.0])]
    pyogrio.raw.write(
        chart,
        square,
        depth,
        fields=["OBJL", "DRVAL1"],
        layer="DEPARE",
        geometry_type="Polygon",
        crs="EPSG:4326",
        driver="GPKG",
    )
    dsid = [np.array([5]), np.array([12000]), np.array([3])]  # DUNI 3: feet
    pyogrio.raw.write(
        chart,
        None,
        dsid,
        fields=["DSID_INTU", "DSPM_CSCL", "DSPM_DUNI"],
        layer="DSID",
        driver="GPKG",
        append=True,
    )
    with pytest.raises(ChartError, match=r"feet.gpkg: the cell gives its depths in feet"):
        load_chart([chart])


def test_charts_that_leave_no_depth_area_where_each_decides_are_one_error(tmp_path: Path) -> None:
    """The detailed chart's only depth area lies outside its coverage, and the coarse chart's
    inside it: cut to where each decides, none is left (was a traceback)."""
    detailed = _chart(
        tmp_path / "detailed.geojson",
        [
            (DEEP, _box(0, 0, 2 * KM, 2 * KM)),
            ({"OBJL": "M_COVR", "CATCOV": 1, "INTU": 5}, _box(5 * KM, 5 * KM, 6 * KM, 6 * KM)),
        ],
    )
    coarse = _chart(tmp_path / "coarse.geojson", [(DEEP, _box(5 * KM, 5 * KM, 6 * KM, 6 * KM))])
    with pytest.raises(ChartError, match="no depth area is left where each chart decides"):
        load_chart([detailed, coarse], frame=FRAME)


def test_a_clearance_without_a_draught_is_refused() -> None:
    result = CliRunner().invoke(app, ["chart", str(ANNAPOLIS_ENC), "--ukc", "2"])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        "Error: --ukc 2 needs --draught M: the clearance is added to a draught; add --draught"
    ]


@pytest.mark.parametrize(
    "geometry",
    [
        {"type": "Polgon", "coordinates": [[[10.5, 57.0], [10.51, 57.0], [10.5, 57.01]]]},
        {"type": "Polygon", "coordinates": [10.5, 57.0]},
        None,
    ],
    ids=["misspelt type", "wrong nesting", "null"],
)
def test_land_without_a_readable_geometry_is_refused(
    tmp_path: Path, geometry: dict[str, Any] | None
) -> None:
    """GDAL reads such land as no geometry (and warns, quietly): the water would run over it."""
    path = _chart(tmp_path / "land.geojson", [(DEEP, _box(0, 0, KM, KM))])
    collection = json.loads(path.read_text())
    collection["features"].append(
        {"type": "Feature", "properties": {"OBJL": "LNDARE"}, "geometry": geometry}
    )
    path.write_text(json.dumps(collection))
    with pytest.raises(ChartError, match=r"1 land or hazard feature\(s\) \(LNDARE first\)"):
        load_chart([path], frame=FRAME)
