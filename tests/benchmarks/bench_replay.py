"""Replay benchmark (a script, not a test): ``python tests/benchmarks/bench_replay.py``.

1. The real five-minute national NMEA sample end to end, without and with plots.
2. A synthetic dense harbour (default 300 vessels, 1 hour, AIS every 10 s, replayed at 1 s),
   written as DMA CSV into a temporary directory, end to end without plots.
3. The pair search (``find_encounters``) at 100/200/300 vessels, at constant traffic density
   (the harbour's area grows with the number of vessels), to show that the work grows with
   the number of vessels and close pairs, not with the square of the number of vessels; and
   on subsets of the one 300-vessel harbour (fixed area, so density grows too).

Figures go to stdout; put them in tests/benchmarks/README.md ("Replay benchmark").
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from colregs9_cli.ais.layouts import DMA_COLUMNS
from colregs9_cli.core.encounters import find_encounters
from colregs9_cli.core.tracks import build_tracks
from colregs9_cli.geo import LocalFrame
from colregs9_cli.jobs.replay import run_replay
from colregs9_cli.jobs.replay_params import ReplayParams
from colregs9_cli.units import MPS_PER_KNOT

ROOT = Path(__file__).resolve().parents[2]
NATIONAL_SAMPLE = ROOT / "fixtures" / "ais" / "dma_nmea_2013-11-12_5min.txt.gz"
HARBOUR_CENTRE = (57.05, 9.94)
DMA_HEADER = ",".join(DMA_COLUMNS)


def harbour_positions(
    vessels: int, duration_s: float, report_s: float, side_m: float, seed: int = 9
) -> pd.DataFrame:
    """Vessels on straight legs at 2–12 kn in a square harbour, turning back at its walls.

    Positions are exact along each leg, so SOG and COG agree with the movement.
    """
    rng = np.random.default_rng(seed)
    frame = LocalFrame(*HARBOUR_CENTRE)
    t = np.arange(0.0, duration_s + 1e-9, report_s)
    half = side_m / 2.0
    speed_mps = rng.uniform(2.0, 12.0, vessels) * MPS_PER_KNOT
    course_rad = rng.uniform(0.0, 2.0 * np.pi, vessels)
    # Reflecting walls: unfold the straight motion, then fold it back into the square.
    north0 = rng.uniform(-half, half, vessels)
    east0 = rng.uniform(-half, half, vessels)
    unfolded_n = north0[:, None] + speed_mps[:, None] * np.cos(course_rad)[:, None] * t
    unfolded_e = east0[:, None] + speed_mps[:, None] * np.sin(course_rad)[:, None] * t

    def fold(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        period = 4.0 * half
        phase = np.mod(x + half, period)
        forward = phase < 2.0 * half
        return np.where(forward, phase, period - phase) - half, np.where(forward, 1.0, -1.0)

    north, sign_n = fold(unfolded_n)
    east, sign_e = fold(unfolded_e)
    vn = speed_mps[:, None] * np.cos(course_rad)[:, None] * sign_n
    ve = speed_mps[:, None] * np.sin(course_rad)[:, None] * sign_e
    lat, lon = frame.to_geodetic(north.ravel(), east.ravel())
    start = pd.Timestamp("2024-06-01 12:00:00", tz="UTC")
    return pd.DataFrame(
        {
            "timestamp": np.tile(start + pd.to_timedelta(t, unit="s"), vessels),
            "mmsi": np.repeat(219_000_000 + np.arange(vessels), len(t)),
            "lat_deg": lat,
            "lon_deg": lon,
            "sog_kn": np.repeat(speed_mps / MPS_PER_KNOT, len(t)),
            "cog_deg": np.mod(np.degrees(np.arctan2(ve, vn)), 360.0).ravel(),
            "heading_deg": np.nan,
            "nav_status": 0,
        }
    )


def write_dma_csv(positions: pd.DataFrame, path: Path) -> None:
    """The positions as DMA "aisdk" 26-column CSV (Class A, under way, 30 m × 8 m × 3 m)."""
    rows = pd.DataFrame(
        {
            "Timestamp": positions["timestamp"].dt.strftime("%d/%m/%Y %H:%M:%S"),
            "Type of mobile": "Class A",
            "MMSI": positions["mmsi"],
            "Latitude": positions["lat_deg"].round(7),
            "Longitude": positions["lon_deg"].round(7),
            "Navigational status": "Under way using engine",
            "ROT": 0,
            "SOG": positions["sog_kn"].round(1),
            "COG": positions["cog_deg"].round(1),
            "Heading": positions["cog_deg"].round(0).astype(int) % 360,
            "IMO": "Unknown",
            "Callsign": "Unknown",
            "Name": "HARBOUR " + positions["mmsi"].astype(str),
            "Ship type": "Cargo",
            "Cargo type": "",
            "Width": 8,
            "Length": 30,
            "Type of position fixing device": "GPS",
            "Draught": 3.0,
            "Destination": "Unknown",
            "ETA": "",
            "Data source type": "AIS",
            "A": 20,
            "B": 10,
            "C": 4,
            "D": 4,
        }
    )
    with path.open("w", encoding="utf-8") as handle:
        handle.write(DMA_HEADER + "\n")
        rows.to_csv(handle, header=False, index=False)


def timed(label: str, func: Callable[[], Any], repeat: int = 1) -> Any:
    best = float("inf")
    result = None
    for _ in range(repeat):
        start = time.perf_counter()
        result = func()
        best = min(best, time.perf_counter() - start)
    print(f"{label:<58} {best:8.2f} s")
    return result


def bench_national(work: Path, repeat: int) -> None:
    for plots in (False, True):
        label = f"national NMEA sample, {'with' if plots else 'without'} plots"
        result = timed(
            label,
            lambda plots=plots: run_replay(
                [NATIONAL_SAMPLE], out_dir=work / f"national-{plots}", plots=plots
            ),
            repeat=repeat if not plots else 1,
        )
        counts = result.counts
        print(
            f"    {counts.vessels} vessels, {counts.segments} segments, "
            f"{counts.candidate_pairs} candidate pairs, {counts.encounters} encounters, "
            f"{counts.triggered} triggered, {len(result.files)} files"
        )


def bench_harbour(work: Path, vessels: int, duration_s: float, side_m: float) -> None:
    positions = harbour_positions(vessels, duration_s, 10.0, side_m)
    csv = work / f"harbour_{vessels}.csv"
    timed(
        f"generate harbour DMA CSV ({len(positions):,} rows)", lambda: write_dma_csv(positions, csv)
    )
    result = timed(
        f"harbour {vessels} vessels, {duration_s / 3600:g} h at 1 s, without plots",
        lambda: run_replay([csv], out_dir=work / "harbour-out", plots=False),
    )
    counts = result.counts
    print(
        f"    {counts.vessels} vessels, {counts.candidate_pair_steps:,} candidate pair-steps, "
        f"{counts.candidate_pairs} candidate pairs, {counts.encounters} encounters, "
        f"{counts.triggered} triggered"
    )


def bench_pair_search(duration_s: float, side_m_300: float) -> None:
    params = ReplayParams()
    frame = LocalFrame(*HARBOUR_CENTRE)
    print("pair search (find_encounters), constant density:")
    for vessels in (100, 200, 300):
        side_m = side_m_300 * np.sqrt(vessels / 300.0)
        tracks = build_tracks(
            harbour_positions(vessels, duration_s, 10.0, side_m), frame, params.tracks
        )
        search = timed(
            f"  {vessels} vessels, {side_m / 1000:.1f} km square, {len(tracks.samples):,} samples",
            lambda tracks=tracks: find_encounters(tracks, params.encounters),
            repeat=2,
        )
        print(f"    {search.candidate_pair_steps:,} candidate pair-steps")
    print("pair search, subsets of the 300-vessel harbour (fixed area):")
    full = build_tracks(harbour_positions(300, duration_s, 10.0, side_m_300), frame, params.tracks)
    mmsis = np.sort(full.samples["mmsi"].unique())
    for vessels in (100, 200, 300):
        keep = full.samples["mmsi"].isin(mmsis[:vessels])
        subset = dataclasses.replace(full, samples=full.samples[keep])
        search = timed(
            f"  {vessels} vessels, {len(subset.samples):,} samples",
            lambda subset=subset: find_encounters(subset, params.encounters),
            repeat=2,
        )
        print(f"    {search.candidate_pair_steps:,} candidate pair-steps")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vessels", type=int, default=300)
    parser.add_argument("--hours", type=float, default=1.0)
    parser.add_argument("--side-km", type=float, default=20.0, help="harbour side at 300 vessels")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="colregs9-bench-") as tmp:
        work = Path(tmp)
        bench_national(work, args.repeat)
        side_m = args.side_km * 1000.0 * np.sqrt(args.vessels / 300.0)
        bench_harbour(work, args.vessels, args.hours * 3600.0, side_m)
        bench_pair_search(args.hours * 3600.0, args.side_km * 1000.0)


if __name__ == "__main__":
    main()
