"""Whether a vessel's draught confines her to the channel she proceeds along
(``charts/channel_confinement.py``, ``core/channel_audit.confined_to_channel``): hand-worked
synthetic cuts, and the San Diego main channel checked against the cell's depth areas read
with GDAL directly."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyogrio
import pytest
import shapely

from colregs9_cli.charts.channel_confinement import water_beyond_limits
from colregs9_cli.charts.channels import Channels, load_channels
from colregs9_cli.charts.water import load_chart
from colregs9_cli.core.audit import Fact
from colregs9_cli.core.channel_audit import (
    ChannelAuditParams,
    DraughtOnChart,
    vessel_in_channel,
)
from colregs9_cli.core.vessel_defaults import VesselDimensions
from colregs9_cli.errors import ParameterError
from colregs9_cli.geo import LocalFrame

from fixture_files import SANDIEGO_ENC
from geojson_charts import write_chart

FRAME = LocalFrame(55.0, 10.0)
PARAMS = ChannelAuditParams()
# A dredged cut 200 m wide, 12 m deep, running north-south on x = 0.
CUT = ({"OBJL": "DRGARE", "OBJNAM": "Cut", "DRVAL1": 12.0}, shapely.box(-100, -3000, 100, 3000))


def _cut_chart(tmp_path: Path, *banks: tuple[dict[str, Any], Any]) -> tuple[Any, Channels]:
    path = write_chart(tmp_path / "cut.geojson", FRAME, *banks, CUT)
    chart = load_chart([path], frame=FRAME)
    return chart, load_channels(chart)


def _bank(depth_m: float, west_m: float, east_m: float) -> tuple[dict[str, Any], Any]:
    return {"OBJL": "DEPARE", "DRVAL1": depth_m}, shapely.box(west_m, -3000, east_m, 3000)


def _land(west_m: float, east_m: float) -> tuple[dict[str, Any], Any]:
    return {"OBJL": "LNDARE"}, shapely.box(west_m, -3000, east_m, 3000)


def _vessel(length_m: float, draught_m: float, defaulted: tuple[str, ...] = ()) -> Any:
    return VesselDimensions(length_m, length_m / 6.0, draught_m, defaulted, "")


def _judge(chart: Any, channels: Channels, east_m: float, course_deg: float, dims: Any) -> Any:
    """The fact and basis for a vessel 60 s along the cut at ``east_m``, 5 m/s."""
    t = np.arange(60, dtype=float)
    window = pd.DataFrame(
        {
            "own_north_m": 5.0 * t * np.cos(np.radians(course_deg)),
            "own_east_m": east_m + 5.0 * t * np.sin(np.radians(course_deg)),
            "own_cog_grid_deg": course_deg,
            "own_heading_grid_deg": course_deg,
        }
    )
    return vessel_in_channel(
        window, "own_", channels, 59, True, 1.0, PARAMS, DraughtOnChart(chart, dims, 0.5)
    ).confined


def test_a_deep_draught_ship_in_a_cut_through_shoals_is_confined(tmp_path: Path) -> None:
    # 4 m banks either side of the 12 m cut, land 900 m east of it.
    chart, channels = _cut_chart(tmp_path, _bank(4.0, -3000, 1000), _land(1000, 3000))
    ship = _judge(chart, channels, 20.0, 0.0, _vessel(150.0, 9.5))
    assert ship.fact is Fact.TRUE
    assert ship.basis == (
        "along Cut; water navigable for her draught 9.5 m + UKC 0.5 m reaches 0 m beyond its "
        "port-hand limit and 0 m beyond its starboard-hand limit (confined under 150 m, 1 of "
        "her length)"
    )
    # Southbound, the same: port and starboard swap, both still shut.
    assert _judge(chart, channels, -20.0, 180.0, _vessel(150.0, 9.5)).fact is Fact.TRUE
    # A 3 m draught finds the banks navigable for miles: not confined.
    coaster = _judge(chart, channels, 20.0, 0.0, _vessel(150.0, 3.0))
    assert coaster.fact is Fact.FALSE
    assert "150 m or more beyond its port-hand limit" in coaster.basis


def test_a_bank_narrower_than_her_length_confines_her(tmp_path: Path) -> None:
    # West of the cut 100 m of 5 m water, then a 1 m flat; east 50 m of it, then land.
    chart, channels = _cut_chart(
        tmp_path,
        _bank(1.0, -3000, -200),
        _bank(5.0, -200, 150),
        _land(150, 3000),
    )
    long_ship = _judge(chart, channels, 0.0, 0.0, _vessel(120.0, 4.0))
    assert long_ship.fact is Fact.TRUE
    assert "reaches 100 m beyond its port-hand limit and 50 m beyond its starboard" in (
        long_ship.basis
    )
    # An 80 m vessel could leave to the west, where the bank is wider than she is long.
    assert _judge(chart, channels, 0.0, 0.0, _vessel(80.0, 4.0)).fact is Fact.FALSE
    # The room asked is a [replay] key, in her lengths.
    assert ChannelAuditParams(channel_confined_within_lengths=0.5).channel_confined_within_lengths
    with pytest.raises(ParameterError, match="channel_confined_within_lengths"):
        ChannelAuditParams(channel_confined_within_lengths=0.0)


def test_what_cannot_be_judged(tmp_path: Path) -> None:
    chart, channels = _cut_chart(tmp_path, _bank(4.0, -3000, 3000))
    # No reported draught: the estimator's defaults are not evidence of a draught.
    unknown = _judge(chart, channels, 0.0, 0.0, _vessel(150.0, 9.5, ("draught_m",)))
    assert unknown.fact is Fact.INSUFFICIENT and unknown.basis.endswith("draught not reported")
    # Deeper than the cut: her position is not navigable for her on this chart.
    aground = _judge(chart, channels, 0.0, 0.0, _vessel(150.0, 12.0))
    assert aground.fact is Fact.INSUFFICIENT and "not in water navigable" in aground.basis
    # Crossing the cut: the question does not arise.
    crossing = _judge(chart, channels, -150.0, 90.0, _vessel(150.0, 9.5))
    assert crossing.fact is None and crossing.basis == "not proceeding along a charted channel"
    # No chart's depths with the channels: not judged.
    bare = vessel_in_channel(
        pd.DataFrame(
            {
                "own_north_m": [0.0, 5.0],
                "own_east_m": [0.0, 0.0],
                "own_cog_grid_deg": 0.0,
                "own_heading_grid_deg": 0.0,
            }
        ),
        "own_",
        channels,
        1,
        True,
        1.0,
        PARAMS,
        DraughtOnChart(None, _vessel(150.0, 9.5), 0.5),
    )
    assert bare.confined.fact is Fact.INSUFFICIENT and bare.confined.basis.endswith("charted")


def test_water_that_runs_off_the_chart_is_not_taken_as_a_shoal(tmp_path: Path) -> None:
    # The cut runs along the eastern edge of the chart's coverage: what lies east of it is
    # not charted, so the starboard side is unknown; the port side is shut.
    path = write_chart(
        tmp_path / "edge.geojson",
        FRAME,
        _bank(4.0, -3000, 3000),
        (
            {"OBJL": "DRGARE", "OBJNAM": "Edge", "DRVAL1": 12.0},
            shapely.box(2800, -3000, 3000, 3000),
        ),
    )
    chart = load_chart([path], frame=FRAME)
    channels = load_channels(chart)
    beyond = water_beyond_limits(channels, chart, 0.0, 2900.0, 0, 0.0, 9.5, 0.5, 150.0)
    assert beyond.port_m[0] == 0.0 and np.isnan(beyond.starboard_m[0])
    np.testing.assert_allclose(
        [beyond.channel_port_m[0], beyond.channel_starboard_m[0]], [100.0, 100.0], atol=0.5
    )
    found = _judge(chart, channels, 2900.0, 0.0, _vessel(150.0, 9.5))
    assert found.fact is Fact.INSUFFICIENT and found.basis.endswith("reaches the chart's edge")
    assert "to the chart's edge beyond its starboard-hand limit" in found.basis


# -- the San Diego main channel, against the cell read with GDAL directly ------------------


@pytest.fixture(scope="module")
def sandiego() -> tuple[Any, Channels, int]:
    chart = load_chart([SANDIEGO_ENC])
    channels = load_channels(chart)
    (index,) = [i for i, c in enumerate(channels) if c.name == "San Diego Harbor Channel"]
    return chart, channels, index


def _depth_at(lon_lat: np.ndarray) -> np.ndarray:
    """The least depth (DRVAL1) charted at each point by the cell's DEPARE and DRGARE, read
    with GDAL (updates applied), -inf on land; NaN where nothing is charted."""
    depth = np.full(len(lon_lat), np.nan)
    points = shapely.points(lon_lat)
    for layer in ("DEPARE", "DRGARE"):
        meta, _, wkb, fields = pyogrio.raw.read(SANDIEGO_ENC, layer=layer, UPDATES="APPLY")
        drval1 = np.asarray(fields[list(meta["fields"]).index("DRVAL1")], dtype=float)
        for geometry, least_m in zip(shapely.from_wkb(wkb), drval1, strict=True):
            if shapely.get_type_id(geometry) not in (3, 6):  # polygons only
                continue
            inside = shapely.intersects(geometry, points)
            here = depth[inside]
            depth[inside] = np.where(np.isnan(here), least_m, np.minimum(here, least_m))
    _, _, wkb, _ = pyogrio.raw.read(SANDIEGO_ENC, layer="LNDARE", UPDATES="APPLY")
    for geometry in shapely.from_wkb(wkb):
        depth[shapely.intersects(geometry, points)] = -np.inf
    return depth


def _first_shallower_m(depth: np.ndarray, draught_m: float, steps_m: np.ndarray) -> np.ndarray:
    """Per row, the first step charted shallower than ``draught_m`` (inf where none is)."""
    shallow = ~(depth >= draught_m)
    return np.where(shallow.any(axis=1), steps_m[np.argmax(shallow, axis=1)], np.inf)


def test_sandiego_main_channel_confines_an_11_m_draught_where_the_chart_says_so(
    sandiego: tuple[Any, Channels, int],
) -> None:
    chart, channels, index = sandiego
    main = channels[index]
    at = shapely.get_coordinates(
        shapely.line_interpolate_point(main.axis, np.linspace(0.05, 0.65, 7), normalized=True)
    )
    north, east = at[:, 1], at[:, 0]
    assert (channels.channel_at(north, east) == index).all()
    direction = channels.axis_at(north, east, index).direction_grid_deg
    beyond = water_beyond_limits(channels, chart, north, east, index, direction, 11.0, 0.0, 300.0)
    # Every point of the outer reach: the 11 m water ends at the channel's limits.
    np.testing.assert_array_less(np.nan_to_num(beyond.port_m, nan=1e9), 1.0)
    np.testing.assert_array_less(np.nan_to_num(beyond.starboard_m, nan=1e9), 1.0)
    # GDAL, directly: walking out from her along the section, 2 m a step, the first point
    # charted shallower than 11 m (or land) comes at the channel's limit or inside it; for
    # 2 m, on at least one side, 50 m or more beyond it.
    radians = np.radians(direction)
    right = np.column_stack([np.cos(radians), -np.sin(radians)])
    steps_m = np.arange(0.0, 600.0, 2.0)
    room_2m = np.zeros(len(at))
    for limit_m, sign in ((beyond.channel_port_m, -1.0), (beyond.channel_starboard_m, 1.0)):
        xy = at[:, None, :] + sign * steps_m[None, :, None] * right[:, None, :]
        lat, lon = channels.frame.to_geodetic(xy[..., 1].ravel(), xy[..., 0].ravel())
        depth = _depth_at(np.column_stack([lon, lat])).reshape(len(at), len(steps_m))
        np.testing.assert_array_less(_first_shallower_m(depth, 11.0, steps_m), limit_m + 2.0)
        room_2m = np.fmax(room_2m, _first_shallower_m(depth, 2.0, steps_m) - limit_m)
    assert (room_2m >= 48.0).all()
    # A 2 m draught has room outside the channel at every one of these points.
    shallow = water_beyond_limits(channels, chart, north, east, index, direction, 2.0, 0.0, 50.0)
    assert ((shallow.port_m >= 50.0) | (shallow.starboard_m >= 50.0)).all()


# -- end to end: a deep-draught ship in a cut, a yacht crossing ahead of her ----------------

CUT_FRAME = LocalFrame(56.9, 11.4)


def _scenario(tmp_path: Path, ship_draught_m: float) -> Path:
    """A 150 m ship northbound up the axis of a 200 m cut through 4 m banks at 10 kn; a 15 m
    motor yacht crossing from her starboard side westbound at 8 kn, ahead of her. Under rule
    15 the ship gives way. Arcs of a 400 m radius (a fixed rate of swing of 0.36 deg/m at
    α 0.4) over 30 s keep the estimator's ship domains inside the cut, so that only her
    draught can restrict her."""
    chart = write_chart(
        tmp_path / "cut.geojson",
        CUT_FRAME,
        ({"OBJL": "DEPARE", "DRVAL1": 4.0}, shapely.box(-4000, -4000, 4000, 4000)),
        ({"OBJL": "DRGARE", "OBJNAM": "Cut", "DRVAL1": 12.0}, shapely.box(-100, -4000, 100, 4000)),
        box_m=4000.0,
    )

    def at(north_m: float, east_m: float) -> str:
        lat, lon = CUT_FRAME.to_geodetic(north_m, east_m)
        return f"[{float(lat):.7f}, {float(lon):.7f}]"

    path = tmp_path / f"cut_{ship_draught_m:g}.toml"
    path.write_text(
        f"""name = "cut"
