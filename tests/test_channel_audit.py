"""Each vessel and the charted channels over a passing, and rule 9(a)
(``core/channel_audit.py``): hand-worked cases on a straight synthetic fairway."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st

from colregs9_cli.charts.channel_facts import ChannelRelation
from colregs9_cli.charts.channels import Channels, make_channel
from colregs9_cli.charts.s57_classes import ChannelKind
from colregs9_cli.core.audit import ConductParams, Fact, conduct
from colregs9_cli.core.channel_audit import (
    NOT_CHARTED,
    ChannelAuditParams,
    DraughtOnChart,
    vessel_in_channel,
)
from colregs9_cli.core.vessel_defaults import VesselDimensions
from colregs9_cli.errors import ParameterError
from colregs9_cli.geo import LocalFrame

from geojson_charts import annulus_sector

FRAME = LocalFrame(55.0, 10.0)
PARAMS = ChannelAuditParams()
NO_DEPTHS = DraughtOnChart(None, VesselDimensions(100.0, 15.0, 6.0, (), ""), 0.0)
# A fairway 200 m wide running north-south for 4 km, its axis on x = 0 (east_m).
FAIRWAY = make_channel(
    FRAME,
    ChannelKind.FAIRWAY,
    shapely.box(-100.0, -2000.0, 100.0, 2000.0),
    record_id="F1",
    name="Test Fairway",
)
assert FAIRWAY is not None
CHANNELS = Channels(FRAME, (FAIRWAY,))


def _run(east_m: float, course_deg: float, seconds: int, start_north_m: float = -500.0):
    """A vessel on a straight course at 5 m/s, one row a second, as a pair's series."""
    t = np.arange(seconds, dtype=float)
    north = start_north_m + 5.0 * t * np.cos(np.radians(course_deg))
    east = east_m + 5.0 * t * np.sin(np.radians(course_deg))
    return pd.DataFrame(
        {
            "own_north_m": north,
            "own_east_m": east,
            "own_cog_grid_deg": course_deg,
            "own_heading_grid_deg": course_deg,
        }
    )


def _judge(window: pd.DataFrame, cpa_row: int | None = None, covers_cpa: bool = True):
    cpa = len(window) - 1 if cpa_row is None else cpa_row
    return vessel_in_channel(window, "own_", CHANNELS, cpa, covers_cpa, 1.0, PARAMS, NO_DEPTHS)


def test_northbound_in_the_eastern_half_keeps_to_starboard() -> None:
    found = _judge(_run(50.0, 0.0, 120))
    assert found.at_trigger.channel == "Test Fairway"
    assert found.at_trigger.relation is ChannelRelation.ALONG
    assert found.at_trigger.offset_m == pytest.approx(50.0, abs=0.5)
    assert found.keeps_to_starboard_side.fact is Fact.TRUE
    assert "along Test Fairway for 120 s, in its starboard half 100%" in (
        found.keeps_to_starboard_side.basis
    )
    assert "offset +50 m" in found.keeps_to_starboard_side.basis


def test_southbound_in_the_eastern_half_is_on_her_port_side() -> None:
    found = _judge(_run(50.0, 180.0, 120, start_north_m=500.0))
    assert found.at_trigger.offset_m == pytest.approx(-50.0, abs=0.5)
    assert found.keeps_to_starboard_side.fact is Fact.FALSE
    assert "starboard half 0%" in found.keeps_to_starboard_side.basis


def test_a_vessel_that_moves_over_to_port_partway_is_judged_by_her_share() -> None:
    # 60 s in the starboard half, then 60 s at 30 m to port: a share of 50 % < 80 %.
    starboard = _run(30.0, 0.0, 60)
    port = _run(-30.0, 0.0, 60, start_north_m=float(starboard["own_north_m"].iloc[-1]) + 5.0)
    found = _judge(pd.concat([starboard, port], ignore_index=True))
    assert found.keeps_to_starboard_side.fact is Fact.FALSE
    assert "starboard half 50%" in found.keeps_to_starboard_side.basis


