"""Tracks: segmentation (gaps, jumps), missing SOG/COG, resampling on the absolute UTC grid."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pyproj import Geod
from test_replay_cli import write_dma

from colregs9_cli.ais.ledger import RejectsLedger
from colregs9_cli.ais.nmea import read_nmea
from colregs9_cli.core.ais_claims import Fixes, SogCheckParams, contradicted_sog
from colregs9_cli.core.encounters import find_encounters
from colregs9_cli.core.pair_search import EncounterParams
from colregs9_cli.core.tracks import (
    NO_TRACK_STATS,
    SAMPLE_COLUMNS,
    CourseSource,
    TrackParams,
    TrackStats,
    build_tracks,
    empty_carry,
    report_table,
    segment_reports,
)
from colregs9_cli.geo import LocalFrame
from colregs9_cli.jobs.replay import run_replay
from colregs9_cli.units import MPS_PER_KNOT

FRAME = LocalFrame(57.05, 9.94)
# 2024-01-01 12:00:00 UTC: a multiple of 5 s (and 1 s) since the Unix epoch.
T0 = pd.Timestamp("2024-01-01T12:00:00Z")
T0_S = 1_704_110_400


def reports(
    t_s: list[float],
    north_m: list[float],
    east_m: list[float],
    mmsi: int = 219000001,
    sog_kn: list[float] | float = 10.0,
    cog_deg: list[float] | float = 0.0,
    heading_deg: list[float] | float = np.nan,
    nav_status: list[float] | float = 0,
) -> pd.DataFrame:
    """Position reports at T0 + t_s, given in the local frame."""
    lat, lon = FRAME.to_geodetic(north_m, east_m)
    n = len(t_s)
    return pd.DataFrame(
        {
            "timestamp": [T0 + pd.Timedelta(seconds=s) for s in t_s],
            "mmsi": [mmsi] * n,
            "lat_deg": lat,
            "lon_deg": lon,
            "sog_kn": np.broadcast_to(np.asarray(sog_kn, dtype=float), n),
            "cog_deg": np.broadcast_to(np.asarray(cog_deg, dtype=float), n),
            "heading_deg": np.broadcast_to(np.asarray(heading_deg, dtype=float), n),
            "nav_status": np.broadcast_to(np.asarray(nav_status, dtype=float), n),
        }
    )


def northbound(t_s: list[float], speed_mps: float = 5.0) -> pd.DataFrame:
    t = np.asarray(t_s, dtype=float)
    return reports(list(t), list(speed_mps * t), [0.0] * len(t), sog_kn=speed_mps / MPS_PER_KNOT)


def test_output_columns_and_sorting() -> None:
    two = pd.concat([northbound([10, 0, 5]), reports([0, 4], [0, 0], [0, 8], mmsi=5, sog_kn=4.0)])
    tracks = build_tracks(two, FRAME, TrackParams())
    samples = tracks.samples
    assert tuple(samples.columns) == SAMPLE_COLUMNS
    assert samples["mmsi"].tolist() == [5] * 5 + [219000001] * 11
    assert (samples.groupby("mmsi")["step"].diff().dropna() == 1).all()
    assert str(samples["timestamp"].dt.tz) == "UTC"
    assert samples["nav_status"].dtype == "Int64"


def test_gap_longer_than_max_gap_splits_and_leaves_the_gap_empty() -> None:
    times = [*range(0, 101, 10), *range(401, 502, 10)]  # 101 → 401: a 300 s gap, then 301
    tracks = build_tracks(northbound(times), FRAME, TrackParams(max_gap_s=299.0))
    assert tracks.stats.gap_splits == 1
    assert tracks.stats.segments == 2
    steps = tracks.samples["step"].to_numpy() - T0_S
    assert steps.min() == 0 and steps.max() == 501
    assert not np.any((steps > 100) & (steps < 401))
    assert len(steps) == 101 + 101
    assert tracks.samples["segment_id"].nunique() == 2


def test_gap_equal_to_max_gap_does_not_split() -> None:
    tracks = build_tracks(northbound([0, 300, 310]), FRAME, TrackParams(max_gap_s=300.0))
    assert tracks.stats.gap_splits == 0
    assert tracks.stats.segments == 1
    assert len(tracks.samples) == 311


def test_isolated_speed_jump_is_dropped_and_counted() -> None:
    # Northbound at 5 m/s; the report at t=30 claims 5 km east: 5000 m / 10 s ≈ 972 kn.
    frame = northbound([0, 10, 20, 30, 40, 50])
    lat, lon = FRAME.to_geodetic(150.0, 5000.0)
    frame.loc[3, ["lat_deg", "lon_deg"]] = [float(lat), float(lon)]
    tracks = build_tracks(frame, FRAME, TrackParams())
    assert tracks.stats.speed_jump_dropped == 1
    assert tracks.stats.jump_splits == 0
    assert tracks.stats.segments == 1
    assert tracks.stats.reports_used == 5
    # The dropped report leaves no trace: t=30 is interpolated from t=20 and t=40 (on the
    # Earth, so the frame sees the midpoint to a fraction of a millimetre).
    at_30 = tracks.samples.loc[tracks.samples["step"] == T0_S + 30]
    assert at_30["north_m"].item() == pytest.approx(150.0, abs=1e-4)
    assert at_30["east_m"].item() == pytest.approx(0.0, abs=1e-4)


def test_last_report_jumping_is_dropped() -> None:
    frame = northbound([0, 10, 20])
    lat, lon = FRAME.to_geodetic(100.0, 3000.0)
    frame.loc[2, ["lat_deg", "lon_deg"]] = [float(lat), float(lon)]
    tracks = build_tracks(frame, FRAME, TrackParams())
    assert tracks.stats.speed_jump_dropped == 1
    assert tracks.samples["step"].max() == T0_S + 10


def test_confirmed_jump_splits_the_track_without_dropping() -> None:
    # From t=30 the vessel is reported 5 km east, consistently: the position source moved.
    t = [0, 10, 20, 30, 40, 50]
    north = [0.0, 50.0, 100.0, 150.0, 200.0, 250.0]
    east = [0.0, 0.0, 0.0, 5000.0, 5000.0, 5000.0]
    tracks = build_tracks(reports(t, north, east), FRAME, TrackParams())
    assert tracks.stats.speed_jump_dropped == 0
    assert tracks.stats.jump_splits == 1
    assert tracks.stats.segments == 2
    steps = tracks.samples["step"].to_numpy() - T0_S
    # Nothing is interpolated across the jump (21..29 would be a 5 km slide).
    assert steps.tolist() == [*range(0, 21), *range(30, 51)]


def test_speed_exactly_at_the_limit_is_plausible() -> None:
    limit_mps = 50.0 * MPS_PER_KNOT
    frame = reports([0, 10], [0.0, 10 * limit_mps], [0.0, 0.0])
    tracks = build_tracks(frame, FRAME, TrackParams(max_speed_kn=50.0 * (1 + 1e-9)))
    assert tracks.stats.speed_jump_dropped == 0
    tracks = build_tracks(frame, FRAME, TrackParams(max_speed_kn=50.0 * (1 - 1e-6)))
    assert tracks.stats.speed_jump_dropped == 1


def test_same_second_reports_keep_the_first() -> None:
    frame = pd.concat([northbound([0, 10, 20]), northbound([10])], ignore_index=True)
    frame.loc[3, "sog_kn"] = 99.0
    tracks = build_tracks(frame, FRAME, TrackParams())
    assert tracks.stats.same_time_dropped == 1
    assert tracks.stats.reports_used == 3
    assert (tracks.samples["sog_kn"] < 99.0).all()


def test_positions_and_speed_are_linear_in_time() -> None:
    # Linear on the Earth between reports: in the frame, to a fraction of a millimetre.
    frame = reports([0, 10], [0.0, 100.0], [0.0, -40.0], sog_kn=[4.0, 6.0], cog_deg=350.0)
    samples = build_tracks(frame, FRAME, TrackParams()).samples
    at_3 = samples.loc[samples["step"] == T0_S + 3].iloc[0]
    assert at_3["north_m"] == pytest.approx(30.0, abs=1e-4)
    assert at_3["east_m"] == pytest.approx(-12.0, abs=1e-4)
    assert at_3["sog_kn"] == pytest.approx(4.6)
    assert at_3["speed_mps"] == pytest.approx(4.6 * 1852 / 3600)
    lat, lon = FRAME.to_geodetic(30.0, -12.0)
    assert at_3["lat_deg"] == pytest.approx(float(lat), abs=1e-9)
    assert at_3["lon_deg"] == pytest.approx(float(lon), abs=1e-9)


def test_course_interpolates_across_north_along_the_short_arc() -> None:
    frame = reports([0, 10], [0.0, 50.0], [0.0, 0.0], cog_deg=[359.0, 1.0])
    samples = build_tracks(frame, FRAME, TrackParams(step_s=0.5)).samples
    course = dict(zip(samples["t_s"] - T0_S, samples["cog_deg"], strict=True))
    assert course[5.0] == pytest.approx(0.0, abs=1e-9)  # not 180
    assert course[2.5] == pytest.approx(359.5)
    assert course[7.5] == pytest.approx(0.5)
    assert ((samples["cog_deg"] >= 0) & (samples["cog_deg"] < 360)).all()


def test_course_interpolates_the_other_way_too() -> None:
    frame = reports([0, 4], [0.0, 20.0], [0.0, 0.0], cog_deg=[10.0, 350.0])
    samples = build_tracks(frame, FRAME, TrackParams()).samples
    assert samples["cog_deg"].tolist() == pytest.approx([10.0, 5.0, 0.0, 355.0, 350.0])


def test_no_extrapolation_and_grid_alignment() -> None:
    # Reports at T0+2 s and T0+23 s; a 5 s grid gives samples at T0+5, 10, 15, 20 only.
    frame = reports([2, 23], [0.0, 210.0], [0.0, 0.0])
    tracks = build_tracks(frame, FRAME, TrackParams(step_s=5.0))
    samples = tracks.samples
    assert (samples["t_s"] - T0_S).tolist() == [5.0, 10.0, 15.0, 20.0]
    assert samples["step"].tolist() == [(T0_S + s) // 5 for s in (5, 10, 15, 20)]
    assert samples["north_m"].tolist() == pytest.approx([30.0, 80.0, 130.0, 180.0])
    assert samples["timestamp"].iloc[0] == T0 + pd.Timedelta(seconds=5)
    assert tracks.step_to_timestamp(int(samples["step"].iloc[0])) == T0 + pd.Timedelta(seconds=5)


def test_sub_second_report_times_stay_inside_the_segment() -> None:
    frame = reports([0.4, 3.6], [0.0, 32.0], [0.0, 0.0])
    samples = build_tracks(frame, FRAME, TrackParams()).samples
    assert (samples["t_s"] - T0_S).tolist() == pytest.approx([1.0, 2.0, 3.0])
    assert samples["north_m"].tolist() == pytest.approx([6.0, 16.0, 26.0])


def test_samples_carry_the_report_gap_they_were_interpolated_across() -> None:
    # Reports at T0+2, 5 and 23 s on a 1 s grid: samples at 3-4 s lie in a 3 s gap, 6-22 s
    # in an 18 s gap; the samples at a report's own second are that report.
    samples = build_tracks(
        reports([2, 5, 23], [0.0, 30.0, 210.0], [0.0] * 3), FRAME, TrackParams()
    ).samples
    gap = dict(zip(samples["t_s"] - T0_S, samples["report_gap_s"], strict=True))
    nearest = dict(zip(samples["t_s"] - T0_S, samples["nearest_report_s"], strict=True))
    assert [gap[t] for t in (2.0, 3.0, 4.0, 5.0, 6.0, 14.0, 22.0, 23.0)] == [
        0.0,
        3.0,
        3.0,
        0.0,
        18.0,
        18.0,
        18.0,
        0.0,
    ]
    assert [nearest[t] for t in (3.0, 4.0, 6.0, 14.0, 22.0)] == [1.0, 1.0, 1.0, 9.0, 1.0]
    assert nearest[2.0] == nearest[5.0] == nearest[23.0] == 0.0


def test_samples_carry_the_turn_of_the_gap_they_were_interpolated_across() -> None:
    # COG 350 deg at T0+2 s, 020 deg at 5 s (30 deg over north), 020 deg again at 23 s
    samples = build_tracks(
        reports([2, 5, 23], [0.0, 30.0, 210.0], [0.0] * 3, cog_deg=[350.0, 20.0, 20.0]),
        FRAME,
        TrackParams(),
    ).samples
    turn = dict(zip(samples["t_s"] - T0_S, samples["gap_turn_deg"], strict=True))
    assert [turn[t] for t in (2.0, 3.0, 4.0, 5.0, 6.0, 22.0, 23.0)] == pytest.approx(
        [0.0, 30.0, 30.0, 0.0, 0.0, 0.0, 0.0]
    )


def test_a_sample_between_sub_second_reports_is_not_at_a_report() -> None:
    samples = build_tracks(
        reports([0.4, 3.6], [0.0, 32.0], [0.0, 0.0]), FRAME, TrackParams()
    ).samples
    assert samples["report_gap_s"].tolist() == pytest.approx([3.2] * 3)
    assert samples["nearest_report_s"].tolist() == pytest.approx([0.6, 1.6, 0.6])


def test_segment_between_grid_points_has_no_samples() -> None:
    frame = reports([1, 3], [0.0, 10.0], [0.0, 0.0])
    tracks = build_tracks(frame, FRAME, TrackParams(step_s=5.0))
    assert tracks.samples.empty
    assert tracks.stats.segments == 1


def test_missing_sog_and_cog_come_from_the_movement() -> None:
    # East at 5 m/s, every report without SOG/COG; the last one stops (5 m in 10 s).
    t = [0, 10, 20, 30]
    east = [0.0, 50.0, 100.0, 105.0]
    frame = reports(t, [0.0] * 4, east, sog_kn=np.nan, cog_deg=np.nan)
    samples = build_tracks(frame, FRAME, TrackParams()).samples.set_index("t_s")
    # Central differences: (100 − 0)/20 s at t=10, (105 − 50)/20 s at t=20, one-sided at the ends.
    assert samples.loc[T0_S + 0, "sog_kn"] == pytest.approx(5.0 / MPS_PER_KNOT)
    assert samples.loc[T0_S + 10, "sog_kn"] == pytest.approx(5.0 / MPS_PER_KNOT)
    assert samples.loc[T0_S + 20, "sog_kn"] == pytest.approx(2.75 / MPS_PER_KNOT)
    assert samples.loc[T0_S + 30, "sog_kn"] == pytest.approx(0.5 / MPS_PER_KNOT)
    # The derived COG is the true bearing of the movement, measured on the Earth; checked
    # against pyproj's geodesic azimuth from the earlier report to the later one (due grid
    # east here, 1.4e-3° off true east 100 m east of this frame's central meridian).
    from pyproj import Geod

    lat, lon = frame["lat_deg"].to_numpy(), frame["lon_deg"].to_numpy()
    azimuth, _, _ = Geod(ellps="WGS84").inv(
        lon[[0, 0, 1, 2]], lat[[0, 0, 1, 2]], lon[[1, 2, 3, 3]], lat[[1, 2, 3, 3]]
    )
    by_report = samples.loc[[T0_S + 0, T0_S + 10, T0_S + 20, T0_S + 30], "cog_deg"].to_numpy()
    assert by_report == pytest.approx(azimuth % 360.0, abs=1e-5)
    assert samples["cog_grid_deg"].to_numpy() == pytest.approx(90.0, abs=1e-3)
    assert samples["cog_deg"].to_numpy() == pytest.approx(90.0, abs=2e-3)


def test_a_vessel_that_did_not_move_gets_no_course() -> None:
    frame = reports([0, 10], [0.0, 0.0], [0.0, 0.0], sog_kn=np.nan, cog_deg=np.nan)
    samples = build_tracks(frame, FRAME, TrackParams()).samples
    assert (samples["sog_kn"] == 0.0).all()
    assert samples["cog_deg"].isna().all()


def test_reported_sog_and_cog_are_kept() -> None:
    frame = reports([0, 10], [0.0, 50.0], [0.0, 0.0], sog_kn=3.0, cog_deg=10.0)
    samples = build_tracks(frame, FRAME, TrackParams()).samples
    assert samples["sog_kn"].to_numpy() == pytest.approx(3.0)
    assert samples["cog_deg"].to_numpy() == pytest.approx(10.0)


def test_course_source_heading_falls_back_to_cog() -> None:
    frame = reports([0, 10, 20], [0.0, 50.0, 100.0], [0.0] * 3, cog_deg=0.0)
    frame["heading_deg"] = [20.0, np.nan, 20.0]
    by_cog = build_tracks(frame, FRAME, TrackParams()).samples
    by_heading = build_tracks(frame, FRAME, TrackParams(), CourseSource.HEADING).samples
    assert by_cog["course_deg"].to_numpy() == pytest.approx(0.0)
    # Heading 20 at t=0, null → COG 0 at t=10, 20 at t=20.
    expected = [20.0 - 2.0 * k for k in range(11)] + [2.0 * k for k in range(1, 11)]
    assert by_heading["course_deg"].tolist() == pytest.approx(expected)
    assert by_heading["heading_deg"].tolist() == pytest.approx(expected)
    assert by_heading["cog_deg"].to_numpy() == pytest.approx(0.0)


def test_nav_status_is_held_from_the_latest_report() -> None:
    frame = northbound([0, 10, 20])
    frame["nav_status"] = [0.0, 3.0, np.nan]
    samples = build_tracks(frame, FRAME, TrackParams()).samples
    status = samples["nav_status"].tolist()
    assert status[:10] == [0] * 10
    assert status[10:20] == [3] * 10
    assert status[20] is pd.NA


def test_vessels_hold_the_last_known_static_values() -> None:
    frame = northbound([0, 10, 20])
    frame["length_m"] = [100.0, np.nan, np.nan]
    frame["draught_m"] = [5.0, 6.5, np.nan]
    frame["name"] = [None, "HAMLET", None]
    other = reports([0, 10], [900.0, 900.0], [0.0, 50.0], mmsi=7)
    tracks = build_tracks(pd.concat([frame, other], ignore_index=True), FRAME, TrackParams())
    vessels = tracks.vessels
    assert vessels.index.tolist() == [7, 219000001]
    assert vessels.loc[219000001, "length_m"] == 100.0
    assert vessels.loc[219000001, "draught_m"] == 6.5
    assert vessels.loc[219000001, "name"] == "HAMLET"
    assert pd.isna(vessels.loc[7, "length_m"])


def test_unclean_input_is_a_programming_error() -> None:
    frame = northbound([0, 10])
    with pytest.raises(ValueError, match="canonical columns"):
        build_tracks(frame.drop(columns="cog_deg"), FRAME, TrackParams())
    frame.loc[1, "lat_deg"] = np.nan
    with pytest.raises(ValueError, match="cleaned"):
        build_tracks(frame, FRAME, TrackParams())


@pytest.mark.slow
def test_real_nmea_sample(fixtures_dir: Path) -> None:
    path = fixtures_dir / "ais" / "dma_nmea_2013-11-12_5min.txt.gz"
    with gzip.open(path, "rt", errors="replace") as lines:
        batches = list(read_nmea(lines, path.name, RejectsLedger()))
    positions = pa.concat_tables([b.positions for b in batches]).to_pandas()
    frame = LocalFrame.centred_on(
        positions["lat_deg"].min(),
        positions["lat_deg"].max(),
        positions["lon_deg"].min(),
        positions["lon_deg"].max(),
    )
    tracks = build_tracks(positions, frame, TrackParams())
    # With the $PGHP milliseconds no (mmsi, timestamp) repeats (floored to the second, 53
    # did). The longest gap between a vessel's reports is 258 s (< 300, no gap split). Four
    # reports imply > 50 kn from the last kept one and are dropped: with whole seconds it was
    # 18, 17 of them 1 s timestamp jitter of the ≈34 kn craft 219017081. 219601000 (≈36 kn)
    # still repeats a stale position three times, then jumps, confirmed by the next report:
    # split. Resampling never extrapolates, so a vessel whose reports all fall inside one
    # grid second has no sample: 1,112 of the 1,438 vessels have samples. Of their 282,777
    # samples, 117,411 are under way (SOG >= 0.5 kn), the ones the pair search uses.
    assert len(tracks.samples) == 282777
    under_way = tracks.samples["sog_kn"] >= TrackParams().min_sog_kn
    assert tracks.stats.samples == int(under_way.sum())
    assert tracks.stats == TrackStats(
        reports_in=24688,
        reports_used=24688 - 4,
        same_time_dropped=0,
        speed_jump_dropped=4,
        jump_splits=3,
        gap_splits=0,
        segments=1438 + 3,
        samples=117411,
        sog_contradicted=0,
    )
    assert len(tracks.vessels) == 1112
    assert tracks.samples["mmsi"].nunique() == 1112
    split_vessels = tracks.samples.groupby("mmsi")["segment_id"].nunique()
    assert split_vessels[split_vessels > 1].to_dict() == {219601000: 4}


def test_grid_courses_far_from_the_central_meridian() -> None:
    # A vessel at 56° N, 2° east of the frame's central meridian (convergence ≈ 2°·sin 56° ≈
    # 1.66°), sailing from true 045° along a geodesic laid with pyproj Geod, each report's COG
    # the geodesic's azimuth there (045.00° to 045.02°); heading 050°. The report at
    # t = 100 s has no COG, so it is derived from the movement.
    frame = LocalFrame(56.0, 10.0)
    geod = Geod(ellps="WGS84")
    t = np.arange(0.0, 301.0, 10.0)
    start_lon, start_lat = 12.0, 56.0
    lon, lat, back_azimuth_deg = geod.fwd(
        np.full_like(t, start_lon), np.full_like(t, start_lat), np.full_like(t, 45.0), 6.0 * t
    )
    azimuth_along_deg = (np.asarray(back_azimuth_deg) + 180.0) % 360.0
    cog = azimuth_along_deg.copy()
    cog[10] = np.nan
    positions = pd.DataFrame(
        {
            "timestamp": [T0 + pd.Timedelta(seconds=s) for s in t],
            "mmsi": 219000001,
            "lat_deg": lat,
            "lon_deg": lon,
            "sog_kn": 6.0 / MPS_PER_KNOT,
            "cog_deg": cog,
            "heading_deg": 50.0,
            "nav_status": 0,
        }
    )
    samples = build_tracks(positions, frame, TrackParams(), CourseSource.HEADING).samples
    by_time = samples.set_index("t_s")
    # The derived COG is true: the ellipsoidal azimuth from the previous to the next report.
    azimuth_deg, _, _ = geod.inv(lon[9], lat[9], lon[11], lat[11])
    assert by_time.loc[T0_S + 100, "cog_deg"] == pytest.approx(azimuth_deg, abs=0.01)
    reported = samples[~samples["t_s"].between(T0_S + 91, T0_S + 109)]
    assert reported["cog_deg"].to_numpy() == pytest.approx(45.0, abs=0.02)
    assert reported["course_deg"].to_numpy() == pytest.approx(50.0)
    # The grid COG is the direction the vessel moves in the frame, 1.66° left of the true one.
    motion_deg = np.degrees(np.arctan2(np.diff(samples["east_m"]), np.diff(samples["north_m"])))
    assert samples["cog_grid_deg"].to_numpy()[1:] == pytest.approx(motion_deg, abs=1e-3)
    assert reported["cog_grid_deg"].to_numpy() == pytest.approx(45.0 - 1.66, abs=0.01)
    turn = samples["heading_deg"] - samples["heading_grid_deg"]
    assert turn.to_numpy() == pytest.approx(samples["cog_deg"] - samples["cog_grid_deg"])
    assert (samples["course_grid_deg"] == samples["heading_grid_deg"]).all()


def test_a_track_across_the_antimeridian_is_resampled_on_the_earth() -> None:
    # Two reports 10 s apart either side of 180°: the sample between lies on 180°, not on the
    # far side of the Earth, and a frame that cannot reach it leaves its frame position empty.
    crossing = reports([0, 10], [0.0, 0.0], [0.0, 0.0], sog_kn=[10.0, 10.0], cog_deg=90.0)
    crossing["lat_deg"] = [0.0, 0.0]
    crossing["lon_deg"] = [179.9998, -179.9998]
    far_frame = LocalFrame(0.0, 10.0)
    samples = build_tracks(crossing, far_frame, TrackParams()).samples
    middle = samples.loc[samples["step"] == T0_S + 5].iloc[0]
    assert abs(middle["lon_deg"]) == pytest.approx(180.0, abs=1e-9)
    assert middle["lat_deg"] == pytest.approx(0.0, abs=1e-12)
    assert np.isnan(middle["north_m"]) and np.isnan(middle["east_m"])


# -- rule 3a: a reported SOG that the vessel's own positions contradict ------------------------

YACHT = 219000009
NO_SOG_CHECK = TrackParams(sog_check=SogCheckParams(max_gap_s=0.0))  # no neighbour counts


def _yacht(t_s: tuple[float, ...] = (0.0, 30.0, 60.0, 90.0)) -> pd.DataFrame:
    """A yacht at one fixed position reporting 102.2 kn (AIS's largest SOG) on 045°, every
    30 s (a Class B "CS" above 2 kn)."""
    n = len(t_s)
    return reports(list(t_s), [0.0] * n, [0.0] * n, mmsi=YACHT, sog_kn=102.2, cog_deg=45.0)


def test_a_yacht_reporting_102_kn_from_one_fixed_position_is_at_rest() -> None:
    tracks = build_tracks(_yacht(), FRAME, TrackParams())
    # All four: the middle two over 60 s, the ends one-sided over 30 s (she would have made
    # good 0.5 * 52.6 m/s * (30 - 10) s - 20 m = 506 m at least; she made 0 m).
    assert tracks.stats.sog_contradicted == 4
    assert tracks.stats.reports_used == 4
    assert tracks.samples["sog_kn"].to_numpy() == pytest.approx(0.0, abs=1e-9)
    assert tracks.stats.samples == 0  # not under way
    believed = build_tracks(_yacht(), FRAME, NO_SOG_CHECK)
    assert believed.stats.sog_contradicted == 0
    assert believed.samples["sog_kn"].to_numpy() == pytest.approx(102.2)


def test_the_yacht_at_rest_forms_no_candidate_pair() -> None:
    # A vessel eastbound at 10 kn passes 300 m south of her: with her SOG believed, the two
    # are a candidate pair; at rest, the yacht is in none.
    passer = reports(
        list(range(-60, 151, 10)),
        [-300.0] * 22,
        [5.144 * s for s in range(-60, 151, 10)],
        mmsi=219000010,
        sog_kn=10.0,
        cog_deg=90.0,
    )
    both = pd.concat([_yacht(), passer], ignore_index=True)
    believed = find_encounters(build_tracks(both, FRAME, NO_SOG_CHECK), EncounterParams())
    assert believed.candidate_pair_steps > 0
    checked = find_encounters(build_tracks(both, FRAME, TrackParams()), EncounterParams())
    assert checked.candidate_pair_steps == 0
    assert checked.encounters == ()


def test_a_sog_the_positions_agree_with_is_untouched() -> None:
    # 5 m/s north reported as 9.72 kn every 10 s, and a slow vessel whose SOG (0.1 kn) is
    # far below what her scattered fixes imply (100 m in 20 s): a SOG lower than the
    # positions is never contradicted.
    agreeing = northbound(list(range(0, 201, 10)))
    scattered = reports(
        [0, 10, 20, 30, 40],
        [0.0, 60.0, -40.0, 50.0, 0.0],
        [0.0, -30.0, 20.0, 40.0, 0.0],
        mmsi=219000011,
        sog_kn=0.1,
        cog_deg=[216.0, 227.6, 269.7, 267.4, 275.4],
    )
    both = pd.concat([agreeing, scattered], ignore_index=True)
    tracks = build_tracks(both, FRAME, TrackParams())
    assert tracks.stats.sog_contradicted == 0
    samples = tracks.samples
    assert samples.loc[samples["mmsi"] == 219000001, "sog_kn"].to_numpy() == pytest.approx(
        5.0 / MPS_PER_KNOT
    )
    assert samples.loc[samples["mmsi"] == 219000011, "sog_kn"].to_numpy() == pytest.approx(0.1)


def test_a_fast_craft_repeating_a_stale_fix_keeps_her_sog() -> None:
    # 219601000 in the DMA NMEA sample: 36.6 kn, a report every 2 s, one fix repeated at
    # three reports. Spans of 4 s are shorter than stale_s: never judged.
    speed_mps = 36.6 * MPS_PER_KNOT
    t = [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]
    north = [speed_mps * s for s in (0.0, 2.0, 4.0, 4.0, 4.0, 10.0)]
    tracks = build_tracks(reports(t, north, [0.0] * 6, sog_kn=36.6), FRAME, TrackParams())
    assert tracks.stats.sog_contradicted == 0
    assert tracks.samples["sog_kn"].to_numpy() == pytest.approx(36.6)


def _fixes(t_s: list[float], north_m: list[float], cog_deg: list[float]) -> Fixes:
    lat, lon = FRAME.to_geodetic(north_m, [0.0] * len(north_m))
    return Fixes(
        np.asarray(t_s, dtype=float),
        np.asarray(lat, dtype=float),
        np.asarray(lon, dtype=float),
        np.asarray(cog_deg, dtype=float),
    )


def _judge(
    sog_kn: float,
    chord_m: float,
    cogs: tuple[float, float, float] = (0.0, 0.0, 0.0),
    span_s: tuple[float, float] = (30.0, 30.0),
) -> bool:
    """Whether a report between neighbours span_s before and after, chord_m apart
    (half-way: the report itself lies in the middle), contradicts sog_kn."""
    result = contradicted_sog(
        np.array([sog_kn]),
        _fixes([0.0], [chord_m / 2.0], [cogs[1]]),
        _fixes([-span_s[0]], [0.0], [cogs[0]]),
        _fixes([span_s[1]], [chord_m], [cogs[2]]),
        SogCheckParams(),
    )
    return bool(result[0])


def test_the_sog_check_thresholds_worked_by_hand() -> None:
    # 20 kn over 60 s claims at least 0.5 * 10.2889 m/s * (60 - 10) s - 2 * 10 m = 237.2 m.
    assert _judge(20.0, 230.0)
    assert not _judge(20.0, 245.0)
    # An excess of 3 kn or less is not judged: 2.9 kn with no movement at all stands.
    assert _judge(4.0, 0.0)
    assert not _judge(2.9, 0.0)
    # Reported COGs that turn by more than 90° (a loop): the chord says nothing.
    assert not _judge(20.0, 0.0, cogs=(177.0, 6.0, 180.0))
    assert _judge(20.0, 0.0, cogs=(10.0, 60.0, 95.0))
    # Neighbours more than 180 s away are not used; a span of 10 s or less is never judged.
    assert not _judge(20.0, 0.0, span_s=(181.0, 181.0))
    assert _judge(20.0, 0.0, span_s=(181.0, 180.0))  # one-sided, 180 s
    assert not _judge(102.2, 0.0, span_s=(5.0, 5.0))
    # A null SOG is not contradicted; a report with no neighbour is not judged.
    assert not _judge(np.nan, 0.0)
    alone = contradicted_sog(
        np.array([50.0]),
        _fixes([0.0], [0.0], [0.0]),
        _fixes([np.nan], [np.nan], [np.nan]),
        _fixes([np.nan], [np.nan], [np.nan]),
        SogCheckParams(),
    )
    assert not alone[0]


def _streamed(reports_table: pd.DataFrame, slab_s: float, params: TrackParams):
    """Rules 1-3a slab by slab (as ``slabs.segment_part`` runs them): the kept reports, in
    MMSI and time order, the counts, and how many came out in a later slab than their own."""
    slab = np.floor(reports_table["t_s"].to_numpy() / slab_s).astype(np.int64)
    indices = np.unique(slab)
    carry, stats, kept, late = empty_carry(), NO_TRACK_STATS, [], 0
    for n, index in enumerate(indices):
        until = None if n == len(indices) - 1 else (index + 1) * slab_s
        part = segment_reports(reports_table[slab == index], carry, params, until)
        carry, stats = part.carry, stats + part.stats
        kept.append(part.kept)
        late += int((part.kept["t_s"] < index * slab_s).sum())
    streamed = pd.concat(kept, ignore_index=True)
    order = np.lexsort((streamed["t_s"].to_numpy(), streamed["mmsi"].to_numpy()))
    return streamed.iloc[order].reset_index(drop=True), stats, late


def test_the_yacht_in_slabs_shorter_than_her_gaps_is_judged_as_in_one_go() -> None:
    table = report_table(_yacht())
    whole = segment_reports(table, empty_carry(), TrackParams())
    assert whole.stats.sog_contradicted == 4
    assert whole.kept["sog_kn"].isna().all()
    kept, stats, late = _streamed(table, 5.0, TrackParams())
    pd.testing.assert_frame_equal(kept, whole.kept)
    assert stats == whole.stats
    assert late == 3  # each report waits in the carry for the next


@st.composite
def _claims(draw) -> pd.DataFrame:
    """A few vessels' reports, some from a fixed position, with SOGs true or not, COGs
    steady or turning, and gaps from 3 s to beyond max_gap_s."""
    frames = []
    for vessel in range(draw(st.integers(1, 3))):
        count = draw(st.integers(1, 25))
        steps = draw(
            st.lists(
                st.sampled_from([3.0, 10.0, 30.0, 90.0, 200.0, 400.0]),
                min_size=count,
                max_size=count,
            )
        )
        t = 1_000_000.0 + np.cumsum(steps)
        moving = np.asarray(draw(st.lists(st.booleans(), min_size=count, max_size=count)))
        north_m = np.cumsum(np.where(moving, 5.0 * np.asarray(steps), 0.0))
        sog = draw(
            st.lists(st.sampled_from([0.0, 9.7, 20.0, 102.2]), min_size=count, max_size=count)
        )
        cog = draw(st.lists(st.sampled_from([0.0, 10.0, 180.0]), min_size=count, max_size=count))
        frames.append(
            pd.DataFrame(
                {
                    "mmsi": np.full(count, 219_000_000 + vessel, dtype=np.int64),
                    "t_s": t,
                    "lat_deg": 57.0 + north_m / 111_320.0,
                    "lon_deg": np.full(count, 10.0),
                    "sog_kn": np.asarray(sog, dtype=float),
                    "cog_deg": np.asarray(cog, dtype=float),
                    "heading_deg": np.full(count, np.nan),
                    "nav_status": np.full(count, 0.0),
                }
            )
        )
    return pd.concat(frames, ignore_index=True)


@settings(max_examples=40, deadline=None)
@given(reports_table=_claims(), slab_s=st.sampled_from([5.0, 20.0, 60.0, 300.0, 1000.0]))
def test_sog_checks_in_slabs_are_those_of_one_go(reports_table, slab_s) -> None:
    """Reports held past their slab for their next neighbour: the same SOGs nulled and the
    same counts, whatever the slab length."""
    params = TrackParams()
    whole = segment_reports(reports_table, empty_carry(), params)
    kept, stats, _ = _streamed(reports_table, slab_s, params)
    pd.testing.assert_frame_equal(kept, whole.kept)
    assert stats == whole.stats
    # Every SOG here is reported: a null one in the kept reports was contradicted.
    assert stats.sog_contradicted == int(whole.kept["sog_kn"].isna().sum())


def test_the_ledger_counts_the_sogs_set_to_null(tmp_path: Path) -> None:
    # The yacht in a DMA file beside a vessel passing at 10 kn: four SOGs dropped, their
    # reports used, and no candidate pair.
    yacht = [(f"12/11/2013 12:00:{s:02d}", YACHT, 57.0, 10.0, 102.2, 45.0) for s in (0, 30)]
    yacht += [(f"12/11/2013 12:01:{s:02d}", YACHT, 57.0, 10.0, 102.2, 45.0) for s in (0, 30)]
    deg_per_s = 10 * 1852 / 3600 / (111_320 * np.cos(np.radians(57.0)))
    passer = [
        (
            f"12/11/2013 12:{s // 60:02d}:{s % 60:02d}",
            219000010,
            56.997,
            9.99 + deg_per_s * s,
            10.0,
            90.0,
        )
        for s in range(0, 180, 10)
    ]
    path = write_dma(tmp_path / "yacht.csv", yacht + passer)
    result = run_replay([path], write=False)
    ledger = result.manifest["ledger"]
    assert ledger["values_dropped"] == {"sog_contradicted": 4}
    assert ledger["rows_used"] == len(yacht) + len(passer)
    assert result.manifest["tracks"]["sog_contradicted"] == 4
    assert result.counts.candidate_pairs == 0
