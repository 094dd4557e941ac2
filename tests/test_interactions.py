"""Interactions: encounter, in-company, alongside, service, not-making-way (DESIGN §7).

Hand-built pairs (one per kind, and the close encounters that must stay encounters),
Hypothesis properties (the same kind from both seats, only the window counts, a crossing at
100 m is an encounter), and the triggered pairs of both real fixtures.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from colregs9_cli.ais.clean import SHIP_TYPE_CATEGORIES
from colregs9_cli.ais.load import load_ais
from colregs9_cli.core.encounters import (
    Encounter,
    encounter_series,
    find_encounters,
)
from colregs9_cli.core.interactions import (
    SERVICE_SHIP_TYPES,
    Interaction,
    InteractionKind,
    InteractionParams,
    VesselFacts,
    classify_interaction,
    under_way_from,
    window_steps,
)
from colregs9_cli.core.pair import pair_tracks
from colregs9_cli.core.tracks import Tracks, build_tracks
from colregs9_cli.errors import ParameterError
from colregs9_cli.geo import LocalFrame
from colregs9_cli.jobs.replay_params import ReplayParams
from colregs9_cli.units import MPS_PER_KNOT

from fixture_files import NMEA, SANDIEGO_AIS, pair_summary

FRAME = LocalFrame(56.0, 12.6)
STEP0 = 1_700_000_000  # the grid step of a hand-built series' first row (1 s steps)
PARAMS = InteractionParams()
KIND = InteractionKind


# --- hand-built series ----------------------------------------------------------------------


def path(
    start_ne: tuple[float, float], legs: Sequence[tuple[float, float, float]]
) -> NDArray[np.float64]:
    """Positions (north, east; m) every second of a vessel sailing ``legs`` of
    (seconds, course_deg, speed_kn) from ``start_ne``; the first row is the start."""
    points = [np.asarray(start_ne, dtype=float)]
    for seconds, course_deg, speed_kn in legs:
        step = (
            speed_kn
            * MPS_PER_KNOT
            * np.array([math.cos(math.radians(course_deg)), math.sin(math.radians(course_deg))])
        )
        for _ in range(int(seconds)):
            points.append(points[-1] + step)
    return np.array(points)


def pair_series(
    own_ne: NDArray[np.float64],
    target_ne: NDArray[np.float64],
    own_sog_kn: float | NDArray[np.float64] | None = None,
    target_sog_kn: float | NDArray[np.float64] | None = None,
    nav_status: tuple[int | None, int | None] = (0, 0),
) -> pd.DataFrame:
    """An ``encounter_series``-like frame of two vessels' positions (1 s steps, the frame's
    north and east); SOG defaults to the speed along the positions."""
    n = min(len(own_ne), len(target_ne))
    series = pd.DataFrame({"step": STEP0 + np.arange(n)})
    series["timestamp"] = pd.to_datetime(series["step"], unit="s", utc=True)
    for prefix, ne, sog in (
        ("own_", own_ne[:n], own_sog_kn),
        ("target_", target_ne[:n], target_sog_kn),
    ):
        lat, lon = FRAME.to_geodetic(ne[:, 0], ne[:, 1])
        series[f"{prefix}lat_deg"] = lat
        series[f"{prefix}lon_deg"] = lon
        series[f"{prefix}north_m"] = ne[:, 0]
        series[f"{prefix}east_m"] = ne[:, 1]
        moves = np.gradient(ne, axis=0) if n > 1 else np.zeros_like(ne)
        speed_kn = np.linalg.norm(moves, axis=1) / MPS_PER_KNOT
        series[f"{prefix}sog_kn"] = speed_kn if sog is None else np.broadcast_to(sog, n)
        status = nav_status[0 if prefix == "own_" else 1]
        series[f"{prefix}nav_status"] = pd.array([status] * n, dtype="Int64")
    return series


def swapped(series: pd.DataFrame) -> pd.DataFrame:
    """The same pair seen from the other seat: own_* and target_* exchanged."""

    def other(column: str) -> str:
        if column.startswith("own_"):
            return "target_" + column.removeprefix("own_")
        if column.startswith("target_"):
            return "own_" + column.removeprefix("target_")
        return column

    return series.rename(columns=other)


def classify(
    series: pd.DataFrame,
    trigger_row: int,
    a: VesselFacts,
    b: VesselFacts,
    params: InteractionParams = PARAMS,
) -> Interaction:
    return classify_interaction(series, trigger_row, (a, b), params, 1.0)


TANKER_A = VesselFacts(1, "Tanker", "Class A", 250.0, 40.0)
TANKER_B = VesselFacts(2, "Tanker", "Class A", 250.0, 40.0)


# --- one hand-built pair per kind --------------------------------------------------------------


def test_tankers_38_m_apart_on_one_course_are_alongside() -> None:
    # The held-out STS pair: 38 m apart at 4.8 kn on the same course, half-breadths
    # 20 + 20 = 40 m: 38 <= 40 + 10 for the whole window (trigger ± 120 s = 240 s).
    own = path((0.0, 0.0), [(400, 45.0, 4.8)])
    target = own + 38.0 * np.array([math.cos(math.radians(135.0)), math.sin(math.radians(135.0))])
    found = classify(pair_series(own, target), 200, TANKER_A, TANKER_B)
    assert found.kind is KIND.ALONGSIDE
    assert found.basis == "range 38 m <= half-breadths 40.0 m + margin 10 m for 240 s"
    assert (found.first_step, found.last_step) == (STEP0 + 80, STEP0 + 320)


def test_unknown_breadths_take_the_default_table_and_say_so() -> None:
    # Two Class A vessels without dimensions: 9.2 m each (vessel_defaults), so
    # half-breadths 9.2 m; 16 m apart is within 9.2 + 10.
    own = path((0.0, 0.0), [(300, 230.0, 2.6)])
    target = own + np.array([16.0, 0.0])
    unknown = (VesselFacts(1, mobile_type="Class A"), VesselFacts(2, mobile_type="Class A"))
    found = classify_interaction(pair_series(own, target), 0, unknown, PARAMS, 1.0)
    assert found.kind is KIND.ALONGSIDE
    assert "half-breadths 9.2 m (defaulted) + margin 10 m for 120 s" in found.basis


def test_a_close_head_on_pass_between_wide_ships_is_not_alongside() -> None:
    # 45 m apart at the pass, inside the 50 m limit, but at 10 kn relative for 8 s only.
    own = path((0.0, 0.0), [(400, 0.0, 5.0)])
    target = path((1029.0, 45.0), [(400, 180.0, 5.0)])
    found = classify(pair_series(own, target), 100, TANKER_A, TANKER_B)
    assert found.kind is KIND.ENCOUNTER
    assert found.basis.startswith("none of the other kinds: 1 at 5.0 kn and 2 at 5.0 kn")


def test_tugs_in_company_turning_together() -> None:
    # Two tugs at 6 kn, one abeam of the other at 60–80 m for 6 min, turning 30° together.
    seconds = np.arange(361)
    course = np.radians(np.where(seconds < 120, 0.0, np.minimum(30.0, (seconds - 120) * 0.25)))
    heading = np.c_[np.cos(course), np.sin(course)]
    own = np.cumsum(heading * 6.0 * MPS_PER_KNOT, axis=0)
    beam = np.c_[-np.sin(course), np.cos(course)]
    offset_m = 70.0 + 10.0 * np.sin(2.0 * np.pi * seconds / 360.0)
    target = own + beam * offset_m[:, None]
    tugs = (
        VesselFacts(1, "Tug", "Class A", 30.0, 10.0),
        VesselFacts(2, "Tug", "Class A", 30.0, 10.0),
    )
    found = classify_interaction(pair_series(own, target), 180, tugs, PARAMS, 1.0)
    assert found.kind is KIND.IN_COMPANY
    # the target keeps her place on own ship's beam as it turns: in the frame of the course
    assert found.basis.startswith("range 60–80 m, relative position along the course within ")
    assert found.basis.endswith("for 240 s")


def test_ships_abreast_turning_together_keep_their_places_over_ground() -> None:
    # Two tugs 70 m abreast at 6 kn turn 40° together, each on the spot: their relative
    # position stays put over ground, while in the frame of their course it swings by
    # 2 · 70 · sin(20°) = 48 m, more than company_drift_m.
    seconds = np.arange(361)
    course = np.radians(np.where(seconds < 120, 0.0, np.minimum(40.0, (seconds - 120) * 0.25)))
    heading = np.c_[np.cos(course), np.sin(course)]
    own = np.cumsum(heading * 6.0 * MPS_PER_KNOT, axis=0)
    target = own + np.array([0.0, 70.0])
    tugs = (
        VesselFacts(1, "Tug", "Class A", 30.0, 10.0),
        VesselFacts(2, "Tug", "Class A", 30.0, 10.0),
    )
    found = classify_interaction(pair_series(own, target), 180, tugs, PARAMS, 1.0)
    assert found.kind is KIND.IN_COMPANY
    assert found.basis.startswith("range 70 m, relative position over ground within 0 m ")


def test_a_slow_overtaking_on_the_same_course_stays_an_encounter() -> None:
    # Courses matched and range 100–118 m: only the relative position, running 62 m along
    # the formation in 4 min at 0.5 kn, tells an overtaking from a convoy.
    own = path((0.0, 0.0), [(400, 90.0, 6.0)])
    target = path((100.0, -62.0), [(400, 90.0, 6.5)])
    found = classify(pair_series(own, target), 200, TANKER_A, TANKER_B)
    assert found.kind is KIND.ENCOUNTER


def test_a_pilot_boat_coming_alongside_a_tanker_is_service() -> None:
    # A 185 m tanker at 10 kn; the pilot boat comes up from astern at 14 kn, 50 m off her
    # side, then holds 60 m from the tanker's antenna at 10 kn (reach 92.5 + 30 m).
    tanker = path((0.0, 0.0), [(400, 90.0, 10.0)])
    pilot = path((50.0, -250.0), [(160, 90.0, 14.0), (240, 90.0, 10.0)])
    facts = (
        VesselFacts(219000001, "Tanker", "Class A", 185.0, 32.0),
        VesselFacts(219000002, "Pilot", "Class A", 18.0, 5.5),
    )
    found = classify_interaction(pair_series(tanker, pilot), 200, facts, PARAMS, 1.0)
    assert found.kind is KIND.SERVICE
    assert found.basis.startswith("service craft 219000002 within ")
    assert "of 219000001 (half-length 92 m + margin 30 m)" in found.basis


def test_a_pilot_boat_crossing_a_tanker_is_an_encounter() -> None:
    tanker = path((0.0, 0.0), [(400, 90.0, 10.0)])
    pilot = path((-1029.0, 1129.0), [(400, 0.0, 10.0)])  # crosses 100 m ahead of her at t = 200 s
    facts = (
        VesselFacts(219000001, "Tanker", "Class A", 185.0, 32.0),
        VesselFacts(219000002, "Pilot", "Class A", 18.0, 5.5),
    )
    found = classify_interaction(pair_series(tanker, pilot), 100, facts, PARAMS, 1.0)
    assert found.kind is KIND.ENCOUNTER


def test_a_towing_vessel_with_her_tow_in_station_is_in_company_not_service() -> None:
    # In station for the whole window: nothing came to work, they sail together.
    tug = path((0.0, 0.0), [(400, 90.0, 5.0)])
    tow = tug + np.array([0.0, -90.0])
    facts = (
        VesselFacts(1, "Towing", "Class A", 30.0, 10.0),
        VesselFacts(2, "Other", "Class A", 80.0, 20.0),
    )
    found = classify_interaction(pair_series(tug, tow), 200, facts, PARAMS, 1.0)
    assert found.kind is KIND.IN_COMPANY


def test_towboats_drifting_side_by_side_are_not_making_way() -> None:
    # The held-out pair: two towboats drifting at 0.2–0.8 kn, 140 m apart, matched drift
    # (in company by range and course, but not making way comes first).
    seconds = np.arange(401)
    drift_kn = 0.5 + 0.3 * np.sin(2.0 * np.pi * seconds / 200.0)
    north = np.cumsum(drift_kn * MPS_PER_KNOT)
    one = np.c_[north, np.zeros_like(north)]
    other = one + np.array([0.0, 140.0])
    towboats = (
        VesselFacts(1, "Towing", "Class A", 25.0, 8.0),
        VesselFacts(2, "Towing", "Class A", 25.0, 8.0),
    )
    found = classify_interaction(pair_series(one, other, 0.6, 0.6), 200, towboats, PARAMS, 1.0)
    assert found.kind is KIND.NOT_MAKING_WAY
    assert found.basis.startswith("1 moved ")
    assert "; 2 moved " in found.basis
    assert "(< 1 kn over ground; reports SOG 0.6 kn)" in found.basis


def test_a_ferry_leaving_her_berth_is_not_making_way_when_the_window_sees_the_berth() -> None:
    # At her berth (moored) until 80 s, then away to 10 kn; the other ferry arrives at 10 kn
    # and passes 150 m off. The trigger is at 110 s, as her SOG passes 0.5 kn.
    leaving = path(
        (0.0, 0.0), [(80, 90.0, 0.0), *((10, 90.0, 0.5 + k) for k in range(10)), (220, 90.0, 10.0)]
    )
    arriving = path((150.0, 1900.0), [(400, 270.0, 10.0)])
    series = pair_series(leaving, arriving, nav_status=(5, 0))
    found = classify(series, 110, VesselFacts(1), VesselFacts(2))
    assert found.kind is KIND.NOT_MAKING_WAY
    assert found.basis == (
        "1 moved 2 m in 89 s from -110 s (< 1 kn over ground; reports SOG 0.0–0.5 kn, moored)"
    )
    # A series cut at the start of the candidate run (her SOG >= 0.5 kn) no longer shows
    # the berth: why the series should start window_steps before the trigger.
    cut = series.iloc[80:].reset_index(drop=True)
    assert classify(cut, 30, VesselFacts(1), VesselFacts(2)).kind is KIND.ENCOUNTER
    assert window_steps(PARAMS, 1.0) == 120
    assert window_steps(PARAMS, 10.0) == 12
    assert window_steps(PARAMS, 7.0) == 18


def test_a_yacht_reporting_102_kn_from_one_position_is_not_making_way() -> None:
    # Her SOG says 102.2 kn for 90 s; her positions never move. A vessel passes 100 m off.
    yacht = path((100.0, 0.0), [(300, 0.0, 0.0)])
    passing = path((0.0, -600.0), [(300, 90.0, 8.0)])
    series = pair_series(yacht, passing, own_sog_kn=102.2, nav_status=(None, 0)).iloc[100:191]
    facts = (VesselFacts(211000001, "Sailing", "Class B"), VesselFacts(211000002, "Cargo"))
    found = classify_interaction(series.reset_index(drop=True), 0, facts, PARAMS, 1.0)
    assert found.kind is KIND.NOT_MAKING_WAY
    assert found.basis == (
        "211000001 moved 0 m in 90 s from +0 s (< 1 kn over ground; reports SOG 102.2 kn)"
    )


def test_two_vessels_crossing_at_100_m_are_an_encounter() -> None:
    own = path((0.0, 0.0), [(400, 0.0, 10.0)])
    target = path((1029.0 + 100.0, 1029.0), [(400, 270.0, 10.0)])  # 100 m ahead at 200 s
    found = classify(pair_series(own, target), 150, TANKER_A, TANKER_B)
    assert found.kind is KIND.ENCOUNTER
    assert found.basis.endswith("over 240 s")


def test_no_positions_at_the_trigger_is_an_encounter_with_nothing_judged() -> None:
    own = path((0.0, 0.0), [(10, 0.0, 10.0)])
    series = pair_series(own, own + 500.0)
    series.loc[5, "own_lat_deg"] = np.nan
    found = classify(series, 5, VesselFacts(1), VesselFacts(2))
    assert (found.kind, found.first_step, found.last_step) == (KIND.ENCOUNTER, -1, -1)


def test_a_gap_in_the_steps_ends_the_window() -> None:
    # Rows after a missing step are another stretch of track: not read.
    own = path((0.0, 0.0), [(300, 0.0, 5.0)])
    target = own + np.array([0.0, 15.0])
    series = pair_series(own, target).drop(index=range(150, 160)).reset_index(drop=True)
    found = classify(series, 100, TANKER_A, TANKER_B)
    assert (found.first_step, found.last_step) == (STEP0, STEP0 + 149)


# --- properties ----------------------------------------------------------------------------

SHIP_TYPES = [None, "Tanker", "Cargo", "Sailing", "Pleasure", "Tug", "Pilot", "Towing", "SAR"]
legs = st.lists(
    st.tuples(
        st.integers(10, 150),
        st.floats(0.0, 359.0),
        st.one_of(st.floats(0.0, 1.2), st.floats(0.0, 14.0)),
    ),
    min_size=1,
    max_size=4,
)
facts_of = st.builds(
    VesselFacts,
    mmsi=st.none(),
    ship_type=st.sampled_from(SHIP_TYPES),
    mobile_type=st.sampled_from([None, "Class A", "Class B"]),
    length_m=st.one_of(st.none(), st.floats(3.0, 400.0)),
    breadth_m=st.one_of(st.none(), st.floats(1.0, 60.0)),
)


def _random_pair(own_legs, target_legs, offset, motion) -> tuple[pd.DataFrame, int]:
    """Two random tracks; with ``motion`` "follow" the target keeps station on own ship at
    ``offset``, with "join" she closes from three times that offset over the first 100 s
    and then keeps station (the close kinds: alongside, in company, service)."""
    own = path((0.0, 0.0), own_legs)
    target = path(offset, target_legs)
    if motion != "free":
        closing = np.clip(1.0 - np.arange(len(own)) / 100.0, 0.0, 1.0) if motion == "join" else 0.0
        target = own + np.asarray(offset) * (1.0 + 2.0 * np.asarray(closing))[..., None]
    n = min(len(own), len(target))
    return pair_series(own[:n], target[:n]), n


motions = st.sampled_from(["free", "follow", "join"])


@settings(max_examples=60)
@given(
    own_legs=legs,
    target_legs=legs,
    offset=st.tuples(st.floats(-300.0, 300.0), st.floats(-300.0, 300.0)),
    motion=motions,
    facts=st.tuples(facts_of, facts_of),
    with_mmsi=st.booleans(),
    trigger=st.floats(0.0, 1.0),
)
def test_both_seats_get_the_same_interaction(
    own_legs, target_legs, offset, motion, facts, with_mmsi, trigger
) -> None:
    series, n = _random_pair(own_legs, target_legs, offset, motion)
    row = min(n - 1, int(trigger * n))
    a, b = facts
    if with_mmsi:
        a, b = VesselFacts(7, *_rest(a)), VesselFacts(3, *_rest(b))
    seen_from_a = classify_interaction(series, row, (a, b), PARAMS, 1.0)
    seen_from_b = classify_interaction(swapped(series), row, (b, a), PARAMS, 1.0)
    assert seen_from_a.kind is seen_from_b.kind
    if with_mmsi:  # vessels named by MMSI: the whole interaction is the same
        assert seen_from_a == seen_from_b


def _rest(facts: VesselFacts) -> tuple:
    return (facts.ship_type, facts.mobile_type, facts.length_m, facts.breadth_m)


@settings(max_examples=60)
@given(
    own_legs=legs,
    target_legs=legs,
    offset=st.tuples(st.floats(-300.0, 300.0), st.floats(-300.0, 300.0)),
    motion=motions,
    facts=st.tuples(facts_of, facts_of),
    trigger=st.floats(0.0, 1.0),
    before=st.integers(0, 200),
    after=st.integers(0, 200),
)
def test_only_the_window_counts(
    own_legs, target_legs, offset, motion, facts, trigger, before, after
) -> None:
    # The same pair, with the rows beyond the window cut off or replaced by other motion.
    series, n = _random_pair(own_legs, target_legs, offset, motion)
    row = min(n - 1, int(trigger * n))
    reach = window_steps(PARAMS, 1.0)
    lo, hi = max(0, row - reach), min(n, row + reach + 1)
    whole = classify_interaction(series, row, facts, PARAMS, 1.0)
    cut = series.iloc[lo:hi].reset_index(drop=True)
    assert classify_interaction(cut, row - lo, facts, PARAMS, 1.0) == whole
    # Other rows beyond the window: the vessels somewhere else entirely (right after the
    # window where it reaches its full length, else after a gap in the steps).
    earlier = pair_series(
        path((5000.0, 0.0), [(before, 0.0, 20.0)]), path((0.0, 5000.0), [(before, 0.0, 3.0)])
    ).iloc[:-1]
    later = pair_series(
        path((0.0, 0.0), [(after, 90.0, 1.0)]), path((-9.0, 0.0), [(after, 90.0, 0.2)])
    ).iloc[1:]
    gap_before = 0 if row - lo == reach else 5
    gap_after = 0 if hi - 1 - row == reach else 5
    earlier["step"] = cut["step"].iloc[0] - gap_before - len(earlier) + np.arange(len(earlier))
    later["step"] = cut["step"].iloc[-1] + 1 + gap_after + np.arange(len(later))
    padded = pd.concat([earlier, cut, later], ignore_index=True)
    assert classify_interaction(padded, row - lo + len(earlier), facts, PARAMS, 1.0) == whole


@settings(max_examples=100)
@given(
    own_course=st.floats(0.0, 359.0),
    angle=st.floats(0.0, 180.0),
    speeds=st.tuples(st.floats(2.0, 20.0), st.floats(2.0, 20.0)),
    cpa_m=st.floats(100.0, 150.0),
    side=st.sampled_from([-1.0, 1.0]),
    tcpa_s=st.floats(0.0, 180.0),
    breadths=st.tuples(st.floats(2.0, 80.0), st.floats(2.0, 80.0)),
    types=st.tuples(
        st.sampled_from(["Tanker", "Cargo", "Passenger", None]),
        st.sampled_from(["Tanker", "Cargo", "Sailing", None]),
    ),
)
def test_vessels_passing_100_m_apart_are_an_encounter(
    own_course, angle, speeds, cpa_m, side, tcpa_s, breadths, types
) -> None:
    # Any two vessels making way that pass 100–150 m apart at 1 kn relative or more, even
    # the widest ships on the same course: never in company, alongside or not making way.
    def velocity(course_deg: float, speed_kn: float) -> NDArray[np.float64]:
        return (
            speed_kn
            * MPS_PER_KNOT
            * np.array([math.cos(math.radians(course_deg)), math.sin(math.radians(course_deg))])
        )

    v_own = velocity(own_course, speeds[0])
    v_target = velocity(own_course + angle, speeds[1])
    v_rel = v_target - v_own
    assume(np.linalg.norm(v_rel) >= 1.0 * MPS_PER_KNOT)
    across = side * np.array([-v_rel[1], v_rel[0]]) / np.linalg.norm(v_rel)
    t = np.arange(601, dtype=float)[:, None]
    t_cpa = 300.0
    own = v_own * t
    target = own + across * cpa_m + v_rel * (t - t_cpa)
    facts = (
        VesselFacts(1, types[0], "Class A", 200.0, breadths[0]),
        VesselFacts(2, types[1], "Class A", 200.0, breadths[1]),
    )
    found = classify_interaction(pair_series(own, target), int(t_cpa - tcpa_s), facts, PARAMS, 1.0)
    assert found.kind is KIND.ENCOUNTER, found.basis


# --- parameters -------------------------------------------------------------------------


def test_service_types_are_the_canonical_spellings() -> None:
    assert set(SHIP_TYPE_CATEGORIES.values()) >= SERVICE_SHIP_TYPES
    assert {SHIP_TYPE_CATEGORIES[code] for code in (31, 32, 50, 51, 52, 53)} == SERVICE_SHIP_TYPES


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("making_way_kn", -1.0),
        ("alongside_margin_m", math.nan),
        ("interaction_window_s", 0.0),
        ("company_course_deg", 200.0),
    ],
)
def test_bad_parameters_name_their_key(key: str, value: float) -> None:
    with pytest.raises(ParameterError, match=rf"\[replay\] {key}"):
        InteractionParams(**{key: value})


def test_thresholds_change_the_kind() -> None:
    # Narrower tankers 38 m apart: half-breadths 10 + 10 m, so 38 m is beyond 20 + 10 m and
    # they are merely in company; a margin of 20 m makes them alongside.
    own = path((0.0, 0.0), [(400, 45.0, 4.8)])
    target = own + np.array([38.0, 0.0])
    narrow = (
        VesselFacts(1, "Tanker", "Class A", 250.0, 20.0),
        VesselFacts(2, "Tanker", "Class A", 250.0, 20.0),
    )
    series = pair_series(own, target)
    assert classify_interaction(series, 200, narrow, PARAMS, 1.0).kind is KIND.IN_COMPANY
    wider = InteractionParams(alongside_margin_m=20.0)
    assert classify_interaction(series, 200, narrow, wider, 1.0).kind is KIND.ALONGSIDE


def test_facts_from_a_tracks_row() -> None:
    row = {
        "ship_type": "Tug",
        "mobile_type": "Class A",
        "length_m": np.nan,
        "breadth_m": 9.0,
        "name": "X",
    }
    assert VesselFacts.from_static(219000001, row) == VesselFacts(
        219000001, "Tug", "Class A", None, 9.0
    )
    assert VesselFacts.from_static(5, {}) == VesselFacts(5)


# --- the real fixtures -----------------------------------------------------------------------


def _pair_series(
    tracks: Tracks, encounter: Encounter, replay: ReplayParams
) -> tuple[pd.DataFrame, int]:
    """A triggered pair's series in vessel order (a, b) as the pair evaluation builds it,
    from ``window_steps`` before the trigger, cut at gaps; and the trigger's row."""
    assert encounter.trigger_step is not None and encounter.tcpa_s_at_trigger is not None
    a, b = sorted((encounter.own_mmsi, encounter.target_mmsi))
    oriented = dataclasses.replace(encounter, own_mmsi=a, target_mmsi=b)
    horizon = math.ceil(
        (encounter.tcpa_s_at_trigger + replay.encounters.tcpa_act_s) / tracks.step_s
    )
    series = encounter_series(
        pair_tracks(tracks, (a, b)),
        oriented,
        from_step=encounter.trigger_step - window_steps(PARAMS, tracks.step_s),
        to_step=max(encounter.end_step, encounter.trigger_step + horizon),
    )
    trigger_row = int(np.flatnonzero(series["step"].to_numpy() == encounter.trigger_step)[0])
    return series, trigger_row


