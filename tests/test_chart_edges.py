"""The edge of a chart is not the edge of the water: an ellipse that reaches past a chart's
coverage is "unknown", never red (restricted)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from colregs9_cli.chart import load_chart
from colregs9_cli.geo import LocalFrame
from colregs9_cli.manoeuvrability import ManoeuvrabilityParams, Restriction, assess_manoeuvrability

FRAME = LocalFrame(57.0, 10.0)
PARAMS = ManoeuvrabilityParams()


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
    result = assess_manoeuvrability(chart, north, 0.0, 0.0, 0.0, 50.0, 9.0, 5.0, PARAMS)
    assert len(result.restricted) == 360
    assert not (result.restricted & result.covered).any()  # no red ellipse
    assert not result.covered.any()  # every ellipse reaches past the edge
    assert result.restriction is Restriction.UNKNOWN


def test_well_inside_a_deep_chart_is_clear(chart) -> None:
    result = assess_manoeuvrability(chart, 0.0, 0.0, 0.0, 0.0, 50.0, 9.0, 5.0, PARAMS)
    assert result.covered.all() and not result.restricted.any()
    assert result.restriction is Restriction.NOT_RESTRICTED


def test_moving_towards_the_edge_only_the_far_ellipses_are_uncovered(chart) -> None:
    north = _edge_north_m(chart) - 400.0
    result = assess_manoeuvrability(chart, north, 0.0, 0.0, 3.0, 50.0, 9.0, 5.0, PARAMS)
    distance_to_edge = _edge_north_m(chart) - result.north_m
    # covered exactly where the whole ellipse (semi-axes 50 m and 13.5 m) is inside
    assert result.covered[distance_to_edge > 50.0 + 1.0].all()
    assert not result.covered[distance_to_edge < 13.5].any()
    assert not (result.restricted & result.covered).any()
    assert result.restriction is Restriction.UNKNOWN
    assert np.isfinite(result.north_m).all()
