"""Encounters: CPA/TCPA, the grid pair search, runs, triggers and own-ship seats."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pyproj import Geod

from colregs9_cli.core import encounters as encounters_module
from colregs9_cli.core.encounters import (
    SERIES_VESSEL_COLUMNS,
    encounter_series,
    find_encounters,
)
from colregs9_cli.core.pair_search import candidate_pairs, cpa_tcpa, trigger_mask
from colregs9_cli.core.tracks import build_tracks
from colregs9_cli.errors import NoDataError, ParameterError, QueryError
from colregs9_cli.geo import LocalFrame, velocity_mps
from colregs9_cli.jobs.replay_params import ReplayParams, replay_params_from_table
from colregs9_cli.units import (
    knots_to_mps,
    metres_to_nautical_miles,
    mps_to_knots,
    nautical_miles_to_metres,
)

FRAME = LocalFrame(57.05, 9.94)
T0 = pd.Timestamp("2024-01-01T12:00:00Z")
T0_S = 1_704_110_400
PARAMS = ReplayParams()


def straight_track(
    mmsi: int, north0_m: float, east0_m: float, cog_deg: float, speed_mps: float, end_s: int
) -> pd.DataFrame:
    """Reports every 10 s of a vessel on a straight line, given in the local frame.

    ``cog_deg`` is the line's grid direction; the reports carry it as the true COG an AIS
    transponder would send there (grid + meridian convergence).
    """
    t = np.arange(0, end_s + 1, 10, dtype=float)
    v_n, v_e = velocity_mps(speed_mps, cog_deg)
    lat, lon = FRAME.to_geodetic(north0_m + v_n * t, east0_m + v_e * t)
    return pd.DataFrame(
        {
            "timestamp": [T0 + pd.Timedelta(seconds=s) for s in t],
            "mmsi": mmsi,
            "lat_deg": lat,
            "lon_deg": lon,
            "sog_kn": speed_mps * 3600 / 1852,
            "cog_deg": FRAME.grid_to_true_deg(cog_deg, lat, lon),
            "heading_deg": np.nan,
            "nav_status": 0.0,
        }
    )


def tracks_of(*frames: pd.DataFrame, params: ReplayParams = PARAMS):
    return build_tracks(pd.concat(frames, ignore_index=True), FRAME, params.tracks)


# --- CPA / TCPA ---------------------------------------------------------------------------


def test_cpa_tcpa_hand_worked_crossing() -> None:
    # Own ship at the origin heading north at 4 m/s: v_o = (4, 0) (north, east).
    # Target 1200 m north, 1500 m east, heading west at 6 m/s: v_t = (0, −6).
    # p = (1200, 1500), v = v_t − v_o = (−4, −6), |v|² = 16 + 36 = 52.
    # p·v = −4800 − 9000 = −13800, so TCPA = 13800 / 52 = 265.3846 s.
    # p + v·TCPA = (1200 − 1061.538, 1500 − 1592.308) = (138.462, −92.308),
    # CPA = √(138.462² + 92.308²) = 166.410 m, which is also |p × v| / |v| = 1200 / √52.
    v_on, v_oe = velocity_mps(4.0, 0.0)
    v_tn, v_te = velocity_mps(6.0, 270.0)
    cpa_m, tcpa_s = cpa_tcpa(1200.0, 1500.0, v_tn - v_on, v_te - v_oe)
    assert tcpa_s == pytest.approx(13800.0 / 52.0)
    assert tcpa_s == pytest.approx(265.3846, abs=1e-4)
    assert cpa_m == pytest.approx(1200.0 / math.sqrt(52.0))
    assert cpa_m == pytest.approx(166.410, abs=1e-3)


def test_cpa_tcpa_opening_gives_negative_tcpa() -> None:
    cpa_m, tcpa_s = cpa_tcpa(100.0, 0.0, 2.0, 0.0)  # target ahead and pulling away
    assert tcpa_s == pytest.approx(-50.0)
    assert cpa_m == pytest.approx(0.0)


def test_cpa_tcpa_without_relative_motion_is_the_current_range() -> None:
    cpa_m, tcpa_s = cpa_tcpa([300.0, 0.0], [400.0, 0.0], [0.0, 0.0], [0.0, 0.0])
    assert tcpa_s.tolist() == [0.0, 0.0]
    assert cpa_m.tolist() == [500.0, 0.0]


def test_cpa_tcpa_unknown_velocity_is_nan() -> None:
    cpa_m, tcpa_s = cpa_tcpa(100.0, 0.0, np.nan, 1.0)
    assert np.isnan(cpa_m) and np.isnan(tcpa_s)
    assert not trigger_mask(cpa_m, tcpa_s, np.nan, PARAMS.encounters)


coordinate = st.floats(-20_000, 20_000, allow_nan=False)
speed = st.floats(0.0, 15.0, allow_nan=False)
course = st.floats(0.0, 359.999, allow_nan=False)


@given(coordinate, coordinate, coordinate, coordinate, speed, course, speed, course)
def test_cpa_is_the_same_with_the_vessels_swapped(
    own_n: float,
    own_e: float,
    tgt_n: float,
    tgt_e: float,
    own_speed: float,
    own_course: float,
    tgt_speed: float,
    tgt_course: float,
) -> None:
    own_v = velocity_mps(own_speed, own_course)
    tgt_v = velocity_mps(tgt_speed, tgt_course)
    seen_from_own = cpa_tcpa(tgt_n - own_n, tgt_e - own_e, tgt_v[0] - own_v[0], tgt_v[1] - own_v[1])
    seen_from_tgt = cpa_tcpa(own_n - tgt_n, own_e - tgt_e, own_v[0] - tgt_v[0], own_v[1] - tgt_v[1])
    assert seen_from_tgt[0] == pytest.approx(seen_from_own[0], rel=1e-9, abs=1e-6)
    assert seen_from_tgt[1] == pytest.approx(seen_from_own[1], rel=1e-9, abs=1e-6)


@given(coordinate, coordinate, coordinate, coordinate, speed, course, speed, course, coordinate)
def test_cpa_is_invariant_under_translation(
    own_n: float,
    own_e: float,
    tgt_n: float,
    tgt_e: float,
    own_speed: float,
    own_course: float,
    tgt_speed: float,
    tgt_course: float,
    shift: float,
) -> None:
    own_v = velocity_mps(own_speed, own_course)
    tgt_v = velocity_mps(tgt_speed, tgt_course)
    rel_v = (tgt_v[0] - own_v[0], tgt_v[1] - own_v[1])
    here = cpa_tcpa(tgt_n - own_n, tgt_e - own_e, *rel_v)
    moved = cpa_tcpa((tgt_n + shift) - (own_n + shift), (tgt_e - shift) - (own_e - shift), *rel_v)
    assert moved[0] == pytest.approx(here[0], rel=1e-6, abs=1e-5)
    assert moved[1] == pytest.approx(here[1], rel=1e-6, abs=1e-5)


@given(coordinate, coordinate, coordinate, coordinate, speed, course)
def test_parallel_courses_at_equal_speed_never_trigger(
    own_n: float,
    own_e: float,
    tgt_n: float,
    tgt_e: float,
    common_speed: float,
    common_course: float,
) -> None:
    own_v = velocity_mps(common_speed, common_course)
    tgt_v = velocity_mps(common_speed, common_course)
    rel_v = (tgt_v[0] - own_v[0], tgt_v[1] - own_v[1])
    cpa_m, tcpa_s = cpa_tcpa(tgt_n - own_n, tgt_e - own_e, *rel_v)
    assert cpa_m == pytest.approx(math.hypot(tgt_n - own_n, tgt_e - own_e))
    assert not trigger_mask(cpa_m, tcpa_s, math.hypot(*rel_v), PARAMS.encounters)


def test_parallel_convoy_within_cpa_req_gives_no_triggered_encounter() -> None:
    # Two vessels 100 m apart (inside CPA_req), same course and speed, for 10 minutes.
    tracks = tracks_of(
        straight_track(1, 0.0, 0.0, 45.0, 5.0, 600), straight_track(2, 0.0, 100.0, 45.0, 5.0, 600)
    )
    search = find_encounters(tracks, PARAMS.encounters)
    assert len(search.encounters) == 2  # a candidate pair from both seats ...
    assert search.triggered == ()  # ... that never triggers


@given(st.floats(0.0, 1e4, allow_nan=False))
def test_knots_round_trip(speed_kn: float) -> None:
    assert float(mps_to_knots(knots_to_mps(speed_kn))) == pytest.approx(speed_kn, rel=1e-12)


@given(st.floats(0.0, 1e5, allow_nan=False))
def test_nautical_miles_round_trip(distance_nm: float) -> None:
    metres = nautical_miles_to_metres(distance_nm)
    assert float(metres_to_nautical_miles(metres)) == pytest.approx(distance_nm, rel=1e-12)


def test_unit_constants() -> None:
    assert float(knots_to_mps(1.0)) == pytest.approx(0.514444, abs=1e-6)
    assert float(nautical_miles_to_metres(2.0)) == 3704.0
    assert PARAMS.candidate_range_m == 3704.0


# --- the grid pair search -----------------------------------------------------------------


def brute_force_pairs(
    step: np.ndarray, north: np.ndarray, east: np.ndarray, range_m: float
) -> set[tuple[int, int]]:
    found = set()
    for i in range(len(step)):
        for j in range(i + 1, len(step)):
            if step[i] == step[j] and math.hypot(north[i] - north[j], east[i] - east[j]) <= range_m:
                found.add((i, j))
    return found


def as_set(first: np.ndarray, second: np.ndarray) -> set[tuple[int, int]]:
    pairs = {(min(i, j), max(i, j)) for i, j in zip(first.tolist(), second.tolist(), strict=True)}
    assert len(pairs) == len(first), "a pair was reported twice"
    return pairs


@pytest.mark.parametrize("seed", range(12))
def test_grid_search_equals_brute_force_on_random_scenes(seed: int) -> None:
    rng = np.random.default_rng(seed)
    count = int(rng.integers(2, 120))
    range_m = float(rng.choice([50.0, 500.0, 3704.0]))
    step = rng.integers(0, 4, count).astype(np.int64)
    # Clusters of a few ranges across, plus points exactly on cell edges and exactly at range.
    north = rng.normal(0.0, 2.0 * range_m, count)
    east = rng.normal(0.0, 2.0 * range_m, count)
    north[:4] = [0.0, range_m, -range_m, 3.0 * range_m]
    east[:4] = [0.0, 0.0, 0.0, 0.0]
    step[:4] = 0
    first, second = candidate_pairs(step, north, east, range_m)
    assert as_set(first, second) == brute_force_pairs(step, north, east, range_m)


def test_grid_search_counts_a_pair_exactly_at_range() -> None:
    step = np.zeros(3, dtype=np.int64)
    first, second = candidate_pairs(
        step, np.array([0.0, 3704.0, 7408.0 + 1e-6]), np.zeros(3), 3704.0
    )
    assert as_set(first, second) == {(0, 1)}


def test_grid_search_never_pairs_different_steps() -> None:
    first, second = candidate_pairs(np.array([0, 1]), np.zeros(2), np.zeros(2), 100.0)
    assert len(first) == 0 and len(second) == 0


# --- encounters -----------------------------------------------------------------------------


def head_to_head(offset_m: float) -> tuple[pd.DataFrame, pd.DataFrame]:
    # Own northbound from 5 km south, target southbound from 5 km north, offset east by
    # offset_m, both 5 m/s: the along-track gap is 10000 − 10·t metres.
    own = straight_track(1, -5000.0, 0.0, 0.0, 5.0, 2000)
    target = straight_track(2, 5000.0, offset_m, 180.0, 5.0, 2000)
    return own, target


def test_pair_entering_and_leaving_range_without_trigger() -> None:
    # Range √((10000 − 10t)² + 500²) ≤ 3704 for |10000 − 10t| ≤ √(3704² − 500²) = 3670.10,
    # i.e. t in [632.99, 1367.01]: steps 633..1367. CPA 500 m ≥ 150 m: no trigger.
    search = find_encounters(tracks_of(*head_to_head(500.0)), PARAMS.encounters, own_mmsi=[1])
    (encounter,) = search.encounters
    assert encounter.start_step - T0_S == 633
    assert encounter.end_step - T0_S == 1367
    assert encounter.start == T0 + pd.Timedelta(seconds=633)
    assert not encounter.triggered
    assert encounter.trigger is None and encounter.cpa_m_at_trigger is None
    assert encounter.min_range_m == pytest.approx(500.0)
    assert search.candidate_pair_steps == 1367 - 633 + 1


def test_trigger_step_is_exact() -> None:
    # Offset 100 m: CPA 100 < 150. TCPA = (10000 − 10t)/10 = 1000 − t ≤ 180 first at t = 820.
    # In range from √(3704² − 100²) = 3702.65: t ≥ 629.74 → 630; to t ≤ 1370.26 → 1370.
    search = find_encounters(tracks_of(*head_to_head(100.0)), PARAMS.encounters, own_mmsi=[1])
    (encounter,) = search.encounters
    assert (encounter.start_step - T0_S, encounter.end_step - T0_S) == (630, 1370)
    # The tracks are laid in the map frame, the geometry is geodesic: they differ by parts in
    # 10⁶, which puts TCPA at t = 820 a hair above 180 s, so the trigger is the next step.
    assert encounter.trigger_step - T0_S in (820, 821)
    assert encounter.trigger == T0 + pd.Timedelta(seconds=encounter.trigger_step - T0_S)
    assert 180.0 - 1.0 - 1e-3 < encounter.tcpa_s_at_trigger <= 180.0
    assert encounter.cpa_m_at_trigger == pytest.approx(100.0, abs=1e-3)
    t = encounter.trigger_step - T0_S
    assert encounter.range_m_at_trigger == pytest.approx(
        math.hypot(10_000.0 - 10.0 * t, 100.0), abs=1e-2
    )
    assert encounter.encounter_id == "20240101T121030-1-2"


def test_crossing_trigger_step_is_the_ceiling_of_tcpa_act_before_collision() -> None:
    # Own north from 2 km south, target west from 2 km east, both 10 kn: they meet at
    # t = 2000 / 5.1444 = 388.77 s; TCPA ≤ 180 s first at t = ceil(208.77) = 209.
    speed = 10 * 1852 / 3600
    own = straight_track(1, -2000.0, 0.0, 0.0, speed, 400)
    target = straight_track(2, 0.0, 2000.0, 270.0, speed, 400)
    (encounter,) = find_encounters(
        tracks_of(own, target), PARAMS.encounters, own_mmsi=[2]
    ).encounters
    assert (encounter.own_mmsi, encounter.target_mmsi) == (2, 1)
    assert encounter.trigger_step - T0_S == math.ceil(2000 / speed - 180)
    assert encounter.cpa_m_at_trigger == pytest.approx(0.0, abs=1e-3)


def test_own_ship_seats() -> None:
    tracks = tracks_of(*head_to_head(100.0), straight_track(3, 40_000.0, 0.0, 90.0, 5.0, 2000))
    both = find_encounters(tracks, PARAMS.encounters)
    assert [(e.own_mmsi, e.target_mmsi) for e in both.encounters] == [(1, 2), (2, 1)]
    first, second = both.encounters
    assert (first.start_step, first.end_step, first.trigger_step) == (
        second.start_step,
        second.end_step,
        second.trigger_step,
    )
    assert first.cpa_m_at_trigger == second.cpa_m_at_trigger
    only_two = find_encounters(tracks, PARAMS.encounters, own_mmsi=[2])
    assert [(e.own_mmsi, e.target_mmsi) for e in only_two.encounters] == [(2, 1)]
    far_away = find_encounters(tracks, PARAMS.encounters, own_mmsi=[3])
    assert far_away.encounters == ()
    pair_seats = find_encounters(tracks, PARAMS.encounters, own_mmsi=[1, 2])
    assert pair_seats.encounters == both.encounters


def test_unknown_own_mmsi_is_a_clear_error() -> None:
    tracks = tracks_of(*head_to_head(100.0))
    with pytest.raises(NoDataError, match="own MMSI 999"):
        find_encounters(tracks, PARAMS.encounters, own_mmsi=[1, 999])


def test_slow_vessels_are_not_candidates() -> None:
    own, target = head_to_head(100.0)
    target["sog_kn"] = 0.4  # reported below min_sog_kn although the positions move
    assert find_encounters(tracks_of(own, target), PARAMS.encounters).encounters == ()
    assert len(
        find_encounters(tracks_of(own, target), ReplayParams(min_sog_kn=0.3).encounters).encounters
    )


def test_a_break_in_candidacy_makes_two_encounters() -> None:
    own, target = head_to_head(100.0)
    # The target reports SOG 0 from t=700 to t=900. SOG is linear between the 10 s reports:
    # 9.72 kn at t=690 falls to 0.97 kn at t=699 (still ≥ 0.5) and 0 at t=700, and rises
    # back to 0.97 kn at t=901. So the pair is a candidate up to step 699 and from 901.
    slow = (target["timestamp"] >= T0 + pd.Timedelta(seconds=700)) & (
        target["timestamp"] <= T0 + pd.Timedelta(seconds=900)
    )
    target.loc[slow, "sog_kn"] = 0.0
    search = find_encounters(tracks_of(own, target), PARAMS.encounters, own_mmsi=[1])
    spans = [(e.start_step - T0_S, e.end_step - T0_S) for e in search.encounters]
    assert spans == [(630, 699), (901, 1370)]
    assert [e.trigger_step is not None for e in search.encounters] == [False, True]


def test_batches_join_runs_across_their_boundaries(monkeypatch: pytest.MonkeyPatch) -> None:
    tracks = tracks_of(
        *head_to_head(100.0),
        straight_track(3, -4000.0, 300.0, 10.0, 6.0, 2000),
        straight_track(4, 3000.0, 2000.0, 250.0, 4.0, 2000),
    )
    whole = find_encounters(tracks, PARAMS.encounters)
    monkeypatch.setattr(encounters_module, "_POINTS_PER_BATCH", 200)  # 50 steps per batch
    pieces = find_encounters(tracks, PARAMS.encounters)
    assert pieces.encounters == whole.encounters
    assert pieces.candidate_pair_steps == whole.candidate_pair_steps
    assert len(whole.triggered) >= 2


def test_encounter_series_orients_own_and_target() -> None:
    tracks = tracks_of(*head_to_head(100.0))
    encounter = find_encounters(tracks, PARAMS.encounters, own_mmsi=[2]).encounters[0]
    series = encounter_series(tracks, encounter, from_step=encounter.trigger_step)
    assert len(series) == encounter.end_step - encounter.trigger_step + 1
    for column in SERIES_VESSEL_COLUMNS:
        assert f"own_{column}" in series and f"target_{column}" in series
    first = series.iloc[0]
    assert first["timestamp"] == encounter.trigger
    assert first["own_cog_grid_deg"] == pytest.approx(180.0)
    assert first["target_cog_grid_deg"] == pytest.approx(0.0, abs=1e-9)
    # The true COGs, for reports, differ from the grid ones by the convergence where they are.
    for side in ("own", "target"):
        convergence_deg = FRAME.grid_convergence_deg(
            first[f"{side}_lat_deg"], first[f"{side}_lon_deg"]
        )
        assert (
            first[f"{side}_cog_deg"] - first[f"{side}_cog_grid_deg"] + 180.0
        ) % 360.0 - 180.0 == (pytest.approx(float(convergence_deg), abs=1e-9))
    # own is the eastern ship; the offset is in own ship's tangent plane (true north), which
    # turns from the frame's grid north by the convergence (0.0014° here: 0.04 m at 1.8 km)
    assert first["rel_east_m"] == pytest.approx(-100.0, abs=0.1)
    t = encounter.trigger_step - T0_S
    assert first["rel_north_m"] == pytest.approx(-(10_000.0 - 10.0 * t), abs=0.01)
    assert first["tcpa_s"] == pytest.approx(encounter.tcpa_s_at_trigger)
    assert first["cpa_m"] == pytest.approx(encounter.cpa_m_at_trigger, abs=1e-6)
    assert series["tcpa_s"].iloc[-1] < 0  # the series runs past CPA until they separate


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_find_encounters_agrees_with_a_direct_computation(seed: int) -> None:
    # A handful of random straight tracks: every triggered encounter's trigger values equal
    # those recomputed from its own time series, and its first trigger-worthy step.
    rng = np.random.default_rng(seed)
    frames = [
        straight_track(
            m,
            float(rng.uniform(-3000, 3000)),
            float(rng.uniform(-3000, 3000)),
            float(rng.uniform(0, 360)),
            float(rng.uniform(1, 8)),
            300,
        )
        for m in range(1, 6)
    ]
    tracks = tracks_of(*frames)
    for encounter in find_encounters(tracks, PARAMS.encounters).encounters:
        series = encounter_series(tracks, encounter)
        assert len(series) == encounter.end_step - encounter.start_step + 1
        assert (series["range_m"] <= PARAMS.candidate_range_m).all()
        rel_speed = np.hypot(
            *(
                np.subtract(
                    velocity_mps(series["target_speed_mps"], series["target_cog_grid_deg"]),
                    velocity_mps(series["own_speed_mps"], series["own_cog_grid_deg"]),
                )
            )
        )
        fires = trigger_mask(series["cpa_m"], series["tcpa_s"], rel_speed, PARAMS.encounters)
        if encounter.triggered:
            first = int(np.argmax(fires))
            assert fires.any() and series["step"].iloc[first] == encounter.trigger_step
            assert series["cpa_m"].iloc[first] == pytest.approx(
                encounter.cpa_m_at_trigger, abs=1e-6
            )
        else:
            assert not fires.any()


# --- the [replay] table ----------------------------------------------------------------------


def test_replay_params_defaults_are_the_papers() -> None:
    assert (PARAMS.step_s, PARAMS.tcpa_act_s, PARAMS.cpa_req_m) == (1.0, 180.0, 150.0)
    assert (PARAMS.max_gap_s, PARAMS.max_speed_kn, PARAMS.min_sog_kn) == (300.0, 50.0, 0.5)
    assert PARAMS.restricted_nav_statuses == frozenset({3, 4})


def test_replay_params_from_a_toml_table() -> None:
    params = replay_params_from_table(
        {"step_s": 2, "restricted_nav_statuses": [3, 4, 7], "cpa_req_m": 200}, "q.toml [replay]"
    )
    assert params.step_s == 2.0 and isinstance(params.step_s, float)
    assert params.restricted_nav_statuses == frozenset({3, 4, 7})
    assert params.cpa_req_m == 200.0
    with pytest.raises(QueryError, match=r"q.toml \[replay\]: unknown key 'tcpa_s'"):
        replay_params_from_table({"tcpa_s": 10}, "q.toml [replay]")


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"step_s": 0.0}, "step_s"),
        ({"cpa_req_m": -1.0}, "cpa_req_m"),
        ({"min_sog_kn": float("nan")}, "min_sog_kn"),
        ({"max_gap_s": 0.5}, "max_gap_s"),
        ({"course_change_deg": 181.0}, "course_change_deg"),
        ({"restricted_nav_statuses": frozenset({3, 16})}, "restricted_nav_statuses"),
    ],
)
def test_replay_params_out_of_range(kwargs: dict[str, object], message: str) -> None:
    with pytest.raises(ParameterError, match=message):
        ReplayParams(**kwargs)  # type: ignore[arg-type]


# --- meridian convergence ------------------------------------------------------------------


def geodesic_track(
    mmsi: int, meet_lat: float, meet_lon: float, cog_deg: float, speed_mps: float, meet_s: int
) -> pd.DataFrame:
    """Reports every 10 s of a vessel sailing at true ``cog_deg`` through the meeting point
    at ``meet_s``, built on the ellipsoid (pyproj Geod), not in any projection."""
    geod = Geod(ellps="WGS84")
    start_lon, start_lat, start_course = geod.fwd(
        meet_lon, meet_lat, cog_deg + 180.0, speed_mps * meet_s
    )
    t = np.arange(0, 2 * meet_s + 1, 10, dtype=float)
    lon, lat, _ = geod.fwd(
        np.full_like(t, start_lon),
        np.full_like(t, start_lat),
        np.full_like(t, start_course),
        speed_mps * t,
    )
    return pd.DataFrame(
        {
            "timestamp": [T0 + pd.Timedelta(seconds=s) for s in t],
            "mmsi": mmsi,
            "lat_deg": lat,
            "lon_deg": lon,
            "sog_kn": mps_to_knots(speed_mps),
            "cog_deg": start_course % 360.0,
            "heading_deg": np.nan,
            "nav_status": 0.0,
        }
    )


def test_true_collision_course_far_from_the_central_meridian_has_cpa_zero() -> None:
    # Two vessels meet at 56° N, 2° of longitude east of the frame's central meridian, where
    # grid north is 1.66° east of true north. Their tracks are laid on the ellipsoid with true
    # courses 000° and 270°, so they collide (CPA 0) by construction. The trigger comes at
    # range ≈ 180 s × 7.3 m/s ≈ 1.3 km, where turning both velocities by 1.66° would move the
    # CPA by ≈ 38 m.
    frame = LocalFrame(56.0, 10.0)
    speed = 5.0
    own = geodesic_track(1, 56.0, 12.0, 0.0, speed, 600)
    target = geodesic_track(2, 56.0, 12.0, 270.0, speed, 600)
    tracks = build_tracks(pd.concat([own, target], ignore_index=True), frame, PARAMS.tracks)
    (encounter,) = find_encounters(tracks, PARAMS.encounters, own_mmsi=[1]).encounters
    assert encounter.triggered
    assert encounter.tcpa_s_at_trigger == pytest.approx(180.0, abs=1.0)
    assert encounter.cpa_m_at_trigger == pytest.approx(0.0, abs=2.0)
    series = encounter_series(tracks, encounter)
    approaching = series[(series["tcpa_s"] > 0) & (series["range_m"] > 100.0)]
    assert len(approaching) > 100
    assert approaching["cpa_m"].max() < 2.0
    assert approaching["tcpa_s"].to_numpy() == pytest.approx(
        600.0 - (approaching["step"] - T0_S).to_numpy(), abs=1.0
    )
    # The reports keep the true courses.
    assert series["own_cog_deg"].to_numpy() == pytest.approx(0.0, abs=0.05)
    assert series["target_cog_deg"].to_numpy() == pytest.approx(270.0, abs=0.05)