def _classified(ais_path: Path) -> dict[tuple[int, int], Interaction]:
    replay = ReplayParams()
    positions = load_ais([ais_path]).positions
    frame = LocalFrame(float(positions["lat_deg"].mean()), float(positions["lon_deg"].mean()))
    tracks = build_tracks(positions, frame, replay.tracks)
    found: dict[tuple[int, int], Interaction] = {}
    for encounter in find_encounters(tracks, replay.encounters).triggered:
        a, b = sorted((encounter.own_mmsi, encounter.target_mmsi))
        if (a, b) in found:
            continue
        series, trigger_row = _pair_series(tracks, encounter, replay)
        facts = (
            VesselFacts.from_static(a, tracks.vessels.loc[a].to_dict()),
            VesselFacts.from_static(b, tracks.vessels.loc[b].to_dict()),
        )
        found[a, b] = classify_interaction(series, trigger_row, facts, PARAMS, tracks.step_s)
    return found


@pytest.fixture(scope="module")
def dma() -> dict[tuple[int, int], Interaction]:
    return _classified(NMEA)


@pytest.fixture(scope="module")
def sandiego() -> dict[tuple[int, int], Interaction]:
    return _classified(SANDIEGO_AIS)


def test_the_dma_tow_is_alongside(dma: dict[tuple[int, int], Interaction]) -> None:
    # 219017105 and 219018499: 13–16 m apart at 2.6 kn, turning together.
    tow = dma[219017105, 219018499]
    assert tow.kind is KIND.ALONGSIDE
    assert tow.basis == "range 13–16 m <= half-breadths 6.6 m (defaulted) + margin 10 m for 120 s"