description = "A ship in a dredged cut and a yacht crossing it."
start_utc = 2024-09-09T10:00:00Z
duration_s = 900.0
step_s = 1.0
ais_interval_s = 10.0
chart = "{chart.name}"

[[vessel]]
mmsi = 219600001
name = "DEEP"
callsign = "OXDP1"
length_m = 150.0
breadth_m = 24.0
draught_m = {ship_draught_m}
ship_type = "Cargo"
nav_status = 0
route = [{at(-3000.0, 0.0)}, {at(3000.0, 0.0)}]
speed_kn = 10.0

[[vessel]]
mmsi = 219600002
name = "YACHT"
callsign = "OXYT2"
length_m = 15.0
breadth_m = 4.0
draught_m = 1.5
ship_type = "Pleasure"
nav_status = 0
route = [{at(150.0, 1500.0)}, {at(150.0, -1500.0)}]
speed_kn = 8.0
depart_s = 250.0
"""
    )
    return path


@pytest.mark.parametrize(("draught_m", "confined"), [(9.5, True), (3.0, False)])
def test_a_ship_her_draught_confines_to_a_cut_stands_on_under_rule_9(
    tmp_path: Path, draught_m: float, confined: bool
) -> None:
    from colregs9_cli.jobs.replay import run_replay
    from colregs9_cli.jobs.simulate import simulate_scenario

    ais = tmp_path / "cut.csv"
    simulate_scenario(_scenario(tmp_path, draught_m), ais)
    result = run_replay(
        [ais],
        chart_paths=[tmp_path / "cut.geojson"],
        plots=False,
        write=False,
        overrides={
            "manoeuvrability": {"swing_model": "fixed", "swing_deg_per_m": 0.36, "horizon_s": 30.0}
        },
    )
    (row,) = result.pairs_table.itertuples()
    assert (row.name_a, row.name_b, row.situation) == ("DEEP", "YACHT", "crossing")
    assert row.role_colregs_a == "give-way"  # the yacht is on her starboard side
    assert row.estimated_restricted_a == "false"  # her arcs fit in the cut
    assert row.channel_a == "Cut" and row.channel_relation_a == "along"
    assert row.confined_to_channel_a == ("true" if confined else "false")
    if confined:
        # d3 by the chart: the yacht crossing the cut shall not impede her (9(d)).
        assert row.automaton_path_b == "D1>D2>D3>D4"
        assert (row.rule9_clause, row.deciding_rule) == ("9(d)", "9")
        assert (row.role_final_a, row.role_final_b) == ("stand-on", "give-way")
    else:
        assert row.automaton_path_b == "D1>D2>D3>D1"
        assert row.deciding_rule == "15" and row.role_final_a == "give-way"
