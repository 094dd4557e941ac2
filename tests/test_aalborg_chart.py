"""The modelled Aalborg chart: land/water, a partition of the water by depth areas, honesty
about being modelled, a 5 m draught confined to the fairway in the narrow stretch, and a
byte-identical regeneration."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point, shape
from shapely.ops import unary_union

from colregs9_cli.geo import LocalFrame

from fixture_files import MODELLED_CHART, ROOT

SCRIPT = ROOT / "scripts" / "make_aalborg_chart.py"
FRAME = LocalFrame.centred_on(57.044196, 57.062865, 9.909933, 9.971545)  # region R


def _metric(geom: shapely.Geometry) -> shapely.Geometry:
    def project(lon_lat: np.ndarray) -> np.ndarray:
        north_m, east_m = FRAME.to_local(lon_lat[:, 1], lon_lat[:, 0])
        return np.column_stack([east_m, north_m])

    return shapely.transform(geom, project)


@pytest.fixture(scope="module")
def chart() -> dict:
    return json.loads(MODELLED_CHART.read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def layers(chart: dict) -> dict[str, list[tuple[float | None, shapely.Geometry]]]:
    out: dict[str, list[tuple[float | None, shapely.Geometry]]] = {}
    for feature in chart["features"]:
        props = feature["properties"]
        out.setdefault(props["OBJL"], []).append((props["DRVAL1"], shape(feature["geometry"])))
    return out


def _land(layers) -> shapely.Geometry:
    return unary_union([g for _, g in layers["LNDARE"]])


def _navigable(layers, draught_m: float) -> shapely.Geometry:
    """The raw union from the file: no closing of seams, so any gap between areas would show."""
    deep = [g for objl in ("DEPARE", "DRGARE") for d, g in layers[objl] if d >= draught_m]
    return unary_union(deep)


def _holes(geom: shapely.Geometry) -> list[shapely.Geometry]:
    return [shapely.Polygon(ring) for part in shapely.get_parts(geom) for ring in part.interiors]


def test_chart_says_it_is_modelled(chart: dict) -> None:
    assert chart["metadata"]["modelled"] is True
    assert chart["metadata"]["surveyed"] is False
    assert "not surveyed" in chart["metadata"]["note"].lower()
    assert {f["properties"]["source"] for f in chart["features"]} == {
        "MODELLED - not surveyed, not for navigation"
    }
    sources = (ROOT / "fixtures" / "SOURCES.md").read_text(encoding="utf-8")
    assert "aalborg_modelled.geojson" in sources and "MODELLED, not surveyed" in sources


def test_attributes_follow_s57(chart: dict) -> None:
    for feature in chart["features"]:
        props = feature["properties"]
        assert props["OBJL"] in {"LNDARE", "DEPARE", "DRGARE"}
        if props["OBJL"] == "LNDARE":
            assert props["DRVAL1"] is None and props["DRVAL2"] is None
        else:
            assert 0.0 <= props["DRVAL1"] < props["DRVAL2"]


@pytest.mark.parametrize(
    ("lat_deg", "lon_deg", "is_land"),
    [
        (57.0460, 9.9200, True),  # Aalborg city centre, south of the fjord
        (57.0650, 9.9250, True),  # Nørresundby, north of the fjord
        (57.0535, 9.9250, False),  # mid-fjord east of Limfjordsbroen, in region R
        (57.0515, 9.9360, False),  # mid-fjord in the bend, in region R
    ],
)
def test_land_and_water(layers, lat_deg: float, lon_deg: float, is_land: bool) -> None:
    point = Point(lon_deg, lat_deg)
    assert _land(layers).contains(point) is is_land
    water = unary_union([g for objl in ("DEPARE", "DRGARE") for _, g in layers[objl]])
    assert water.contains(point) is not is_land


def test_chart_covers_region_r(chart: dict) -> None:
    everything = unary_union([shape(f["geometry"]) for f in chart["features"]])
    region_r = shapely.box(9.909933, 57.044196, 9.971545, 57.062865)
    # land and depth areas tile the chart box exactly, region R included
    assert _metric(region_r.difference(everything)).area < 1e-3


def test_depth_areas_partition_the_water(layers) -> None:
    land = _metric(_land(layers))
    areas = [_metric(g) for objl in ("DEPARE", "DRGARE") for _, g in layers[objl]]
    box_m = _metric(shapely.box(9.85, 57.02, 9.998, 57.09))
    water = box_m.difference(land)
    overlap_m2 = sum(
        areas[i].intersection(areas[j]).area
        for i in range(len(areas))
        for j in range(i + 1, len(areas))
    )
    covered = unary_union(areas)
    # one noding of all boundaries on a 1e-7° grid: neighbours share their edges vertex for
    # vertex, so nothing overlaps and nothing is left between them (the fjord is ~9.6 km²)
    assert overlap_m2 < 1.0
    assert sum(a.area for a in areas) == pytest.approx(covered.area, abs=1.0)
    assert water.difference(covered).area < 1.0
    assert covered.intersection(land).area < 1.0
    assert _holes(covered) == []  # the chart has no islands: every hole would be a seam
    assert water.area > 8.0e6


@pytest.mark.parametrize("draught_m", [0.5, 2.0, 3.2, 5.0])
def test_navigable_water_has_no_seams(layers, draught_m: float) -> None:
    # Before the areas were noded together, per-area rounding left 63 seams (0.003–21 m²,
    # up to 650 m long) between them, which the navigable water at 0.5 m inherited as holes.
    nav = _metric(_navigable(layers, draught_m).difference(_land(layers)))
    assert _holes(nav) == []
    # the pieces are the fjord and harbour basins, none a sliver
    assert min(part.area for part in shapely.get_parts(nav)) > 50.0


def _navigable_length_m(layers, draught_m: float, section: LineString) -> tuple[float, float]:
    nav = _metric(_navigable(layers, draught_m))
    fairway = _metric(unary_union([g for _, g in layers["DRGARE"]]))
    line = _metric(section)
    return line.intersection(nav).length, line.intersection(fairway).length


def test_five_metre_draught_confined_to_fairway_in_the_narrow_stretch(layers) -> None:
    # a north–south section east of Limfjordsbroen, inside region R (shore to shore ~440 m)
    section = LineString([(9.9250, 57.0490), (9.9250, 57.0590)])
    navigable_m, fairway_m = _navigable_length_m(layers, 5.0, section)
    assert 100.0 < fairway_m < 160.0
    assert navigable_m == pytest.approx(fairway_m, abs=1.0)


def test_five_metre_draught_has_room_where_the_fjord_widens(layers) -> None:
    # a west–east section across the arm north-east of region R (shore to shore ~1 km)
    section = LineString([(9.9550, 57.0750), (9.9950, 57.0750)])
    navigable_m, fairway_m = _navigable_length_m(layers, 5.0, section)
    assert navigable_m > 600.0
    assert navigable_m > 3.0 * fairway_m


@pytest.mark.parametrize(
    ("drval1_m", "near_m", "far_m"),
    [(0.0, 0.0, 15.0), (2.0, 15.0, 35.0), (4.0, 35.0, None), (6.0, 100.0, None)],
)
def test_depth_bands_by_distance_from_land(
    layers, drval1_m: float, near_m: float, far_m: float | None
) -> None:
    land = _metric(_land(layers))
    (band,) = [_metric(g) for d, g in layers["DEPARE"] if d == drval1_m]
    # simplification moves an edge by up to SIMPLIFY_M = 2 m (+ the 1e-7° grid)
    assert band.distance(land) > near_m - 2.5
    if far_m is not None:
        assert band.hausdorff_distance(band.intersection(land.buffer(far_m + 2.5))) < 0.01


def test_file_is_small_and_regenerates_identically(tmp_path: Path) -> None:
    assert MODELLED_CHART.stat().st_size < 1_000_000
    out = tmp_path / "chart.geojson"
    subprocess.run([sys.executable, str(SCRIPT), str(out)], check=True, cwd=ROOT)
    assert out.read_bytes() == MODELLED_CHART.read_bytes()


def test_chart_loader_reads_the_modelled_chart() -> None:
    from colregs9_cli.charts.water import load_chart

    chart = load_chart([MODELLED_CHART], FRAME)
    assert chart.depth_range_m() == (0.0, 8.0)
    narrow = _metric(LineString([(9.9250, 57.0490), (9.9250, 57.0590)]))
    wide = _metric(LineString([(9.9550, 57.0750), (9.9950, 57.0750)]))
    navigable = chart.navigable_water(5.0)
    assert 100.0 < narrow.intersection(navigable).length < 160.0
    assert wide.intersection(navigable).length > 600.0
    # The section crosses 587 m of water. Own ship's 0.5 m draught has all of it but the
    # 0–2 m margins, 15 m wide; the paper's mean draught 3.2 m loses the 2–4 m band as well,
    # out to 35 m (more along this section, which meets the shores obliquely).
    assert 540.0 < narrow.intersection(chart.navigable_water(0.5)).length < 587.0 - 2 * 15.0
    assert 440.0 < narrow.intersection(chart.navigable_water(3.2)).length < 587.0 - 2 * 35.0