def test_too_short_along_or_data_before_the_closest_approach_is_insufficient() -> None:
    short = _judge(_run(50.0, 0.0, 20))
    assert short.keeps_to_starboard_side.fact is Fact.INSUFFICIENT
    assert short.keeps_to_starboard_side.basis.endswith("too short")
    cut = _judge(_run(50.0, 0.0, 120), covers_cpa=False)
    assert cut.keeps_to_starboard_side.fact is Fact.INSUFFICIENT
    assert "data end before the closest approach" in cut.keeps_to_starboard_side.basis


def test_a_crossing_vessel_is_placed_but_rule_9a_does_not_apply() -> None:
    found = _judge(_run(-300.0, 90.0, 120, start_north_m=0.0), cpa_row=60)
    assert found.at_trigger.channel is None
    assert found.at_least_separation.channel == "Test Fairway"
    assert found.at_least_separation.relation is ChannelRelation.CROSSING
    assert found.keeps_to_starboard_side.fact is None
    assert found.keeps_to_starboard_side.basis == "not proceeding along a charted channel"


def test_outside_every_channel_and_without_a_chart() -> None:
    outside = _judge(_run(1000.0, 0.0, 60))
    assert outside.at_trigger.channel is None
    assert outside.at_trigger.relation is ChannelRelation.OUTSIDE
    assert outside.keeps_to_starboard_side.fact is None
    window = _run(50.0, 0.0, 60)
    assert vessel_in_channel(window, "own_", None, 59, True, 1.0, PARAMS, NO_DEPTHS) == NOT_CHARTED


def test_the_least_separation_place_is_its_row() -> None:
    found = _judge(_run(50.0, 0.0, 120), cpa_row=100)
    # 100 s at 5 m/s north of -500 m: still along, still 50 m to starboard
    assert found.at_least_separation.relation is ChannelRelation.ALONG
    assert found.at_least_separation.offset_m == pytest.approx(50.0, abs=0.5)


@given(
    offset_m=st.floats(-90.0, 90.0).filter(lambda x: abs(x) > 1.0),
    northbound=st.booleans(),
)
def test_the_same_place_seen_going_the_other_way_is_the_other_side(
    offset_m: float, northbound: bool
) -> None:
    course, start = (0.0, -500.0) if northbound else (180.0, 500.0)
    here = _judge(_run(offset_m, course, 60, start_north_m=start))
    back = _judge(_run(offset_m, (course + 180.0) % 360.0, 60, start_north_m=-start))
    assert here.at_trigger.offset_m == pytest.approx(-back.at_trigger.offset_m, abs=0.5)
    assert {here.keeps_to_starboard_side.fact, back.keeps_to_starboard_side.fact} == {
        Fact.TRUE,
        Fact.FALSE,
    }


def test_bad_thresholds_are_one_error() -> None:
    with pytest.raises(ParameterError, match="starboard_side_share"):
        ChannelAuditParams(starboard_side_share=0.3)
    with pytest.raises(ParameterError, match="starboard_side_min_s"):
        ChannelAuditParams(starboard_side_min_s=-1.0)
    with pytest.raises(ParameterError, match="along_within_deg"):
        ChannelAuditParams(channel_along_within_deg=50.0)


# -- San Diego with its ENC ----------------------------------------------------------------


def _main_channel_wgs84():
    """The fairway San Diego Harbor Channel, read with GDAL directly (updates applied by the
    S-57 driver's default)."""
    import pyogrio

    from fixture_files import SANDIEGO_ENC

    _, _, wkb, fields = pyogrio.raw.read(SANDIEGO_ENC, layer="FAIRWY", columns=["OBJNAM"])
    (geometry,) = [
        shapely.from_wkb(g)
        for g, name in zip(wkb, fields[0], strict=True)
        if name == "San Diego Harbor Channel"
    ]
    return geometry


