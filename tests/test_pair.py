"""The pair model (``core/pair.py``, ``core/pair_model.py``): one evaluation of a pair, seen
from either seat."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import pandas as pd
import pytest
from test_encounters import FRAME, straight_track, tracks_of

from colregs9_cli.core.colregs import ColregsParams, Role, Situation
from colregs9_cli.core.encounters import Encounter, find_encounters
from colregs9_cli.core.manoeuvrability import ManoeuvrabilityParams
from colregs9_cli.core.pair import evaluate_pair
from colregs9_cli.core.replay_results import pair_outcome
from colregs9_cli.core.rows import seat_series
from colregs9_cli.core.tracks import Tracks
from colregs9_cli.jobs.replay_params import ReplayParams, ReplayRunParams

PARAMS = ReplayRunParams(ReplayParams(), ColregsParams(), ManoeuvrabilityParams(), ())


@pytest.fixture(scope="module")
def crossing():
    """Vessel 2 crosses from vessel 1's starboard side: 1 gives way (rule 15)."""
    own = straight_track(1, -2000.0, 0.0, 0.0, 5.0, 600)
    target = straight_track(2, 0.0, 2000.0, 270.0, 5.0, 600)
    tracks = tracks_of(own, target)
    (encounter,) = find_encounters(tracks, PARAMS.replay.encounters, own_mmsi=[2]).triggered
    return tracks, encounter


def test_a_pair_is_evaluated_in_vessel_order_whichever_seat_found_it(crossing) -> None:
    tracks, encounter = crossing
    assert (encounter.own_mmsi, encounter.target_mmsi) == (2, 1)
    pair = evaluate_pair(tracks, encounter, None, PARAMS.pair)
    assert [v.mmsi for v in pair.vessels] == [1, 2]
    assert pair.verdict.situation is Situation.CROSSING
    assert pair.verdict.role_final == (Role.GIVE_WAY, Role.STAND_ON)
    assert [v.mmsi for v in pair.with_role(Role.GIVE_WAY)] == [1]


def test_each_seat_sees_the_pair_from_its_own_side(crossing) -> None:
    tracks, encounter = crossing
    pair = evaluate_pair(tracks, encounter, None, PARAMS.pair)
    one, two = pair.seen_from(1), pair.seen_from(2)
    assert one.mine(("a", "b")) == ("a", "b") and two.mine(("a", "b")) == ("b", "a")
    assert (one.own.mmsi, one.target.mmsi) == (1, 2)
    assert (two.own.mmsi, two.target.mmsi) == (2, 1)
    assert one.encounter_id.endswith("-1-2") and two.encounter_id.endswith("-2-1")
    with pytest.raises(ValueError, match="MMSI 3"):
        pair.seen_from(3)


def test_both_seats_rows_and_series_mirror_each_other(crossing) -> None:
    tracks, encounter = crossing
    pair = evaluate_pair(tracks, encounter, None, PARAMS.pair)
    outcome = pair_outcome(pair, (1, 2), FRAME)
    first, second = (dataclasses.asdict(seat.summary) for seat in outcome.seats)
    assert (first["own_mmsi"], second["own_mmsi"]) == (1, 2)
    for name, value in first.items():
        if name.startswith("own_"):
            assert second["target_" + name[4:]] == value, name
    assert first["give_way_vessel"] == "own" and second["give_way_vessel"] == "target"
    series = [seat_series(pair.seen_from(m)) for m in (1, 2)]
    pd.testing.assert_series_equal(
        series[0]["beta_deg"], series[1]["beta_prime_deg"], check_names=False
    )
    pd.testing.assert_series_equal(
        series[0]["own_role_final"], series[1]["target_role_final"], check_names=False
    )


def _crossing_reports(kept: Callable[[pd.Series], pd.Series]) -> tuple[Tracks, Encounter]:
    """The crossing above with a 100 m length reported by both, keeping the reports at the
    times ``kept`` chooses: both reach the origin at 400 s."""
    frames = [
        straight_track(1, -2000.0, 0.0, 0.0, 5.0, 800),
        straight_track(2, 0.0, 2000.0, 270.0, 5.0, 800),
    ]
    for frame in frames:
        frame["length_m"] = 100.0
    seconds = pd.concat(frames)["timestamp"].sub(pd.Timestamp("2024-01-01T12:00:00Z"))
    both = pd.concat(frames)[kept(seconds.dt.total_seconds()).to_numpy()]
    tracks = tracks_of(both.reset_index(drop=True))
    (encounter,) = find_encounters(tracks, PARAMS.replay.encounters, own_mmsi=[2]).triggered
    return tracks, encounter


def test_a_least_separation_across_a_long_report_gap_is_flagged() -> None:
    # No reports between 300 s and 500 s: the tracks are interpolated straight to a 0 m
    # "collision" at 400 s, while the real fixes never came closer than at 300 s or 500 s,
    # 500 m from the origin each: √2 · 500 = 707.1 m. 200 s at 5 m/s is 1,000 m > 100 m.
    tracks, encounter = _crossing_reports(lambda t: (t <= 300) | (t >= 500))
    audit = evaluate_pair(tracks, encounter, None, PARAMS.pair).audit
    assert audit.min_separation_m == pytest.approx(0.0, abs=1.0)
    assert audit.min_separation_report_gap_s == pytest.approx(200.0)
    assert audit.min_separation_at_fixes_m == pytest.approx(707.1, abs=0.5)
    assert audit.min_separation_interpolated is True


def test_a_least_separation_between_dense_reports_is_observed() -> None:
    # Reports every 10 s, one at 400 s: the least separation is at a fix; 10 s at 5 m/s is
    # 50 m, half her length.
    tracks, encounter = _crossing_reports(lambda t: t >= 0)
    pair = evaluate_pair(tracks, encounter, None, PARAMS.pair)
    audit = pair.audit
    assert audit.min_separation_report_gap_s == 0.0
    assert audit.min_separation_at_fixes_m == pytest.approx(audit.min_separation_m, abs=1e-6)
    assert audit.min_separation_interpolated is False
    summary = pair_outcome(pair, (1, 2), FRAME).seats[0].summary
    assert summary.min_separation_interpolated is False
    assert summary.min_separation_report_gap_s == 0.0


def test_a_short_gap_through_the_minimum_is_flagged_when_she_outruns_her_length() -> None:
    # Reports every 10 s except 390 s and 400 s: at 400 s both are 20 s into a 30 s gap; 30 s
    # at 5 m/s is 150 m > 100 m, flagged; the fixes at 380 s and 410 s are 100 m and 50 m out.
    tracks, encounter = _crossing_reports(lambda t: (t != 390) & (t != 400))
    audit = evaluate_pair(tracks, encounter, None, PARAMS.pair).audit
    assert audit.min_separation_report_gap_s == pytest.approx(30.0)
    assert audit.min_separation_at_fixes_m == pytest.approx(50.0 * 2**0.5, abs=0.5)
    assert audit.min_separation_interpolated is True
