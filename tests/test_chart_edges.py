"""The edge of a chart is not the edge of the water: an ellipse that reaches past a chart's
coverage is "unknown", never red (restricted)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely

from colregs9_cli.charts.s57_classes import ChartLayer
from colregs9_cli.charts.sources import read_charts
from colregs9_cli.charts.water import Chart, load_chart
from colregs9_cli.core.manoeuvrability import (
    ManoeuvrabilityParams,
    Restriction,
    SwingModel,
    VesselState,
    assess_manoeuvrability,
)
from colregs9_cli.core.vessel_defaults import VesselDimensions
from colregs9_cli.errors import ChartError
from colregs9_cli.geo import LocalFrame

FRAME = LocalFrame(57.0, 10.0)
PARAMS = ManoeuvrabilityParams(swing_model=SwingModel.FIXED)
# The target: 50 m long, 9 m in the beam, 5 m draught, all as reported by AIS.
DIMS = VesselDimensions(50.0, 9.0, 5.0, defaulted=(), basis="")


def _deep_everywhere(tmp_path: Path) -> Path:
    """One depth area, 10 m deep, about 2 km square around the frame's origin."""
    ring = [[9.985, 56.992], [10.015, 56.992], [10.015, 57.008], [9.985, 57.008], [9.985, 56.992]]
    chart = {
        "type": "FeatureCollection",
        "features": [
            {
                "type": "Feature",
                "properties": {"OBJL": "DEPARE", "DRVAL1": 10.0, "DRVAL2": 20.0},
                "geometry": {"type": "Polygon", "coordinates": [ring]},
            }
        ],
    }
    path = tmp_path / "deep.geojson"
    path.write_text(json.dumps(chart), encoding="utf-8")
    return path


@pytest.fixture()
def chart(tmp_path: Path):
    return load_chart([_deep_everywhere(tmp_path)], FRAME)


def _edge_north_m(chart) -> float:
    return float(chart.coverage.bounds[3])


def test_a_target_at_rest_10_m_inside_the_edge_is_unknown_not_restricted(chart) -> None:
    north = _edge_north_m(chart) - 10.0
    result = assess_manoeuvrability(chart, VesselState(north, 0.0, 0.0, 0.0), DIMS, PARAMS)
    assert len(result.restricted) == 360
    # every ellipse crosses the water's boundary, which is the chart's edge: all were red
    # when only the centres were checked against the coverage
    assert result.restricted.all()
    assert not (result.restricted & result.covered).any()  # no red ellipse
    assert not result.covered.any()  # every ellipse reaches past the edge
    assert result.restriction is Restriction.UNKNOWN


def test_a_slow_target_along_the_edge_is_unknown_not_restricted(chart) -> None:
    # 0.5 m/s heading east, 10 m inside the north edge: 341 of 360 ellipses cross the edge
    # (all red before); the 19 that turn away from it far enough are wholly inside and blue.
    north = _edge_north_m(chart) - 10.0
    result = assess_manoeuvrability(chart, VesselState(north, 0.0, 90.0, 0.5), DIMS, PARAMS)
    assert result.restricted.sum() > 300
    assert not (result.restricted & result.covered).any()
    assert result.covered.any() and not result.restricted[result.covered].any()
    assert result.restriction is Restriction.UNKNOWN


def test_well_inside_a_deep_chart_is_clear(chart) -> None:
    result = assess_manoeuvrability(chart, VesselState(0.0, 0.0, 0.0, 0.0), DIMS, PARAMS)
    assert result.covered.all() and not result.restricted.any()
    assert result.restriction is Restriction.NOT_RESTRICTED


def test_moving_towards_the_edge_only_the_far_ellipses_are_uncovered(chart) -> None:
    north = _edge_north_m(chart) - 400.0
    result = assess_manoeuvrability(chart, VesselState(north, 0.0, 0.0, 3.0), DIMS, PARAMS)
    distance_to_edge = _edge_north_m(chart) - result.north_m
    # covered exactly where the whole ellipse (semi-axes 50 m and 13.5 m) is inside
    assert result.covered[distance_to_edge > 50.0 + 1.0].all()
    assert not result.covered[distance_to_edge < 13.5].any()
    assert not (result.restricted & result.covered).any()
    assert result.restriction is Restriction.UNKNOWN
    assert np.isfinite(result.north_m).all()


def _deep_square() -> Chart:
    """10 m everywhere in a 2 km square around the origin, in the frame (x east, y north)."""
    square = shapely.box(-1000.0, -1000.0, 1000.0, 1000.0)
    return Chart(
        frame=FRAME,
        depth_areas=np.array([square], dtype=object),
        drval1_m=np.array([10.0]),
        drval2_m=np.array([20.0]),
        kinds=np.array([ChartLayer.DEPARE], dtype=object),
        land=shapely.Polygon(),
        hazards=shapely.Polygon(),
        coverage=square,
    )


