"""Coverage is what a cell says it covers (M_COVR), and where cells overlap the more detailed
one decides the depth (navigational purpose, then compilation scale)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pyogrio
import pytest
import shapely

from colregs9_cli.chart import load_chart
from colregs9_cli.geo import LocalFrame

from fixture_files import SANDIEGO_ENC


def test_sandiego_coverage_is_its_m_covr() -> None:
    chart = load_chart([SANDIEGO_ENC])
    meta, _, wkb, fields = pyogrio.raw.read(SANDIEGO_ENC, layer="M_COVR")
    catcov = np.asarray(dict(zip(meta["fields"], fields, strict=True))["CATCOV"])
    polygons = shapely.from_wkb(wkb)
    expected = shapely.difference(
        shapely.union_all(polygons[catcov == 1]), shapely.union_all(polygons[catcov == 2])
    )

    def to_frame(xy: np.ndarray) -> np.ndarray:
        north, east = chart.frame.to_local(xy[:, 1], xy[:, 0])
        return np.column_stack([east, north])

    expected_m = shapely.transform(expected, to_frame)
    assert chart.coverage.area == pytest.approx(expected_m.area, rel=1e-9)
    assert shapely.symmetric_difference(chart.coverage, expected_m).area < 1.0  # m²


FRAME = LocalFrame(57.0, 10.0)


def _cell(tmp_path: Path, name: str, box: list[float], depth: float, purpose: int, scale: int):
    lon0, lat0, lon1, lat1 = box
    ring = [[lon0, lat0], [lon1, lat0], [lon1, lat1], [lon0, lat1], [lon0, lat0]]
    polygon = {"type": "Polygon", "coordinates": [ring]}
    features = [
        {
            "type": "Feature",
            "properties": {"OBJL": "DEPARE", "DRVAL1": depth, "DRVAL2": depth + 2.0},
            "geometry": polygon,
        },
        {
            "type": "Feature",
            "properties": {
                "OBJL": "M_COVR",
                "DRVAL1": None,
                "CATCOV": 1,
                "INTU": purpose,
                "CSCL": scale,
            },
            "geometry": polygon,
        },
    ]
    path = tmp_path / f"{name}.geojson"
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return path


@pytest.mark.parametrize("detailed_first", [True, False])
def test_overlapping_cells_resolve_to_the_detailed_one(
    tmp_path: Path, detailed_first: bool
) -> None:
    # A coarse approach cell says 5.4 m over a large square; a harbour cell inside it says 3.6 m.
    coarse = _cell(tmp_path, "coarse", [9.98, 56.99, 10.02, 57.01], 5.4, purpose=3, scale=80_000)
    harbour = _cell(
        tmp_path, "harbour", [9.995, 56.997, 10.005, 57.003], 3.6, purpose=5, scale=12_000
    )
    paths = [harbour, coarse] if detailed_first else [coarse, harbour]
    chart = load_chart(paths, FRAME)
    water = chart.navigable_water(5.0)
    # the harbour's water, charted at 3.6 m by the detailed cell, is not navigable at 5 m
    assert not shapely.contains_xy(water, 0.0, 0.0)
    # outside the harbour cell the coarse cell's 5.4 m counts
    assert shapely.contains_xy(water, 0.0, 900.0)
    # both together cover the coarse square; the harbour square is charted, shallow
    assert chart.covers(0.0, 0.0)[0] and chart.covers(0.0, 900.0)[0]
    harbour_only = load_chart([harbour], FRAME)
    assert chart.navigable_water(3.0).contains(harbour_only.coverage.buffer(-1.0))