def test_sandiego_pairs_in_the_main_channel_are_inside_it_on_the_chart(sandiego_replay) -> None:
    channel = _main_channel_wgs84()
    placed = 0
    for pair in sandiego_replay.pairs:
        s = pair.summary
        for vessel in ("a", "b"):
            lat = getattr(s, f"lat_deg_at_trigger_{vessel}")
            lon = getattr(s, f"lon_deg_at_trigger_{vessel}")
            inside = channel.contains(shapely.Point(lon, lat))
            named = getattr(s, f"channel_{vessel}") == "San Diego Harbor Channel"
            # A dredged quarter or a smaller fairway inside it may be named instead.
            assert named <= inside, (s.pair_id, vessel)
            placed += named
            if named:
                assert getattr(s, f"channel_relation_{vessel}") is ChannelRelation.ALONG
    assert placed == 8
    champagne_leto = [p.summary for p in sandiego_replay.pairs if p.summary.name_a == "CHAMPAGNE"]
    (s,) = [s for s in champagne_leto if s.name_b == "LETO"]
    assert s.keeps_to_starboard_side_a is Fact.TRUE and s.keeps_to_starboard_side_b is Fact.TRUE
    assert s.channel_offset_m_a > 0.0 and s.channel_offset_m_b > 0.0


# -- rule 10 in a synthetic traffic separation scheme ---------------------------------------

LANE = make_channel(
    FRAME,
    ChannelKind.TSS_LANE,
    shapely.box(200.0, -2000.0, 1200.0, 2000.0),
    record_id="L1",
    orient_deg=0.0,
)
assert LANE is not None
SCHEME = Channels(FRAME, (LANE,))


def _in_scheme(east_m: float, course_deg: float, heading_deg: float | None = None):
    window = _run(east_m, course_deg, 120, start_north_m=-300.0 if course_deg < 90 else 300.0)
    window["own_heading_grid_deg"] = np.nan if heading_deg is None else heading_deg
    return vessel_in_channel(window, "own_", SCHEME, 119, True, 1.0, PARAMS, NO_DEPTHS).lane


def test_rule_10_b_a_vessel_in_a_lane_goes_its_way() -> None:
    with_it = _in_scheme(700.0, 0.0)
    assert with_it.follows_lane is Fact.TRUE and with_it.crosses_at_right_angles is None
    assert "along a lane for 120 s, against its ORIENT 0%" in with_it.basis
    against = _in_scheme(700.0, 180.0)
    assert against.follows_lane is Fact.FALSE
    assert "against its ORIENT 100%" in against.basis


def test_rule_10_c_a_lane_crossed_at_right_angles_by_heading() -> None:
    window = _run(0.0, 90.0, 240, start_north_m=0.0)  # east across the lane, 5 m/s
    window["own_heading_grid_deg"] = np.nan
    square = vessel_in_channel(window, "own_", SCHEME, 239, True, 1.0, PARAMS, NO_DEPTHS).lane
    assert square.crosses_at_right_angles is Fact.TRUE and square.follows_lane is None
    assert "heading 0° from a right angle" in square.basis
    # the same track made good with her head 30° to port of it (set by a current): not square
    window["own_heading_grid_deg"] = 60.0
    crabbing = vessel_in_channel(window, "own_", SCHEME, 239, True, 1.0, PARAMS, NO_DEPTHS).lane
    assert crabbing.crosses_at_right_angles is Fact.FALSE
    assert "heading 30° from a right angle" in crabbing.basis


def test_outside_a_scheme_rule_10_does_not_apply() -> None:
    found = _judge(_run(50.0, 0.0, 120))
    assert found.lane.follows_lane is None and found.lane.crosses_at_right_angles is None
    assert found.lane.basis == "in no traffic lane"


# -- a turn that follows a bend is not an action ---------------------------------------------


def _round_the_bend(extra_turn_deg: float) -> pd.DataFrame:
    """A vessel 30 m to starboard of the axis of a river bend (radius 1 km, turning 90°
    clockwise), following it from 10° to 70° round at 5 m/s; her course the tangent plus
    ``extra_turn_deg`` from the row where she is 40° round."""
    at_deg = np.linspace(10.0, 70.0, 230)
    radius = 970.0  # the centre of the bend is to starboard: 30 m inside the axis
    course = at_deg + 90.0 + np.where(at_deg >= 40.0, extra_turn_deg, 0.0)
    return pd.DataFrame(
        {
            "own_north_m": radius * np.cos(np.radians(at_deg)),
            "own_east_m": radius * np.sin(np.radians(at_deg)),
            "own_cog_grid_deg": course,
            "own_heading_grid_deg": course,
        }
    )