def test_ferries_berthing_and_unberthing_are_not_making_way(
    dma: dict[tuple[int, int], Interaction],
) -> None:
    helsingor = dma[219230000, 219622000]  # 219622000 leaves her berth as the other arrives
    assert helsingor.kind is KIND.NOT_MAKING_WAY
    assert helsingor.basis.startswith("219622000 moved 2 m in 38 s from -37 s")
    helsingborg = dma[219000368, 265041000]  # 265041000 comes to her berth
    assert helsingborg.kind is KIND.NOT_MAKING_WAY
    assert helsingborg.basis.startswith("265041000 moved 10 m in 53 s from +67 s")


def test_every_dma_pair(dma: dict[tuple[int, int], Interaction]) -> None:
    assert {pair: found.kind.value for pair, found in dma.items()} == {
        (211546840, 636092478): "encounter",  # Kiel Fjord, converging at 12–21 kn
        (234607000, 636092297): "encounter",  # Kiel Canal, head-on
        (211356520, 211558470): "encounter",  # off Warnemünde, crossing
        (219017105, 219018499): "alongside",  # the tow
        (219000368, 265041000): "not-making-way",  # Helsingborg ferries
        (219230000, 219622000): "not-making-way",  # Helsingør ferries
        (218278000, 304011028): "encounter",  # Kiel Canal at Rendsburg, head-on
        (211219630, 211231520): "not-making-way",  # Holtenau locks: 0.6 kn over ground
        (211231520, 245281000): "encounter",  # Holtenau: 245281000 makes 1.0–1.5 kn
        (211445190, 234607000): "not-making-way",  # TILSIT at rest before the trigger
        (211440340, 211457700): "not-making-way",  # both at rest (211457700 reports 0.7–1.8 kn)
        (265518160, 265548350): "not-making-way",  # 265518160 at rest, reporting 0.5 kn
    }


