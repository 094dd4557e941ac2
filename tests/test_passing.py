"""When a passing is over (``core/passing.py``): the range opened clearly past its minimum."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from colregs9_cli.core.passing import PassingParams, horizon_steps, minimum_evidence, passing

PARAMS = PassingParams()


def test_a_plain_pass_ends_when_the_range_has_opened_by_the_margin() -> None:
    ranges = [500.0, 300.0, 120.0, 100.0, 150.0, 199.0, 201.0, 400.0]
    seen = passing(ranges, PARAMS)
    # least 100 m: opened above 100 + max(100, 50) = 200 m, at row 6
    assert (seen.covers_cpa, seen.end_row, seen.cpa_row, seen.min_separation_m) == (
        True,
        6,
        3,
        100.0,
    )


def test_a_turn_away_that_does_not_open_clearly_is_not_the_pass() -> None:
    # TCPA turned negative at 1,068 m (a turn away), then the vessels closed to 97 m: the
    # first pass the old rule declared; the range never opened by half again before that.
    ranges = [1300.0, 1068.0, 1100.0, 1200.0, 900.0, 400.0, 97.0, 150.0, 250.0]
    seen = passing(ranges, PARAMS)
    assert seen.covers_cpa and seen.min_separation_m == 97.0 and seen.cpa_row == 6
    assert seen.end_row == 8  # 250 > 97 + 100


def test_the_margin_grows_with_the_least_range() -> None:
    ranges = [1000.0, 1400.0, 1501.0]
    seen = passing(ranges, PARAMS)
    assert seen.end_row == 2 and seen.min_separation_m == 1000.0  # 1000 + 500


def test_data_that_stops_before_the_opening_does_not_cover_the_pass() -> None:
    ranges = [318.0, 295.0, 280.0, 295.0, 262.0, 300.0, 250.0]
    seen = passing(ranges, PARAMS)
    assert not seen.covers_cpa
    assert seen.end_row == 6 and seen.cpa_row == 6 and seen.min_separation_m == 250.0
    empty = passing([], PARAMS)
    assert (empty.covers_cpa, empty.cpa_row, empty.min_separation_m) == (False, None, None)
    unknown = passing([math.nan, math.nan], PARAMS)
    assert unknown.cpa_row is None and unknown.min_separation_m is None


def test_the_horizon_follows_the_predicted_closest_approach() -> None:
    assert horizon_steps(172.0, PARAMS, 1.0) == 772
    assert horizon_steps(-5.0, PARAMS, 2.0) == 300


@given(st.lists(st.floats(0.0, 5000.0), min_size=1, max_size=60))
def test_the_pass_is_the_first_clear_opening_and_its_least_range(ranges: list[float]) -> None:
    seen = passing(ranges, PARAMS)
    values = np.asarray(ranges)
    assert seen.min_separation_m == values[: seen.end_row + 1].min()
    for row in range(seen.end_row if seen.covers_cpa else len(values)):
        least = values[: row + 1].min()
        assert values[row] <= least + max(PARAMS.open_m, PARAMS.open_frac * least)
    if seen.covers_cpa:
        least = values[: seen.end_row + 1].min()
        assert values[seen.end_row] > least + max(PARAMS.open_m, PARAMS.open_frac * least)


@given(
    st.lists(st.floats(0.0, 5000.0), min_size=1, max_size=40),
    st.lists(st.sampled_from([0.0, 0.5, 3.0, 60.0]), min_size=80, max_size=80),
)
def test_the_least_range_at_fixes_is_never_below_the_least_range(
    ranges: list[float], nearest: list[float]
) -> None:
    n = len(ranges)
    seen = passing(ranges, PassingParams())
    near = np.reshape(nearest[: 2 * n], (n, 2))
    evidence = minimum_evidence(
        ranges, near * 2, near, np.full((n, 2), 5.0), (100.0, 100.0), seen, 1.0
    )
    assert evidence is not None and seen.min_separation_m is not None
    if evidence.at_fixes_m is not None:
        assert evidence.at_fixes_m >= seen.min_separation_m
    at_cpa = near[seen.cpa_row]
    assert evidence.report_gap_s == 2 * at_cpa.max()
    assert evidence.interpolated == bool((2 * at_cpa * 5.0 > 100.0).any())