RIVER = Channels(
    FRAME,
    tuple(
        c
        for c in (
            make_channel(
                FRAME, ChannelKind.FAIRWAY, annulus_sector(900.0, 1100.0, 90.0), record_id="R1"
            ),
        )
        if c is not None
    ),
)
CONDUCT = ConductParams(
    course_change_deg=15.0,
    speed_change_frac=0.25,
    speed_change_min_kn=1.0,
    course_judged_above_kn=2.0,
)


@pytest.mark.parametrize(("extra_turn_deg", "action"), [(0.0, "none"), (25.0, "starboard-turn")])
def test_following_a_bend_is_no_turn_and_a_turn_within_it_is(
    extra_turn_deg: float, action: str
) -> None:
    window = _round_the_bend(extra_turn_deg)
    found = vessel_in_channel(window, "own_", RIVER, len(window) - 1, True, 1.0, PARAMS, NO_DEPTHS)
    # 60° of bend between the first row and the last, less her own extra turn
    assert found.bend_deg[-1] == pytest.approx(60.0, abs=4.0)
    true_course = window["own_cog_grid_deg"].to_numpy()
    sog_kn = np.full(len(window), 9.7)
    judged = conduct(true_course - found.bend_deg, sog_kn, CONDUCT)
    assert judged.action.value == action
    # Without the channel the bend alone reads as a starboard turn.
    assert conduct(true_course, sog_kn, CONDUCT).action.value == "starboard-turn"


# -- two vessels meeting along a channel ---------------------------------------------------


def _place(channel: str | None, relation: ChannelRelation):
    from colregs9_cli.core.channel_audit import ChannelPlace, StarboardSide, VesselInChannel

    here = ChannelPlace(channel, relation, 20.0)
    return VesselInChannel(here, here, StarboardSide(None, ""))


@pytest.mark.parametrize(
    ("places", "courses", "meeting"),
    [
        # along the same river in a bend: courses 120° apart, as the bend makes them
        (("River", "River"), (30.0, 270.0), True),
        (("River", "River"), (30.0, 50.0), False),  # the same way: an overtaking
        (("River", "Other"), (30.0, 210.0), False),
        ((None, "River"), (30.0, 210.0), False),
    ],
)
def test_meeting_along_a_channel(places, courses, meeting) -> None:
    from colregs9_cli.core.channel_audit import meeting_along_a_channel

    vessels = tuple(
        _place(name, ChannelRelation.ALONG if name else ChannelRelation.OUTSIDE) for name in places
    )
    assert meeting_along_a_channel(vessels, courses) is meeting


def test_a_crossing_read_in_a_bend_is_held_as_head_on() -> None:
    from colregs9_cli.core.colregs import (
        ColregsEvaluation,
        Role,
        Situation,
        SituationBasis,
    )
    from colregs9_cli.core.pair import _held

    def crossing(rows: int) -> ColregsEvaluation:
        return ColregsEvaluation(
            situation=np.array([Situation.CROSSING] * rows, dtype=object),
            own_role=np.array([Role.GIVE_WAY] * rows, dtype=object),
            target_role=np.array([Role.STAND_ON] * rows, dtype=object),
            own_overtaking=np.zeros(rows, dtype=bool),
            ambiguous=np.zeros(rows, dtype=bool),
            basis=np.array([SituationBasis.SECTORS] * rows, dtype=object),
            beta_deg=np.full(rows, 30.0),
            beta_prime_deg=np.full(rows, 330.0),
            closing=np.ones(rows, dtype=bool),
        )

    held = _held(crossing(3), meeting_in_channel=True)
    assert list(held.situation) == [Situation.HEAD_ON] * 3
    assert list(held.own_role) == list(held.target_role) == [Role.GIVE_WAY] * 3
    assert list(held.basis) == [SituationBasis.CHANNEL] * 3
    assert list(_held(crossing(3)).situation) == [Situation.CROSSING] * 3
