"""Audit facts (audit.py): the pass, the closest approach and each vessel's conduct."""

from __future__ import annotations

import numpy as np
import pytest

from colregs9_cli.core.audit import (
    Action,
    ConductParams,
    Fact,
    all_of,
    conduct,
    negated,
    passage,
)

PARAMS = ConductParams(
    course_change_deg=15.0,
    speed_change_frac=0.25,
    speed_change_min_kn=1.0,
    course_judged_above_kn=2.0,
)


def test_passage_is_the_first_opening_step_and_the_least_range_before_it() -> None:
    seen = passage([500.0, 300.0, 120.0, 90.0, 100.0, 200.0], [60, 40, 20, 2, -3, -20])
    assert seen.covers_cpa and seen.cpa_row == 3 and seen.min_separation_m == 90.0


def test_data_that_stops_before_the_pass_covers_nothing() -> None:
    seen = passage([500.0, 300.0, 120.0], [60.0, 40.0, 20.0])
    assert not seen.covers_cpa
    assert seen.cpa_row is None and seen.min_separation_m is None


def test_the_trigger_row_itself_never_counts_as_the_pass() -> None:
    assert not passage([100.0, 90.0], [-1.0, 5.0]).covers_cpa


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