@pytest.mark.parametrize(
    ("north_m", "expected"),
    [(950.0, Restriction.UNKNOWN), (949.0, Restriction.NOT_RESTRICTED)],
)
def test_an_ellipse_touching_the_edge_from_inside_is_unknown(
    north_m: float, expected: Restriction
) -> None:
    # At rest heading north, a = 50 m: from 950 m the ellipse's bow vertex lies on the north
    # edge (1,000 m). It touches the chart's edge, so it is not wholly inside: unknown, not red.
    result = assess_manoeuvrability(
        _deep_square(), VesselState(north_m, 0.0, 0.0, 0.0), DIMS, PARAMS
    )
    assert result.restriction is expected
    assert not (result.restricted & result.covered).any()
    assert result.covered.all() == (expected is Restriction.NOT_RESTRICTED)


def _with_shoal(chart: Chart, shoal: shapely.Polygon) -> Chart:
    return Chart(
        frame=FRAME,
        depth_areas=np.array([shapely.difference(chart.coverage, shoal), shoal], dtype=object),
        drval1_m=np.array([10.0, 1.0]),
        drval2_m=np.array([20.0, 2.0]),
        kinds=np.array([ChartLayer.DEPARE, ChartLayer.DEPARE], dtype=object),
        land=shapely.Polygon(),
        hazards=shapely.Polygon(),
        coverage=chart.coverage,
    )


def test_a_red_ellipse_inside_the_chart_still_decides_when_others_reach_past_the_edge() -> None:
    # Heading north at 3 m/s from 800 m, her later ellipses reach past the north edge
    # (1,000 m); a 1 m shoal 10 m east of her track, inside the chart, makes the first
    # ellipses (half-width 13.5 m) red: the edge hides nothing that the chart does show.
    deep = _deep_square()
    clear = assess_manoeuvrability(deep, VesselState(800.0, 0.0, 0.0, 3.0), DIMS, PARAMS)
    assert (~clear.covered).any() and not clear.restricted[clear.covered].any()
    assert clear.restriction is Restriction.UNKNOWN
    shoal = _with_shoal(deep, shapely.box(10.0, 780.0, 80.0, 830.0))
    result = assess_manoeuvrability(shoal, VesselState(800.0, 0.0, 0.0, 3.0), DIMS, PARAMS)
    assert (result.restricted & result.covered).any()
    assert (~result.covered).any()
    assert result.restriction is Restriction.RESTRICTED


def test_a_depth_area_without_its_depth_is_an_error(tmp_path: Path) -> None:
    box = [[[10.0, 57.0], [10.1, 57.0], [10.1, 57.1], [10.0, 57.1], [10.0, 57.0]]]
    features = [
        {
            "type": "Feature",
            "properties": {"OBJL": "DEPARE", "DRVAL1": depth, "DRVAL2": 20.0},
            "geometry": {"type": "Polygon", "coordinates": box},
        }
        for depth in (10.0, None)
    ]
    path = tmp_path / "unknown_depth.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    with pytest.raises(ChartError, match="1 of 2 depth areas have no DRVAL1"):
        read_charts([path])


def _box_chart(path: Path, west: float, east: float) -> Path:
    ring = [[west, -17.05], [east, -17.05], [east, -16.95], [west, -16.95], [west, -17.05]]
    feature = {
        "type": "Feature",
        "properties": {"OBJL": "DEPARE", "DRVAL1": 10.0, "DRVAL2": 20.0},
        "geometry": {"type": "Polygon", "coordinates": [ring]},
    }
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path


def test_cells_on_both_sides_of_180_are_one_area(tmp_path: Path) -> None:
    from colregs9_cli.charts.water import project_charts

    east = _box_chart(tmp_path / "east.geojson", 179.8, 180.0)
    west = _box_chart(tmp_path / "west.geojson", -180.0, -179.8)
    source = read_charts([east, west])
    chart = project_charts(source)
    assert chart.frame.lon0_deg in (180.0, -180.0)
    # AIS just east of 180° keeps the cell that starts across it, a kilometre away.
    assert source.near([-17.0], [179.99], margin_deg=0.25).paths == (east, west)
    assert source.near([-17.0], [-179.99], margin_deg=0.25).paths == (east, west)
    assert source.near([-17.0], [170.0], margin_deg=0.25).paths == ()
    far = _box_chart(tmp_path / "far.geojson", 0.0, 0.2)
    with pytest.raises(ChartError, match="beyond 400 km"):
        project_charts(read_charts([east, west, far]))
