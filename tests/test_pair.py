"""The pair model (``core/pair.py``): one evaluation of a pair, seen from either seat."""

from __future__ import annotations

import dataclasses

import pandas as pd
import pytest
from test_encounters import FRAME, straight_track, tracks_of

from colregs9_cli.core.colregs import ColregsParams, Role, Situation
from colregs9_cli.core.encounters import find_encounters
from colregs9_cli.core.manoeuvrability import ManoeuvrabilityParams
from colregs9_cli.core.pair import evaluate_pair
from colregs9_cli.core.replay_results import pair_outcome
from colregs9_cli.core.rows import seat_series
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