def test_every_san_diego_pair(sandiego: dict[tuple[int, int], Interaction]) -> None:
    kinds = {pair: found.kind.value for pair, found in sandiego.items()}
    resting = {(338254678, 338330158), (338330158, 368059810)}  # GET KNOTTY at her mooring
    assert len(kinds) == 19
    assert {pair for pair, kind in kinds.items() if kind != "encounter"} == resting
    assert all(kinds[pair] == "not-making-way" for pair in resting)
    # TRADITION and CHAMPAGNE; WELL PLAYED and TRADITION passing 7 m apart at 20 kn;
    # FREEDOM overtaken by CASSIOPEIA 30 m off on the same course
    for pair in ((338403914, 367412850), (338307872, 338403914), (338208033, 367648260)):
        assert kinds[pair] == "encounter"
    assert sandiego[338330158, 368059810].basis.startswith(
        "338330158 moved 9 m in 180 s from -60 s (< 1 kn over ground; reports SOG 0.5 kn)"
    )


# --- a pair not making way at its trigger, under way later in the passing -------------------


def test_under_way_from_finds_where_both_make_way_for_the_rest_span() -> None:
    # At her berth until 80 s, then away to 10 kn; the other vessel at 10 kn throughout.
    leaving = path(
        (0.0, 0.0), [(80, 90.0, 0.0), *((10, 90.0, 0.5 + k) for k in range(10)), (220, 90.0, 10.0)]
    )
    arriving = path((150.0, 1900.0), [(400, 270.0, 10.0)])
    series = pair_series(leaving, arriving)
    first, held = under_way_from(series, (VesselFacts(1), VesselFacts(2)), PARAMS, 1.0)
    # 1 kn over ground, measured over 30 s centred on each step, is reached after 80 s
    assert 80 < first < 100
    assert held - first == math.ceil(PARAMS.at_rest_min_s)
    # ... and a vessel that never leaves her berth never is
    moored = path((0.0, 0.0), [(400, 90.0, 0.0)])
    assert (
        under_way_from(pair_series(moored, arriving), (VesselFacts(1), VesselFacts(2)), PARAMS, 1.0)
        is None
    )


def test_dma_the_helsingor_ferries_are_judged_when_both_are_under_way(dma_nmea_replay) -> None:
    # 219622000 lay at her berth at the trigger (12:00:39) and left it at about 12:00:45; at
    # 12:02:26-34 both ferries made 9-10 kn 153-175 m apart: judged from when both made way.
    summary = pair_summary(dma_nmea_replay, 219230000, 219622000)
    assert summary.interaction == "encounter"
    assert summary.interaction_basis.startswith("judged from 12:01:09, both under way")
    assert summary.trigger_utc == pd.Timestamp("2013-11-12 12:01:09", tz="UTC")
    # 6.8 deg off one bow, 2.3 deg off the other: head-on in doubt (rule 14(c))
    assert (summary.situation, summary.situation_basis) == ("head-on", "head-on in doubt")
    # a pair that stays at rest keeps its kind: the moored pair at Svendborg
    moored = pair_summary(dma_nmea_replay, 265518160, 265548350)
    assert moored.interaction == "not-making-way"
