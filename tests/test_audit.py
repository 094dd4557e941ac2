"""Audit facts (audit.py): the pass, the closest approach and each vessel's conduct."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd
import pytest
import shapely
from hypothesis import given
from hypothesis import strategies as st

from colregs9_cli.core.audit import (
    Action,
    ConductParams,
    Fact,
    action_as_rule_asks,
    all_of,
    conduct,
    course_drawn_through_a_turn,
    negated,
    observed_rows,
    passed_port_to_port,
    stand_on_turned_to_port_for_vessel_on_port,
)
from colregs9_cli.core.colregs import Role, Situation
from colregs9_cli.core.pair_audit import over_land
from colregs9_cli.core.rule9 import DecidingRule
from colregs9_cli.errors import ParameterError

from fixture_files import pair_summary

PARAMS = ConductParams(
    course_change_deg=15.0,
    speed_change_frac=0.25,
    speed_change_min_kn=1.0,
    course_judged_above_kn=2.0,
)


@pytest.mark.parametrize(
    ("course_deg", "speed_kn", "changed", "action", "row"),
    [
        ([10.0, 12.0, 24.9], [10.0, 10.0, 10.0], Fact.FALSE, Action.NONE, None),  # 14.9°
        ([10.0, 12.0, 25.0], [10.0, 10.0, 10.0], Fact.TRUE, Action.STARBOARD_TURN, 2),
        ([355.0, 5.0, 9.0], [10.0, 10.0, 10.0], Fact.FALSE, Action.NONE, None),  # 14° over N
        ([350.0, 0.0, 5.0], [10.0, 10.0, 10.0], Fact.TRUE, Action.STARBOARD_TURN, 2),
        ([90.0, 80.0, 70.0], [10.0, 10.0, 10.0], Fact.TRUE, Action.PORT_TURN, 2),
        ([90.0, 90.0, 90.0], [10.0, 8.0, 7.6], Fact.FALSE, Action.NONE, None),  # 24 % slower
        ([90.0, 90.0, 90.0], [10.0, 8.0, 7.5], Fact.TRUE, Action.SLOWED, 2),
        ([90.0, 90.0, 90.0], [8.0, 9.0, 10.0], Fact.TRUE, Action.SPED_UP, 2),
        # 25 % of a slow vessel's speed is SOG noise below 1 kn (DMA 211219630: 0.60 → 0.98)
        ([90.0, 90.0, 90.0], [0.6, 0.8, 0.98], Fact.INSUFFICIENT, Action.INSUFFICIENT, None),
        ([90.0, 90.0, 90.0], [2.0, 2.5, 2.99], Fact.FALSE, Action.NONE, None),
        ([90.0, 90.0, 90.0], [2.0, 2.5, 3.0], Fact.TRUE, Action.SPED_UP, 2),
        ([90.0, 90.0, 90.0], [0.6, 1.2, 1.6], Fact.TRUE, Action.SPED_UP, 2),
        # the first change in time is the action
        ([90.0, 90.0, 120.0], [10.0, 7.0, 7.0], Fact.TRUE, Action.SLOWED, 1),
    ],
)
def test_conduct_thresholds(
    course_deg: list[float], speed_kn: list[float], changed: Fact, action: Action, row: int | None
) -> None:
    result = conduct(np.array(course_deg), np.array(speed_kn), PARAMS)
    assert (result.changed, result.action, result.action_row) == (changed, action, row)


def test_cog_noise_of_a_slow_vessel_is_not_a_turn() -> None:
    # 1 kn with COG wandering 40°: not judged; no speed change either → cannot tell
    course = np.array([10.0, 50.0, 350.0, 20.0])
    speed = np.array([1.0, 1.1, 0.9, 1.0])
    result = conduct(course, speed, PARAMS)
    assert result.changed is Fact.INSUFFICIENT and result.action is Action.INSUFFICIENT


def test_a_course_unknown_at_the_trigger_is_judged_from_when_it_is_known() -> None:
    course = np.array([np.nan, 100.0, 101.0, 120.0])
    speed = np.array([6.0, 6.0, 6.0, 6.0])
    result = conduct(course, speed, PARAMS)
    assert (result.action, result.action_row) == (Action.STARBOARD_TURN, 3)


def test_three_valued_logic() -> None:
    assert all_of([Fact.TRUE, Fact.TRUE]) is Fact.TRUE
    assert all_of([Fact.TRUE, Fact.INSUFFICIENT]) is Fact.INSUFFICIENT
    assert all_of([Fact.INSUFFICIENT, Fact.FALSE]) is Fact.FALSE
    assert negated(Fact.TRUE) is Fact.FALSE and negated(Fact.FALSE) is Fact.TRUE
    assert negated(Fact.INSUFFICIENT) is Fact.INSUFFICIENT


# --- the kinds of action: stopped ------------------------------------------------------------


@pytest.mark.parametrize(
    ("speed_kn", "action", "row"),
    [
        ([10.0, 8.0, 5.0, 0.3], Action.STOPPED, 2),  # the row is where the slowing began
        ([10.0, 8.0, 5.0, 0.5], Action.SLOWED, 2),  # 0.5 kn is not below 0.5 kn
        ([10.0, 6.0, 0.2, 3.0], Action.STOPPED, 1),  # stopped, then under way again
        ([6.0, 4.5, 4.5, 4.5], Action.SLOWED, 1),
    ],
)
def test_a_slowing_that_takes_the_way_off_is_a_stop(
    speed_kn: list[float], action: Action, row: int
) -> None:
    result = conduct(np.full(len(speed_kn), 90.0), np.array(speed_kn), PARAMS)
    assert (result.changed, result.action, result.action_row) == (Fact.TRUE, action, row)


def test_a_low_speed_without_a_slowing_is_no_stop() -> None:
    # 1.2 → 0.3 kn is less than speed_change_min_kn: SOG noise, and the COG cannot be judged
    result = conduct(np.array([90.0, 90.0, 90.0]), np.array([1.2, 0.8, 0.3]), PARAMS)
    assert result.action is Action.INSUFFICIENT


def test_the_stop_threshold_is_a_parameter() -> None:
    speed = np.array([10.0, 5.0, 0.9])
    assert conduct(np.full(3, 90.0), speed, PARAMS).action is Action.SLOWED
    at_1_kn = dataclasses.replace(PARAMS, stopped_below_kn=1.0)
    assert conduct(np.full(3, 90.0), speed, at_1_kn).action is Action.STOPPED


@pytest.mark.parametrize("value", [-0.1, math.nan, math.inf])
def test_a_stop_threshold_that_is_no_speed_is_refused(value: float) -> None:
    with pytest.raises(ParameterError, match="stopped_below_kn"):
        dataclasses.replace(PARAMS, stopped_below_kn=value)


# --- whether the give-way action is the kind the rule asks --------------------------------------

T, F, U = Fact.TRUE, Fact.FALSE, Fact.INSUFFICIENT  # U: undecided by the data
ACTIONS = (
    Action.STARBOARD_TURN,
    Action.PORT_TURN,
    Action.SLOWED,
    Action.STOPPED,
    Action.SPED_UP,
    Action.NONE,
    Action.INSUFFICIENT,
)
# one row per deciding rule, in the order of ACTIONS
EXPECTED = {
    (Situation.HEAD_ON, DecidingRule.RULE_14): (T, F, F, F, F, F, U),
    (Situation.CROSSING, DecidingRule.RULE_15): (T, F, T, T, F, F, U),
    (Situation.OVERTAKING, DecidingRule.RULE_13): (T, T, T, T, F, F, U),
    (Situation.CROSSING, DecidingRule.RULE_9): (T, T, T, T, F, F, U),
    (Situation.HEAD_ON, DecidingRule.RULE_9): (T, T, T, T, F, F, U),
    (Situation.CROSSING, DecidingRule.RULE_18): (T, T, T, T, F, F, U),
    (Situation.HEAD_ON, DecidingRule.RULE_18): (T, T, T, T, F, F, U),
}
JUDGED = [
    (s, r, a, e) for (s, r), row in EXPECTED.items() for a, e in zip(ACTIONS, row, strict=True)
]


@pytest.mark.parametrize(("situation", "rule", "action", "expected"), JUDGED)
def test_each_rule_judges_each_kind_of_action(
    situation: Situation, rule: DecidingRule, action: Action, expected: Fact
) -> None:
    assert action_as_rule_asks(situation, rule, Role.GIVE_WAY, action) is expected


@pytest.mark.parametrize(("situation", "rule"), list(EXPECTED))
@pytest.mark.parametrize("role", [Role.STAND_ON, Role.NONE])
def test_only_a_give_way_vessel_is_judged(
    situation: Situation, rule: DecidingRule, role: Role
) -> None:
    assert action_as_rule_asks(situation, rule, role, Action.PORT_TURN) is None


def test_a_pair_with_no_situation_has_nothing_to_judge() -> None:
    judged = action_as_rule_asks(Situation.NONE, DecidingRule.NONE, Role.NONE, Action.NONE)
    assert judged is None


@pytest.mark.parametrize(
    ("situation", "rule"),
    [
        (Situation.CROSSING, DecidingRule.RULE_14),
        (Situation.HEAD_ON, DecidingRule.RULE_15),
        (Situation.CROSSING, DecidingRule.RULE_13),
        (Situation.OVERTAKING, DecidingRule.RULE_18),  # rule 13 keeps every overtaking
        (Situation.OVERTAKING, DecidingRule.RULE_9),
        (Situation.CROSSING, DecidingRule.NONE),
        (Situation.NONE, DecidingRule.RULE_15),
    ],
)
def test_a_pair_rule9_cannot_decide_is_a_bug(situation: Situation, rule: DecidingRule) -> None:
    with pytest.raises(ValueError, match="does not decide"):
        action_as_rule_asks(situation, rule, Role.GIVE_WAY, Action.NONE)


def test_the_strings_of_pairs_csv_are_accepted() -> None:
    judged = action_as_rule_asks(
        Situation("crossing"), DecidingRule("15"), Role("give-way"), Action("sped-up")
    )
    assert judged is Fact.FALSE
    assert action_as_rule_asks("head-on", "14", "give-way", "starboard-turn") is Fact.TRUE  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("situation", "rule", "course_deg", "speed_kn", "expected"),
    [
        # the issue: a crossing give-way vessel that speeds up "acted", but not as rule 15 asks
        (Situation.CROSSING, DecidingRule.RULE_15, [45.0] * 4, [8.0, 9.0, 10.5, 11.0], F),
        (Situation.CROSSING, DecidingRule.RULE_15, [45.0] * 4, [8.0, 6.5, 3.0, 0.1], T),
        # a port turn in a head-on situation is a change, not the alteration rule 14(a) asks
        (Situation.HEAD_ON, DecidingRule.RULE_14, [0.0, 350.0, 340.0, 330.0], [12.0] * 4, F),
        (Situation.HEAD_ON, DecidingRule.RULE_14, [0.0, 10.0, 20.0, 30.0], [12.0] * 4, T),
        (Situation.OVERTAKING, DecidingRule.RULE_13, [0.0, 350.0, 340.0, 330.0], [12.0] * 4, T),
        (Situation.OVERTAKING, DecidingRule.RULE_13, [0.0, 2.0, 1.0, 0.0], [12.0] * 4, F),
        # a vessel too slow for her COG to show a turn, whose speed holds: cannot tell
        (Situation.CROSSING, DecidingRule.RULE_15, [0.0, 40.0, 320.0, 10.0], [1.0] * 4, U),
    ],
)
def test_from_a_track_to_the_judgement(
    situation: Situation,
    rule: DecidingRule,
    course_deg: list[float],
    speed_kn: list[float],
    expected: Fact,
) -> None:
    action = conduct(np.array(course_deg), np.array(speed_kn), PARAMS).action
    assert action_as_rule_asks(situation, rule, Role.GIVE_WAY, action) is expected


# --- rule 17(c) -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("action", "bearing_deg", "expected"),
    [
        (Action.PORT_TURN, 300.0, T),  # the give-way vessel on her port bow: 17(c) breached
        (Action.PORT_TURN, 190.0, T),
        (Action.PORT_TURN, -60.0, T),  # any bearing is wrapped
        (Action.PORT_TURN, 660.0, T),
        (Action.PORT_TURN, 60.0, F),  # on her starboard side: 17(c) does not forbid it
        (Action.PORT_TURN, 0.0, F),  # dead ahead and dead astern are on neither side
        (Action.PORT_TURN, 180.0, F),
        (Action.STARBOARD_TURN, 300.0, F),
        (Action.SLOWED, 300.0, F),
        (Action.STOPPED, 300.0, F),
        (Action.SPED_UP, 300.0, F),
        (Action.NONE, 300.0, F),  # she kept her course and speed (rule 17(a)(i))
        (Action.INSUFFICIENT, 300.0, U),
        (Action.PORT_TURN, math.nan, U),
        (Action.STARBOARD_TURN, math.nan, F),
    ],
)
def test_rule_17c_in_a_crossing(action: Action, bearing_deg: float, expected: Fact) -> None:
    judged = stand_on_turned_to_port_for_vessel_on_port(
        Situation.CROSSING, DecidingRule.RULE_15, Role.STAND_ON, action, bearing_deg
    )
    assert judged is expected


@pytest.mark.parametrize(
    ("situation", "rule", "role"),
    [
        (Situation.CROSSING, DecidingRule.RULE_15, Role.GIVE_WAY),
        (Situation.CROSSING, DecidingRule.RULE_18, Role.STAND_ON),
        (Situation.CROSSING, DecidingRule.RULE_9, Role.STAND_ON),
        (Situation.HEAD_ON, DecidingRule.RULE_18, Role.STAND_ON),
        (Situation.OVERTAKING, DecidingRule.RULE_13, Role.STAND_ON),
        (Situation.NONE, DecidingRule.NONE, Role.NONE),
    ],
)
def test_rule_17c_binds_only_the_stand_on_vessel_of_a_rule_15_crossing(
    situation: Situation, rule: DecidingRule, role: Role
) -> None:
    judged = stand_on_turned_to_port_for_vessel_on_port(
        situation, rule, role, Action.PORT_TURN, 300.0
    )
    assert judged is None


# --- properties -----------------------------------------------------------------------------

MIRRORED = {Action.STARBOARD_TURN: Action.PORT_TURN, Action.PORT_TURN: Action.STARBOARD_TURN}


def _mirrored(action: Action) -> Action:
    return MIRRORED.get(action, action)


# whole degrees within ±85° of the first course: the mirrored sums are exact, and no two
# courses differ by the ±180° whose side is undefined (the reference course is the first
# judged row's, not the first row's)
_tracks = st.integers(2, 12).flatmap(
    lambda n: st.tuples(
        st.integers(0, 359),
        st.lists(st.integers(-85, 85), min_size=n, max_size=n),
        st.lists(
            st.sampled_from([0.2, 0.5, 1.0, 2.0, 4.0, 6.0, 8.0, 12.0]), min_size=n, max_size=n
        ),
    )
)


@given(_tracks)
def test_a_mirrored_track_gives_the_mirrored_action(
    track: tuple[int, list[int], list[float]],
) -> None:
    first_deg, offsets_deg, speed_kn = track
    course = np.array([(first_deg + off) % 360 for off in offsets_deg], dtype=float)
    mirror = np.array([(-c) % 360 for c in course], dtype=float)
    seen = conduct(course, np.array(speed_kn), PARAMS)
    seen_mirrored = conduct(mirror, np.array(speed_kn), PARAMS)
    assert seen_mirrored.action is _mirrored(seen.action)
    assert (seen_mirrored.changed, seen_mirrored.action_row) == (seen.changed, seen.action_row)


@given(_tracks)
def test_a_stop_is_a_slowing_that_goes_below_the_threshold(
    track: tuple[int, list[int], list[float]],
) -> None:
    first_deg, offsets_deg, speed_kn = track
    course = np.array([(first_deg + off) % 360 for off in offsets_deg], dtype=float)
    never = conduct(course, np.array(speed_kn), dataclasses.replace(PARAMS, stopped_below_kn=0.0))
    seen = conduct(course, np.array(speed_kn), PARAMS)
    assert never.action is not Action.STOPPED
    expected = Action.SLOWED if seen.action is Action.STOPPED else seen.action
    assert (never.action, never.action_row) == (expected, seen.action_row)
    if seen.action is Action.STOPPED:
        assert min(speed_kn) < PARAMS.stopped_below_kn


@given(st.sampled_from(list(EXPECTED)), st.sampled_from(ACTIONS))
def test_a_mirrored_action_is_judged_by_the_side_the_rule_names(
    decided: tuple[Situation, DecidingRule], action: Action
) -> None:
    situation, rule = decided
    judged = action_as_rule_asks(situation, rule, Role.GIVE_WAY, action)
    mirrored = action_as_rule_asks(situation, rule, Role.GIVE_WAY, _mirrored(action))
    names_a_side = rule in (DecidingRule.RULE_14, DecidingRule.RULE_15)
    if names_a_side and action in MIRRORED:
        assert mirrored is negated(judged or Fact.INSUFFICIENT)
    else:
        assert mirrored is judged


# away from dead ahead and astern, where a bearing of -1e-82° wraps to 0° (neither side)
@given(st.floats(-720.0, 720.0).filter(lambda b: 1e-6 < b % 180.0 < 180.0 - 1e-6))
def test_rule_17c_a_port_turn_breaches_it_on_exactly_one_of_mirrored_bearings(
    bearing_deg: float,
) -> None:
    def breached(bearing: float) -> Fact | None:
        return stand_on_turned_to_port_for_vessel_on_port(
            Situation.CROSSING, DecidingRule.RULE_15, Role.STAND_ON, Action.PORT_TURN, bearing
        )

    assert {breached(bearing_deg), breached(-bearing_deg)} == {Fact.TRUE, Fact.FALSE}
    assert breached(bearing_deg + 360.0) is breached(bearing_deg)


# Only what her reports show: rows 0-3 lie inside one 151 s gap between two reports (the
# trigger 4 s into it), row 4 is the report that closes it.
IN_ONE_GAP = np.array([False, False, False, False, True, True])


def test_a_change_drawn_inside_one_gap_around_the_trigger_is_no_action() -> None:
    # San Diego, SEAS THE DAY: 0.4 kn at 00:00:21, 4.8 kn at 00:02:52; interpolated, she
    # "sped up" 45 s after the trigger. When in the gap she did is unknown.
    speed = np.array([0.5, 1.8, 3.1, 4.4, 4.8, 4.8])
    course = np.full(6, 221.0)
    assert conduct(course, speed, PARAMS).action is Action.SPED_UP
    result = conduct(course, speed, PARAMS, IN_ONE_GAP)
    assert (result.changed, result.action, result.action_row) == (
        Fact.INSUFFICIENT,
        Action.INSUFFICIENT,
        None,
    )


def test_with_no_change_across_the_trigger_gap_her_reference_is_her_first_report() -> None:
    # the course interpolated toward a turn seen only at a report after the closest approach
    # must not count; a turn between two reports after the trigger does, at the later one
    course = np.array([45.0, 45.0, 44.0, 44.0, 44.0, 20.0])
    speed = np.full(6, 3.5)
    result = conduct(course, speed, PARAMS, IN_ONE_GAP)
    assert (result.changed, result.action, result.action_row) == (
        Fact.TRUE,
        Action.PORT_TURN,
        5,
    )
    interpolated_turn = np.array([45.0, 44.0, 44.0, 44.0, 44.0, 35.0])
    assert conduct(interpolated_turn, speed, PARAMS, IN_ONE_GAP).action is Action.NONE


def test_no_observed_row_is_insufficient() -> None:
    result = conduct(np.full(3, 90.0), np.full(3, 8.0), PARAMS, np.zeros(3, bool))
    assert result.action is Action.INSUFFICIENT


def test_observed_rows_are_reports_and_short_gaps() -> None:
    gap_s = np.array([151.0, 151.0, 0.0, 10.0, 31.0, np.nan])
    nearest_s = np.array([4.0, 40.0, 0.0, 5.0, 0.5, np.nan])
    assert observed_rows(gap_s, nearest_s, 1.0, PARAMS).tolist() == [
        False,
        False,
        True,
        True,
        True,
        False,
    ]


def test_observed_gap_must_be_a_number() -> None:
    with pytest.raises(ParameterError, match="observed_gap_max_s"):
        dataclasses.replace(PARAMS, observed_gap_max_s=math.nan)


def test_sandiego_actions_inside_one_report_gap_are_not_judged(sandiego_replay) -> None:
    seas_the_day = 368185860  # reports 0.4 kn at 00:00:21, then 4.8 kn at 00:02:52
    pairs = {
        p.summary.name_a: p.summary
        for p in sandiego_replay.pairs
        if seas_the_day in (p.summary.mmsi_a, p.summary.mmsi_b)
    }
    for name in ("FREEDOM", "CASSIOPEIA"):
        summary = pairs[name]
        assert str(seas_the_day) in summary.give_way_vessels.split(";")
        assert summary.mmsi_b == seas_the_day
        assert summary.action_b == "insufficient-data"
        assert "sped-up" not in summary.give_way_action


def test_sandiego_a_situation_is_read_where_both_courses_are_reported(sandiego_replay) -> None:
    # SHELTER ISLAND reported 087.5 deg at 00:07:12 and 126.2 deg at 00:10:13; at the trigger
    # (00:09:13) the 113 deg drawn between read a crossing with WHITE NIGHTS. At her report
    # they met end on, and passed port to port.
    shelter_island = pair_summary(sandiego_replay, 338187796, 338372419)
    assert shelter_island.trigger_utc == pd.Timestamp("2022-01-03 00:09:13", tz="UTC")
    assert shelter_island.situation_utc == pd.Timestamp("2022-01-03 00:10:13", tz="UTC")
    assert shelter_island.situation == "head-on"
    assert shelter_island.passed_port_to_port == "true"
    # SAILEBRATE and ECHELON tack between reports up to the closest approach the trigger
    # predicts: read at the trigger, and flagged
    tacking = pair_summary(sandiego_replay, 338254678, 368124990)
    assert tacking.situation_utc == tacking.trigger_utc
    assert tacking.situation_ambiguous is True
    # a course reported at the trigger: read there
    champagne_leto = pair_summary(sandiego_replay, 367412850, 368103590)
    assert champagne_leto.situation_utc == champagne_leto.trigger_utc


@pytest.mark.parametrize("rule", [DecidingRule.RULE_13, DecidingRule.RULE_9, DecidingRule.RULE_18])
@pytest.mark.parametrize("turn", [Action.STARBOARD_TURN, Action.PORT_TURN])
def test_a_turn_that_closed_the_cpa_kept_out_of_nobodys_way(
    rule: DecidingRule, turn: Action
) -> None:
    situation = Situation.OVERTAKING if rule is DecidingRule.RULE_13 else Situation.CROSSING
    asks = action_as_rule_asks(situation, rule, Role.GIVE_WAY, turn, closed_cpa=False)
    closed = action_as_rule_asks(situation, rule, Role.GIVE_WAY, turn, closed_cpa=True)
    assert (asks, closed) == (Fact.TRUE, Fact.FALSE)
    # a slowing opens the time, whatever the predicted distance did meanwhile
    slowed = action_as_rule_asks(situation, rule, Role.GIVE_WAY, Action.SLOWED, closed_cpa=True)
    assert slowed is Fact.TRUE


def test_rules_that_name_the_side_judge_the_kind_alone() -> None:
    # rule 14(a) asks a starboard turn, whatever the other vessel did to the predicted CPA
    head_on = (Situation.HEAD_ON, DecidingRule.RULE_14, Role.GIVE_WAY, Action.STARBOARD_TURN)
    assert action_as_rule_asks(*head_on, closed_cpa=True) is Fact.TRUE


def test_dma_the_boat_that_turned_toward_the_ship_she_overtook_did_not_keep_clear(
    dma_nmea_replay,
) -> None:
    # 211546840 overtaking 636092478: a port turn at 12:02:43 that took the predicted CPA
    # from 150 m to 26 m
    summary = pair_summary(dma_nmea_replay, 211546840, 636092478)
    assert (summary.situation, summary.give_way_vessels) == ("overtaking", "211546840")
    assert summary.give_way_action == "port-turn"
    assert summary.give_way_action_as_rule_asks == "false"


@pytest.mark.parametrize(
    ("bearings_deg", "judged", "expected"),
    [
        ((270.0, 290.0), True, Fact.TRUE),  # each has the other on her port side
        ((90.0, 70.0), True, Fact.FALSE),  # starboard to starboard
        ((270.0, 70.0), True, Fact.FALSE),  # one each side: the geometry of a crossing
        ((270.0, 180.0), True, Fact.FALSE),  # dead astern is on neither side
        ((270.0, 290.0), False, Fact.INSUFFICIENT),  # a course not judged (COG noise)
        ((270.0, math.nan), True, Fact.INSUFFICIENT),
    ],
)
def test_passed_port_to_port(
    bearings_deg: tuple[float, float], judged: bool, expected: Fact
) -> None:
    assert passed_port_to_port(Situation.HEAD_ON, bearings_deg, judged) is expected


def test_passed_port_to_port_is_judged_for_head_on_alone() -> None:
    for situation in (Situation.CROSSING, Situation.OVERTAKING, Situation.NONE):
        assert passed_port_to_port(situation, (270.0, 290.0), True) is None


def test_sandiego_a_channel_passing_port_to_port(sandiego_replay) -> None:
    # CHAMPAGNE and LETO meet in the San Diego Harbor Channel, each to her own starboard
    # side of its axis (+44 m and +21 m), and pass port to port at 93 m: no turn was needed.
    champagne, leto = 367412850, 368103590
    summary = pair_summary(sandiego_replay, champagne, leto)
    assert summary.situation == "head-on"
    assert summary.passed_port_to_port == "true"
    assert summary.give_way_vessel_acted == "false"


def test_a_course_is_drawn_through_a_turn_only_across_a_long_gap_with_a_turn() -> None:
    gap_s = np.array([0.0, 20.0, 120.0, 120.0, 120.0])
    turn_deg = np.array([0.0, 40.0, 40.0, 14.9, np.nan])
    assert course_drawn_through_a_turn(gap_s, turn_deg, PARAMS).tolist() == [
        False,
        False,  # a short gap: the turn is seen closely enough
        True,
        False,  # less than an action's turn
        False,
    ]


def test_a_change_across_the_gap_that_holds_the_closest_approach_is_unknown() -> None:
    # reports at rows 0-2; the closest approach (row 4) is drawn inside a long gap that
    # ends at row 6, where her course has turned 50 deg: she may have turned before it
    observed = np.array([True, True, True, False, False, False, True])
    course = np.array([10.0, 10.0, 10.0, 0.0, 350.0, 340.0, 320.0])
    speed = np.full(7, 6.0)
    result = conduct(course, speed, PARAMS, observed, last_row=4)
    assert (result.changed, result.action) == (Fact.INSUFFICIENT, Action.INSUFFICIENT)
    # the same gap with no change across it: she kept her course
    steady = np.full(7, 10.0)
    assert conduct(steady, speed, PARAMS, observed, last_row=4).action is Action.NONE
    # an action seen at a report before the gap is her first action whatever came after
    turned = np.array([10.0, 40.0, 40.0, 30.0, 20.0, 10.0, 0.0])
    first = conduct(turned, speed, PARAMS, observed, last_row=4)
    assert (first.action, first.action_row) == (Action.STARBOARD_TURN, 1)
    # the closest approach at a report: the rows after it are not read
    at_report = conduct(course, speed, PARAMS, np.ones(7, bool), last_row=2)
    assert at_report.action is Action.NONE


def test_sandiego_a_turn_that_may_have_come_before_the_closest_approach(sandiego_replay) -> None:
    # WELL PLAYED reported 009.5 deg at 00:12:56 and 318.7 deg at 00:14:27; the least
    # separation with TRADITION was drawn at 00:14:06, between the two.
    well_played, tradition = 338307872, 338403914
    summary = pair_summary(sandiego_replay, well_played, tradition)
    assert summary.mmsi_a == well_played
    assert summary.action_a == "insufficient-data"


def test_a_least_separation_over_land_is_flagged() -> None:
    land = shapely.box(100.0, 100.0, 200.0, 200.0)
    window = pd.DataFrame(
        {
            "own_north_m": [0.0, 150.0],
            "own_east_m": [0.0, 150.0],
            "target_north_m": [0.0, 150.0],
            "target_east_m": [50.0, 260.0],
        }
    )
    assert over_land(land, window, 1) is True  # own ship drawn on the land
    assert over_land(land, window, 0) is False
    assert over_land(None, window, 1) is None  # no chart
    assert over_land(land, window, None) is None  # no least separation
    beyond = window.assign(own_north_m=np.nan)  # a pair beyond the run's frame
    assert over_land(land, beyond, 1) is None


def test_sandiego_a_pass_drawn_across_a_spit_is_flagged(sandiego_replay, dma_nmea_replay) -> None:
    # SHELTER ISLAND reported at 00:00:12 and 00:02:12, either side of a spit; the straight
    # line between crosses it, and there she "passed" SAILEBRATE at 55 m.
    flagged = {
        (p.summary.name_a, p.summary.name_b)
        for p in sandiego_replay.pairs
        if p.summary.min_separation_over_land
    }
    assert flagged == {("SHELTER ISLAND", "SAILEBRATE")}
    # without a chart nothing is known of the land
    assert all(p.summary.min_separation_over_land is None for p in dma_nmea_replay.pairs)
