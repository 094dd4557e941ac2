"""One encounter per passing, and every passing judged (``core/encounters.py``): a speed dip
does not split a passing, and a pair that passes, opens and meets again is judged twice."""

from __future__ import annotations

import dataclasses
import math
from itertools import pairwise

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_encounters import FRAME, PARAMS, T0, T0_S, head_to_head, straight_track, tracks_of

from colregs9_cli.core.encounters import Encounter, find_encounters
from colregs9_cli.core.pair_search import EncounterParams
from colregs9_cli.core.passing import PassingParams
from colregs9_cli.geo import velocity_mps


def legs_track(
    mmsi: int,
    north0_m: float,
    east0_m: float,
    legs: list[tuple[float, float, float]],
    slow: tuple[float, float] | None = None,
) -> pd.DataFrame:
    """Reports every 10 s of a vessel sailing ``legs`` of (seconds, grid course, m/s) in the
    local frame; a report at the end of a leg still carries that leg's course and speed.
    Reports at times in ``slow`` (inclusive) give SOG 0 while the positions move on."""
    times, north, east, course, speed = [0.0], [north0_m], [east0_m], [legs[0][1]], [legs[0][2]]
    for seconds, cog_deg, speed_mps in legs:
        v_n, v_e = (float(v) for v in velocity_mps(speed_mps, cog_deg))
        t0, n0, e0 = times[-1], north[-1], east[-1]
        for k in range(1, int(seconds // 10) + 1):
            times.append(t0 + 10.0 * k)
            north.append(n0 + v_n * 10.0 * k)
            east.append(e0 + v_e * 10.0 * k)
            course.append(cog_deg)
            speed.append(speed_mps)
    t = np.asarray(times)
    lat, lon = FRAME.to_geodetic(np.asarray(north), np.asarray(east))
    sog_kn = np.asarray(speed) * 3600.0 / 1852.0
    if slow is not None:
        sog_kn = np.where((t >= slow[0]) & (t <= slow[1]), 0.0, sog_kn)
    return pd.DataFrame(
        {
            "timestamp": [T0 + pd.Timedelta(seconds=s) for s in t],
            "mmsi": mmsi,
            "lat_deg": lat,
            "lon_deg": lon,
            "sog_kn": sog_kn,
            "cog_deg": FRAME.grid_to_true_deg(np.asarray(course), lat, lon),
            "heading_deg": np.nan,
            "nav_status": 0.0,
        }
    )


def _at(step: int | None) -> int | None:
    return None if step is None else step - T0_S


def pass_and_return() -> tuple[pd.DataFrame, pd.DataFrame]:
    """Own ship north at 5 m/s from the origin; the target south at 5 m/s from 3 km north,
    100 m east, for 500 s, then north at 8 m/s: they pass at t = 300 s, the target turns
    2 km astern of own ship and overtakes her 100 m off. Always within 2 nm."""
    own = straight_track(1, 0.0, 0.0, 0.0, 5.0, 1400)
    target = legs_track(2, 3000.0, 100.0, [(500.0, 180.0, 5.0), (900.0, 0.0, 8.0)])
    return own, target


def test_a_pass_an_opening_and_a_second_approach_are_two_encounters() -> None:
    search = find_encounters(tracks_of(*pass_and_return()), PARAMS.encounters, own_mmsi=[1])
    first, second = search.encounters
    # One candidate run from t = 0 to 1400, cut where the first passing opened.
    assert (_at(first.start_step), _at(second.end_step)) == (0, 1400)
    # Head-on, closing at 10 m/s: TCPA = (3000 − 10t)/10 <= 180 from t = 120 (a hair later
    # in the geodesic geometry, as in test_encounters.test_trigger_step_is_exact).
    assert _at(first.trigger_step) in (120, 121)
    # Least range 100 m at t = 300; opened above 100 + max(100, 50) = 200 m, where the
    # along-track gap 10·(t − 300) exceeds √(200² − 100²) = 173.2 m: t = 318.
    assert _at(first.opened_step) == 318
    assert _at(first.end_step) == 318 and _at(second.start_step) == 319
    # The target turns at t = 500, 2000 m astern, and closes at 3 m/s: the gap 3500 − 3t
    # gives TCPA = (3500 − 3t)/3 <= 180 from t = 986.67, so 987. Least 100 m at t = 1166.7;
    # opened where 3·(t − 1166.67) > 173.2: t = 1225.
    assert _at(second.trigger_step) == 987
    assert _at(second.opened_step) == 1225
    assert first.min_range_m == pytest.approx(100.0, abs=0.1)
    assert second.min_range_m == pytest.approx(100.0, abs=0.1)
    assert second.cpa_m_at_trigger == pytest.approx(100.0, abs=0.1)
    assert (first.encounter_id, second.encounter_id) == (
        "20240101T120000-1-2",
        "20240101T120519-1-2",
    )
    assert first.chain_start_step == second.chain_start_step == first.start_step
    # Both seats see the same two passings.
    both = find_encounters(tracks_of(*pass_and_return()), PARAMS.encounters).encounters
    assert [(e.own_mmsi, _at(e.start_step), _at(e.trigger_step)) for e in both] == [
        (1, 0, _at(first.trigger_step)),
        (2, 0, _at(first.trigger_step)),
        (1, 319, 987),
        (2, 319, 987),
    ]


def test_a_second_approach_before_the_range_has_opened_is_the_same_passing() -> None:
    # With a margin of 3 km the range never opens: one passing, triggered once, to the end
    # of the run. Its passing did not open within its follow window.
    wide = dataclasses.replace(PARAMS.encounters, passing=PassingParams(open_m=3000.0))
    (encounter,) = find_encounters(tracks_of(*pass_and_return()), wide, own_mmsi=[1]).encounters
    assert (_at(encounter.start_step), _at(encounter.end_step)) == (0, 1400)
    assert _at(encounter.trigger_step) in (120, 121)
    assert encounter.opened_step is None


def _dip(target: pd.DataFrame, start_s: int, end_s: int) -> pd.DataFrame:
    """The target reports SOG 0 from ``start_s`` to ``end_s`` (positions move on). SOG is
    linear between reports 10 s apart: below 0.5 kn from ``start_s`` to ``end_s``."""
    slow = target["timestamp"].between(
        T0 + pd.Timedelta(seconds=start_s), T0 + pd.Timedelta(seconds=end_s)
    )
    return target.assign(sog_kn=np.where(slow, 0.0, target["sog_kn"]))


def test_a_speed_dip_in_the_middle_of_a_passing_is_one_encounter() -> None:
    # Head-on 100 m apart (test_encounters.test_trigger_step_is_exact): candidates from
    # t = 630 to 1370, trigger at t = 820, closest at t = 1000. The target reports SOG 0 at
    # t = 900, 910 and 920: a dip of 21 steps (900..920), between the trigger and the pass.
    own, target = head_to_head(100.0)
    search = find_encounters(
        tracks_of(own, _dip(target, 900, 920)), PARAMS.encounters, own_mmsi=[1]
    )
    (encounter,) = search.encounters
    assert (_at(encounter.start_step), _at(encounter.end_step)) == (630, 1370)
    assert _at(encounter.trigger_step) in (820, 821)
    # The range through the dip counts: least 100 m at t = 1000, opened above 200 m, where
    # 10·(t − 1000) > 173.2: t = 1018.
    assert _at(encounter.opened_step) == 1018
    assert encounter.min_range_m == pytest.approx(100.0, abs=0.1)
    # The candidate steps are those of the two runs only: 630..899 and 921..1370.
    assert search.candidate_pair_steps == (899 - 630 + 1) + (1370 - 921 + 1)


def test_a_run_after_the_opening_is_an_encounter_of_its_own() -> None:
    # The dip comes after the pass (t = 1010..1100), and the range opened during it (1018):
    # the run after it is another encounter, and it never triggers (the pair is opening).
    own, target = head_to_head(100.0)
    search = find_encounters(
        tracks_of(own, _dip(target, 1010, 1100)), PARAMS.encounters, own_mmsi=[1]
    )
    first, second = search.encounters
    assert (_at(first.start_step), _at(first.end_step), _at(first.opened_step)) == (630, 1009, 1018)
    assert (_at(second.start_step), _at(second.end_step)) == (1101, 1370)
    assert not second.triggered
    assert second.chain_start_step == first.start_step  # a firing within its reach before it


def parallel_overtaking(slow: tuple[float, float]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Own ship north at 5 m/s; the target 300 m astern and 100 m east at 5.2 m/s, closing at
    0.2 m/s: TCPA = 1500 − t <= 180 from t = 1320, closest (100 m) at t = 1500, and the
    range opened past 200 m where 0.2·(t − 1500) > 173.2: t = 2367. Own ship reports SOG 0
    in ``slow``: after the pass she falls behind, so the pair is opening when she speeds up
    again and nothing fires."""
    own = legs_track(1, 0.0, 0.0, [(3000.0, 0.0, 5.0)], slow=slow)
    target = straight_track(2, -300.0, 100.0, 0.0, 5.2, 3000)
    return own, target


@pytest.mark.parametrize(("slow_until", "joined"), [(2050, True), (2200, False)])
def test_a_run_within_the_follow_window_joins_the_passing(slow_until: int, joined: bool) -> None:
    # The follow window ends at the trigger + TCPA + 600 s = 1320 + 180 + 600 = 2100. A run
    # that starts at 2051, before the range has opened (2367), joins the passing; one that
    # starts at 2201 is past the window: an encounter of its own.
    own, target = parallel_overtaking((1600.0, float(slow_until)))
    search = find_encounters(tracks_of(own, target), PARAMS.encounters, own_mmsi=[1])
    spans = [(_at(e.start_step), _at(e.end_step), _at(e.trigger_step)) for e in search.encounters]
    trigger = _at(search.encounters[0].trigger_step)
    assert trigger in (1320, 1321)
    if joined:
        assert spans == [(0, 3000, trigger)]
        assert _at(search.encounters[0].opened_step) == 2367
    else:
        assert spans == [(0, 1599, trigger), (slow_until + 1, 3000, None)]
        # its passing opened only after the window the evaluation follows
        assert search.encounters[0].opened_step is None


def test_the_chain_reaches_back_by_the_longest_follow_window() -> None:
    params = EncounterParams()
    assert params.chain_steps(1.0) == math.ceil(180.0 + 600.0)
    assert params.chain_steps(2.0) == 390
    assert dataclasses.replace(params, tcpa_act_s=60.0).chain_steps(1.0) == 660


# --- properties ------------------------------------------------------------------------------


@st.composite
def wandering_tracks(draw) -> list[pd.DataFrame]:
    """Three vessels within a few kilometres, each on two or three legs (turns that bring
    pairs back together), one of them with a speed dip of up to a minute."""
    frames = []
    for mmsi in (1, 2, 3):
        legs = [
            (
                float(draw(st.integers(20, 60)) * 10),
                float(draw(st.integers(0, 35)) * 10),
                float(draw(st.integers(2, 8))),
            )
            for _ in range(draw(st.integers(2, 3)))
        ]
        slow = None
        if mmsi == 1:
            start = draw(st.integers(0, 120)) * 10.0
            slow = (start, start + draw(st.integers(0, 6)) * 10.0)
        frames.append(
            legs_track(
                mmsi,
                float(draw(st.integers(-15, 15)) * 100),
                float(draw(st.integers(-15, 15)) * 100),
                legs,
                slow=slow,
            )
        )
    return frames


def _pair_encounters(encounters: tuple[Encounter, ...]) -> dict[tuple[int, int], list[Encounter]]:
    found: dict[tuple[int, int], list[Encounter]] = {}
    for encounter in encounters:
        found.setdefault((encounter.own_mmsi, encounter.target_mmsi), []).append(encounter)
    return found


# Wider CPA_req and shorter follow windows than the defaults: more passings, chains and splits
# in a few minutes of tracks. The properties hold for any parameters.
search_params = st.builds(
    EncounterParams,
    cpa_req_m=st.sampled_from([150.0, 400.0, 800.0]),
    passing=st.builds(
        PassingParams,
        open_m=st.sampled_from([50.0, 100.0]),
        follow_s=st.sampled_from([60.0, 200.0, 600.0]),
    ),
)


@settings(max_examples=40, deadline=None)
@given(frames=wandering_tracks(), cut=st.integers(0, 900), params=search_params)
def test_encounters_depend_on_nothing_before_their_chain(
    frames, cut: int, params: EncounterParams
) -> None:
    """What slabs rely on: the search over the tracks from any step on gives the same
    encounters, wherever their chain starts a follow window or more after that step; and
    every pair's encounters are disjoint, in order, each triggered within its span, a split
    one starting right after the opening before it."""
    tracks = tracks_of(*frames)
    whole = find_encounters(tracks, params)
    later = dataclasses.replace(
        tracks, samples=tracks.samples[tracks.samples["step"] >= T0_S + cut].reset_index(drop=True)
    )
    cut_search = find_encounters(later, params)
    chain_steps = params.chain_steps(tracks.step_s)
    settled = [e for e in whole.encounters if e.chain_start_step - chain_steps >= T0_S + cut]
    assert [e for e in cut_search.encounters if e in settled] == settled
    for mine in _pair_encounters(whole.encounters).values():
        for before, after in pairwise(mine):
            assert before.end_step < after.start_step
            if after.start_step == before.end_step + 1 and after.triggered:
                assert before.opened_step == before.end_step
        for encounter in mine:
            assert encounter.start_step <= encounter.end_step
            assert encounter.chain_start_step <= encounter.start_step
            if encounter.trigger_step is not None:
                assert encounter.start_step <= encounter.trigger_step <= encounter.end_step
