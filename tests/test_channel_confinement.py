"""Whether a vessel's draught confines her to the narrow channel she proceeds along
(``charts/channel_confinement.py``, ``core/confinement.py``): hand-worked synthetic cuts, the
San Diego main channel checked against the cell's depth areas read with GDAL directly, and a
replay in which the chart decides rule 9."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyogrio
import pytest
import shapely

from colregs9_cli.charts.channel_confinement import water_beyond_limits
from colregs9_cli.charts.channel_facts import ChannelRelation
from colregs9_cli.charts.channels import Channels, load_channels
from colregs9_cli.charts.water import load_chart
from colregs9_cli.core.audit import Fact
from colregs9_cli.core.channel_audit import ChannelAuditParams, vessel_in_channel
from colregs9_cli.core.confinement import DraughtOnChart
from colregs9_cli.core.vessel_defaults import VesselDimensions
from colregs9_cli.errors import ParameterError
from colregs9_cli.geo import LocalFrame

from fixture_files import SANDIEGO_ENC
from geojson_charts import write_chart

FRAME = LocalFrame(55.0, 10.0)
PARAMS = ChannelAuditParams()
# A dredged cut 200 m wide, 12 m deep, running north-south on x = 0.
CUT = ({"OBJL": "DRGARE", "OBJNAM": "Cut", "DRVAL1": 12.0}, shapely.box(-100, -3000, 100, 3000))


def _cut_chart(tmp_path: Path, *features: tuple[dict[str, Any], Any]) -> tuple[Any, Channels]:
    path = write_chart(tmp_path / "cut.geojson", FRAME, *features)
    chart = load_chart([path], frame=FRAME)
    return chart, load_channels(chart)


def _bank(depth_m: float, west_m: float, east_m: float) -> tuple[dict[str, Any], Any]:
    return {"OBJL": "DEPARE", "DRVAL1": depth_m}, shapely.box(west_m, -3000, east_m, 3000)


def _land(west_m: float, east_m: float) -> tuple[dict[str, Any], Any]:
    return {"OBJL": "LNDARE"}, shapely.box(west_m, -3000, east_m, 3000)


def _vessel(length_m: float, draught_m: float, defaulted: tuple[str, ...] = ()) -> Any:
    return VesselDimensions(length_m, length_m / 6.0, draught_m, defaulted, "")


def _passage(east_m: float, course_deg: float, seconds: int = 60) -> pd.DataFrame:
    """A vessel on a straight course at 5 m/s from (0, ``east_m``), a row a second."""
    t = np.arange(seconds, dtype=float)
    return pd.DataFrame(
        {
            "own_north_m": 5.0 * t * np.cos(np.radians(course_deg)),
            "own_east_m": east_m + 5.0 * t * np.sin(np.radians(course_deg)),
            "own_cog_grid_deg": course_deg,
            "own_heading_grid_deg": course_deg,
        }
    )


def _judge(
    chart: Any,
    channels: Channels,
    east_m: float,
    course_deg: float,
    dims: Any,
    params: ChannelAuditParams = PARAMS,
) -> Any:
    """Her place and confinement over 60 s (300 m) along her course from ``east_m``."""
    window = _passage(east_m, course_deg)
    return vessel_in_channel(
        window, "own_", channels, 59, True, 1.0, params, DraughtOnChart(chart, dims, 0.5)
    )


def test_a_deep_draught_ship_in_a_cut_through_shoals_is_confined(tmp_path: Path) -> None:
    # 4 m banks either side of the 12 m cut, land 900 m east of it.
    chart, channels = _cut_chart(tmp_path, _bank(4.0, -3000, 1000), _land(1000, 3000), CUT)
    ship = _judge(chart, channels, 20.0, 0.0, _vessel(150.0, 9.5)).confined
    assert ship.fact is Fact.TRUE
    assert ship.basis == (
        "along Cut, at 9 stations from the trigger to the closest approach: confined at 9 of "
        "the 9 judged; the water navigable for her draught 9.5 m + UKC 0.5 m reaches a median "
        "0 m beyond its port-hand limit and 0 m beyond its starboard-hand limit, the channel "
        "200 m wide for her (confined: under 150 m beyond both, 1× her length, in a channel "
        "under 750 m, 5× her length)"
    )
    assert _judge(chart, channels, -20.0, 180.0, _vessel(150.0, 9.5)).confined.fact is Fact.TRUE
    # A 3 m draught finds the banks navigable for miles: not confined.
    coaster = _judge(chart, channels, 20.0, 0.0, _vessel(150.0, 3.0)).confined
    assert coaster.fact is Fact.FALSE
    assert "150 m or more beyond its port-hand limit" in coaster.basis


def test_a_bank_narrower_than_her_length_confines_her(tmp_path: Path) -> None:
    # West of the cut 100 m of 5 m water, then a 1 m flat; east 50 m of it, then land.
    chart, channels = _cut_chart(
        tmp_path, _bank(1.0, -3000, -200), _bank(5.0, -200, 150), _land(150, 3000), CUT
    )
    north = _judge(chart, channels, 0.0, 0.0, _vessel(120.0, 4.0)).confined
    assert north.fact is Fact.TRUE
    assert "a median 100 m beyond its port-hand limit and 50 m beyond its starboard" in (
        north.basis
    )
    # Southbound the hands change over: the 50 m to the east is now on her port hand.
    south = _judge(chart, channels, 0.0, 180.0, _vessel(120.0, 4.0)).confined
    assert "a median 50 m beyond its port-hand limit and 100 m beyond its starboard" in (
        south.basis
    )
    # An 80 m vessel could leave to the west, where the bank is wider than she is long; so
    # could the 120 m one if half her length were room enough.
    assert _judge(chart, channels, 0.0, 0.0, _vessel(80.0, 4.0)).confined.fact is Fact.FALSE
    half = ChannelAuditParams(channel_confined_within_lengths=0.5)
    assert _judge(chart, channels, 0.0, 0.0, _vessel(120.0, 4.0), half).confined.fact is Fact.FALSE
    for key in ("channel_confined_within_lengths", "channel_narrow_within_lengths"):
        with pytest.raises(ParameterError, match=key):
            ChannelAuditParams(**{key: 0.0})


def test_a_wide_fairway_is_not_narrow_for_her(tmp_path: Path) -> None:
    # A fairway 2 km wide over 30 m water between 8 m shoals: no room outside it for 9.5 m,
    # but 2 km is more than five of her lengths, room to turn round in it.
    chart, channels = _cut_chart(
        tmp_path,
        _bank(8.0, -3000, 3000),
        ({"OBJL": "DEPARE", "DRVAL1": 30.0}, shapely.box(-1000, -3000, 1000, 3000)),
        ({"OBJL": "FAIRWY", "OBJNAM": "Wide"}, shapely.box(-1000, -3000, 1000, 3000)),
    )
    wide = _judge(chart, channels, 0.0, 0.0, _vessel(150.0, 9.5)).confined
    assert wide.fact is Fact.FALSE and "the channel 2000 m wide for her" in wide.basis
    # A 450 m ship: under five of her lengths, so narrow for her.
    assert _judge(chart, channels, 0.0, 0.0, _vessel(450.0, 9.5)).confined.fact is Fact.TRUE


def test_channel_areas_side_by_side_are_one_channel(tmp_path: Path) -> None:
    # A 400 m cut charted as two one-way fairways, inbound and outbound, through 4 m banks;
    # and a 12 m centre between 10.5 m dredged toes. The other half is no room outside.
    fairways = _cut_chart(
        tmp_path,
        _bank(4.0, -3000, 3000),
        ({"OBJL": "DEPARE", "DRVAL1": 12.0}, shapely.box(-200, -3000, 200, 3000)),
        ({"OBJL": "FAIRWY", "OBJNAM": "Inbound", "TRAFIC": 1}, shapely.box(-200, -3000, 0, 3000)),
        ({"OBJL": "FAIRWY", "OBJNAM": "Outbound", "TRAFIC": 2}, shapely.box(0, -3000, 200, 3000)),
    )
    inbound = _judge(*fairways, -100.0, 0.0, _vessel(150.0, 9.5))
    assert inbound.at_trigger.channel == "Inbound"
    assert inbound.confined.fact is Fact.TRUE and "400 m wide for her" in inbound.confined.basis
    toes = _cut_chart(
        tmp_path,
        _bank(4.0, -3000, 3000),
        (
            {"OBJL": "DRGARE", "OBJNAM": "Toe W", "DRVAL1": 10.5},
            shapely.box(-150, -3000, -100, 3000),
        ),
        CUT,
        ({"OBJL": "DRGARE", "OBJNAM": "Toe E", "DRVAL1": 10.5}, shapely.box(100, -3000, 150, 3000)),
    )
    centre = _judge(*toes, 0.0, 0.0, _vessel(150.0, 9.5)).confined
    assert centre.fact is Fact.TRUE and "300 m wide for her" in centre.basis


def test_she_is_judged_in_the_channel_she_was_in_at_the_trigger(tmp_path: Path) -> None:
    # The cut ends 150 m ahead of her, where a fairway 2 km wide opens over 30 m water: half
    # her way to the closest approach lies in it. The stations are those in the cut.
    chart, channels = _cut_chart(
        tmp_path,
        _bank(4.0, -3000, 3000),
        ({"OBJL": "DRGARE", "OBJNAM": "Cut", "DRVAL1": 12.0}, shapely.box(-100, -3000, 100, 150)),
        ({"OBJL": "DEPARE", "DRVAL1": 30.0}, shapely.box(-1000, 150, 1000, 3000)),
        ({"OBJL": "FAIRWY", "OBJNAM": "Wide"}, shapely.box(-1000, 150, 1000, 3000)),
    )
    found = _judge(chart, channels, 0.0, 0.0, _vessel(150.0, 9.5))
    assert found.at_trigger.channel == "Cut" and found.at_least_separation.channel == "Wide"
    assert found.confined.fact is Fact.TRUE
    assert "confined at 9 of the 9 judged" in found.confined.basis
    assert "the channel 200 m wide for her" in found.confined.basis


def test_one_wreck_abeam_does_not_decide(tmp_path: Path) -> None:
    # 30 m water east of the cut, open; an unsounded wreck 60 m east of her track, inside the
    # cut, abeam of her at the trigger only: one station of nine is shut, the rest open.
    wreck = ({"OBJL": "WRECKS"}, shapely.box(55, -5, 65, 5))
    chart, channels = _cut_chart(
        tmp_path, _bank(4.0, -3000, 100), _bank(30.0, 100, 3000), CUT, wreck
    )
    found = _judge(chart, channels, 0.0, 0.0, _vessel(150.0, 9.5)).confined
    assert found.fact is Fact.FALSE and "confined at 1 of the 9 judged" in found.basis


def test_what_cannot_be_judged(tmp_path: Path) -> None:
    chart, channels = _cut_chart(tmp_path, _bank(4.0, -3000, 3000), CUT)
    # No reported draught, or no reported length: the defaults are no evidence.
    for defaulted, missing in ((("draught_m",), "draught"), (("length_m",), "length")):
        unknown = _judge(chart, channels, 0.0, 0.0, _vessel(150.0, 9.5, defaulted)).confined
        assert unknown.fact is Fact.INSUFFICIENT
        assert unknown.basis == f"along Cut; her {missing} not reported"
    # Deeper than the cut: her positions are not navigable for her on this chart.
    aground = _judge(chart, channels, 0.0, 0.0, _vessel(150.0, 12.0)).confined
    assert aground.fact is Fact.INSUFFICIENT
    assert "her positions are not in water navigable for her draught 12 m" in aground.basis
    # Crossing the cut: placed in it, crossing, and the question does not arise.
    crossing = _judge(chart, channels, -50.0, 90.0, _vessel(150.0, 9.5))
    assert crossing.at_trigger.relation is ChannelRelation.CROSSING
    assert crossing.confined.fact is None
    assert crossing.confined.basis == "not proceeding along a charted channel"
    # Without the chart's depths: not judged.
    bare = _judge(None, channels, 0.0, 0.0, _vessel(150.0, 9.5)).confined
    assert bare.fact is Fact.INSUFFICIENT and bare.basis == "along Cut; no depths charted"


def test_water_that_runs_off_the_chart_is_not_taken_as_a_shoal(tmp_path: Path) -> None:
    # The cut runs along the eastern edge of the chart's coverage: what lies east of it is
    # not charted, so the starboard hand is unknown; the port hand is shut.
    edge = (
        {"OBJL": "DRGARE", "OBJNAM": "Edge", "DRVAL1": 12.0},
        shapely.box(2800, -3000, 3000, 3000),
    )
    chart, channels = _cut_chart(tmp_path, _bank(4.0, -3000, 3000), edge)
    beyond = water_beyond_limits(channels, chart, 0.0, 2900.0, 0.0, 9.5, 0.5, 150.0)
    assert beyond.port_m[0] == 0.0 and np.isnan(beyond.starboard_m[0]) and beyond.held[0]
    np.testing.assert_allclose(
        [beyond.channel_port_m[0], beyond.channel_starboard_m[0]], [100.0, 100.0], atol=0.5
    )
    found = _judge(chart, channels, 2900.0, 0.0, _vessel(150.0, 9.5)).confined
    assert found.fact is Fact.INSUFFICIENT
    assert found.basis.endswith(
        "the water navigable for it runs to the chart's edge at her draught 9.5 m + UKC 0.5 m"
    )


def test_a_corridor_chart_gives_unknown_hands_not_a_false_position(tmp_path: Path) -> None:
    # A chart only 400 m wide, all of it 30 m water and one fairway: her position is
    # navigable, the water runs to the chart's edge on both hands.
    path = write_chart(
        tmp_path / "corridor.geojson",
        FRAME,
        ({"OBJL": "FAIRWY", "OBJNAM": "Corridor"}, shapely.box(-100, -3000, 100, 3000)),
        box_m=3000.0,
    )
    chart = load_chart([path], frame=FRAME)
    channels = load_channels(chart)
    beyond = water_beyond_limits(channels, chart, 0.0, 0.0, 0.0, 9.5, 0.0, 5000.0)
    assert beyond.held[0] and np.isnan(beyond.port_m[0]) and np.isnan(beyond.starboard_m[0])


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
    beyond = water_beyond_limits(channels, chart, north, east, direction, 11.0, 0.0, 300.0)
    # Every point of the outer reach: the 11 m water ends at the channel's limits.
    np.testing.assert_array_less(np.nan_to_num(beyond.port_m, nan=1e9), 1.0)
    np.testing.assert_array_less(np.nan_to_num(beyond.starboard_m, nan=1e9), 1.0)
    # GDAL, directly: walking out from her along the section, 2 m a step, the first point
    # charted shallower than 11 m (or land) comes at the channel's limit or inside it; for
    # 2 m, the room beyond each limit (up to 50 m) is the tool's within the step.
    shallow = water_beyond_limits(channels, chart, north, east, direction, 2.0, 0.0, 50.0)
    radians = np.radians(direction)
    right = np.column_stack([np.cos(radians), -np.sin(radians)])
    steps_m = np.arange(0.0, 800.0, 2.0)
    for limit_m, sign, room_m in (
        (beyond.channel_port_m, -1.0, shallow.port_m),
        (beyond.channel_starboard_m, 1.0, shallow.starboard_m),
    ):
        xy = at[:, None, :] + sign * steps_m[None, :, None] * right[:, None, :]
        lat, lon = channels.frame.to_geodetic(xy[..., 1].ravel(), xy[..., 0].ravel())
        depth = _depth_at(np.column_stack([lon, lat])).reshape(len(at), len(steps_m))
        np.testing.assert_array_less(_first_shallower_m(depth, 11.0, steps_m), limit_m + 2.0)
        gdal_room_m = np.clip(_first_shallower_m(depth, 2.0, steps_m) - limit_m, 0.0, 50.0)
        np.testing.assert_allclose(room_m, gdal_room_m, atol=2.5)
    # Along this reach a 2 m draught has room outside the channel on one hand or the other
    # at most stations: she is not confined to it.
    assert np.mean((shallow.port_m >= 50.0) | (shallow.starboard_m >= 50.0)) > 0.5


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
    # What a reader sees, from the yacht's seat (DEEP the target): the title's second line
    # and the dossier name the source of d3.
    from colregs9_cli.report.dossier import channel_lines
    from colregs9_cli.report.encounter_figure import verdict_text

    (yacht_seat,) = [o for o in result.encounters if o.summary.own_name == "YACHT"]
    title = verdict_text(yacht_seat)
    ship_line = next(line for line in channel_lines(yacht_seat.summary) if "target" in line)
    if confined:
        assert "target restricted: false by her arcs, confined to the channel by her draught" in (
            title
        )
        assert "confined to the channel by her draught: true (along Cut, at " in ship_line
    else:
        assert "target restricted: false, CPA" in title
        assert "confined to the channel by her draught: false" in ship_line


def test_the_confinement_is_the_same_for_any_slab_length(tmp_path: Path) -> None:
    from colregs9_cli.jobs.replay import run_replay
    from colregs9_cli.jobs.simulate import simulate_scenario

    ais = tmp_path / "cut.csv"
    simulate_scenario(_scenario(tmp_path, 9.5), ais)
    arcs = {"swing_model": "fixed", "swing_deg_per_m": 0.36, "horizon_s": 30.0}
    tables = [
        run_replay(
            [ais],
            chart_paths=[tmp_path / "cut.geojson"],
            plots=False,
            write=False,
            overrides={"manoeuvrability": arcs, "replay": {"slab_s": slab_s}},
        ).pairs_table
        for slab_s in (120.0, 3600.0)
    ]
    assert tables[0]["confined_to_channel_a"].tolist() == ["true"]
    pd.testing.assert_frame_equal(tables[0], tables[1])


@pytest.mark.parametrize(("neighbour_west_m", "right_m"), [(100.0, 300.0), (150.0, 100.0)])
def test_channel_areas_are_joined_only_where_they_touch(
    tmp_path: Path, neighbour_west_m: float, right_m: float
) -> None:
    # A fairway from x -100 to 100 and another from neighbour_west_m to 300: sharing an edge
    # they are one channel; 50 m apart, two.
    _, channels = _cut_chart(
        tmp_path,
        ({"OBJL": "FAIRWY", "OBJNAM": "A"}, shapely.box(-100, -3000, 100, 3000)),
        ({"OBJL": "FAIRWY", "OBJNAM": "B"}, shapely.box(neighbour_west_m, -3000, 300, 3000)),
    )
    northbound = np.array([[1.0, 0.0]])  # her right hand is east
    left, right = channels.section_limits(np.array([[0.0, 0.0]]), northbound)
    np.testing.assert_allclose([left[0], right[0]], [100.0, right_m], atol=1e-6)
    outside = channels.section_limits(np.array([[-500.0, 0.0]]), northbound)
    assert np.isnan(outside[0][0]) and np.isnan(outside[1][0])


def test_iris_ace_is_confined_to_the_san_diego_entrance_channel(
    sandiego: tuple[Any, Channels, int],
) -> None:
    """The fixture's one large vessel under way: the car carrier IRIS ACE (187 m, 8.7 m
    draught) inbound along the entrance channel at both her reports (README)."""
    from colregs9_cli.charts.channel_facts import channel_facts

    from fixture_files import SANDIEGO_AIS

    chart, channels, index = sandiego
    rows = pd.read_csv(SANDIEGO_AIS)
    iris = rows[rows["MMSI"] == 319392000].sort_values("BaseDateTime")
    assert (iris["Length"] == 187).all() and (iris["Draft"] == 8.7).all()
    lat, lon = iris["LAT"].to_numpy(), iris["LON"].to_numpy()
    north, east = channels.frame.to_local(lat, lon)
    course = channels.frame.true_to_grid_deg(iris["COG"].to_numpy(), lat, lon)
    facts = channel_facts(channels, north, east, course)
    assert facts.channel.tolist() == [index, index]
    assert list(facts.relation) == [ChannelRelation.ALONG] * 2
    water = water_beyond_limits(channels, chart, north, east, facts.axis_grid_deg, 8.7, 0.0, 187.0)
    np.testing.assert_allclose(water.port_m, [12.0, 0.0], atol=1.0)
    np.testing.assert_allclose(water.starboard_m, [32.0, 41.0], atol=1.0)
    np.testing.assert_allclose(water.navigable_width_m, [211.0, 183.0], atol=1.0)
    assert (water.port_m < 187.0).all() and (water.starboard_m < 187.0).all()
    assert (water.navigable_width_m < 5 * 187.0).all()
