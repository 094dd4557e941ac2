"""Benchmark: the encounter pair search (and track building) for a synthetic dense harbour.

Usage:  python tests/benchmarks/bench_pairs.py [--minutes 60] [--vessels 100 200 300]
                                               [--density 1.0] [--fixed-area-km 0]

Each vessel sails a circle (radius 300–1500 m, 3–12 kn) whose centre is uniform in a square
harbour; AIS-like reports every 10 s are generated in memory (nothing is written).

- Constant density (default): the harbour's side grows with the fleet so that there are
  ``--density`` vessels per km², as in real waters where more traffic means more water.
  The number of candidate pairs then grows linearly and so should the time.
- ``--fixed-area-km K``: all fleets in one K × K km square. Every vessel is within 2 nm of
  most others, the candidate pairs themselves grow with N², and so must any pair search.

Timed separately: ``build_tracks`` (reports → 1 s samples) and ``find_encounters``.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
import pandas as pd

from colregs9_cli.core.encounters import find_encounters
from colregs9_cli.core.tracks import build_tracks
from colregs9_cli.geo import LocalFrame
from colregs9_cli.jobs.replay_params import ReplayParams
from colregs9_cli.units import MPS_PER_KNOT

FRAME = LocalFrame(57.05, 9.94)
T0 = pd.Timestamp("2024-01-01T12:00:00Z")


def harbour_reports(vessels: int, minutes: float, side_m: float, seed: int = 1) -> pd.DataFrame:
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, minutes * 60.0 + 1.0, 10.0)
    centre_n = rng.uniform(0.0, side_m, vessels)[:, None]
    centre_e = rng.uniform(0.0, side_m, vessels)[:, None]
    radius = rng.uniform(300.0, 1500.0, vessels)[:, None]
    speed_mps = rng.uniform(3.0, 12.0, vessels)[:, None] * MPS_PER_KNOT
    clockwise = np.where(rng.random(vessels) < 0.5, 1.0, -1.0)[:, None]
    phase = rng.uniform(0.0, 2.0 * math.pi, vessels)[:, None]
    angle = phase + clockwise * speed_mps / radius * t[None, :]
    north = centre_n + radius * np.cos(angle)
    east = centre_e + radius * np.sin(angle)
    # The velocity is the derivative of the position along the circle.
    cog_deg = np.degrees(np.arctan2(clockwise * np.cos(angle), -clockwise * np.sin(angle))) % 360
    lat, lon = FRAME.to_geodetic(north.ravel(), east.ravel())
    return pd.DataFrame(
        {
            "timestamp": pd.to_datetime(np.tile(t, vessels), unit="s", utc=True)
            + (T0 - pd.Timestamp(0, tz="UTC")),
            "mmsi": np.repeat(np.arange(219_000_000, 219_000_000 + vessels), len(t)),
            "lat_deg": lat,
            "lon_deg": lon,
            "sog_kn": np.repeat(speed_mps.ravel() / MPS_PER_KNOT, len(t)),
            "cog_deg": cog_deg.ravel(),
            "heading_deg": np.nan,
            "nav_status": 0.0,
        }
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--vessels", type=int, nargs="+", default=[100, 200, 300])
    parser.add_argument("--density", type=float, default=1.0, help="vessels per km²")
    parser.add_argument("--fixed-area-km", type=float, default=0.0)
    args = parser.parse_args()
    params = ReplayParams()
    print(
        f"{'vessels':>7} {'side km':>7} {'samples':>9} {'tracks s':>8} "
        f"{'pair-steps':>11} {'search s':>8} {'µs/pair-step':>12} {'encounters':>10} "
        f"{'triggered':>9}"
    )
    for vessels in args.vessels:
        side_m = (
            args.fixed_area_km * 1000.0
            if args.fixed_area_km > 0
            else math.sqrt(vessels / args.density) * 1000.0
        )
        reports = harbour_reports(vessels, args.minutes, side_m)
        started = time.perf_counter()
        tracks = build_tracks(reports, FRAME, params.tracks)
        tracks_s = time.perf_counter() - started
        started = time.perf_counter()
        search = find_encounters(tracks, params.encounters)
        search_s = time.perf_counter() - started
        per_pair_us = 1e6 * search_s / max(search.candidate_pair_steps, 1)
        print(
            f"{vessels:>7} {side_m / 1000:>7.1f} {len(tracks.samples):>9} {tracks_s:>8.2f} "
            f"{search.candidate_pair_steps:>11} {search_s:>8.2f} {per_pair_us:>12.3f} "
            f"{len(search.encounters):>10} {len(search.triggered):>9}",
            flush=True,
        )


if __name__ == "__main__":
    main()
