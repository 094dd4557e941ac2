"""Benchmark: manoeuvrability assessments per second on the real ENC at 5 m draught.

One assessment = both arcs over the paper's 180 s horizon at 1 s (360 projected positions and
comfort zones) for a 50 m × 9 m, 5 m-draught target at 7 kn, the paper's defaults. Compared in
the same run with the same work done as a plain per-ellipse shapely loop:

- ``loop, prepared``: one ``shapely.Polygon`` per position and ``water.contains_properly``
  against the same prepared navigable water;
- ``loop, unprepared``: the same against an unprepared copy of the water (the naive code).

The prepared navigable water is built once per (draught, UKC) and cached on the chart
(``Chart.water_index``); its one-off build time is reported separately and is not part of an
assessment. Three cases: a start in the narrow Severn River channel (the worst case: most
comfort zones lie near the bank and need the exact polygon test), one in the widest deep
water (the best case), and ``SAMPLE_SIZE`` starts drawn uniformly over the navigable water
with uniform courses, assessed in turn (the mix a replay meets); the script checks that all
three methods give identical flags for every start.

The machine's speed drifts by up to 2× over seconds (a shared virtual machine), so the three
methods are timed in interleaved rounds of about ``--seconds / --rounds`` each, and the
script prints, per method, the rate of its best round (the usual ``timeit`` practice: slower
rounds measure interference, not the code) and of its median round. The speed-ups compare
rounds taken side by side. Run:
``python tests/benchmarks/bench_manoeuvrability.py [--seconds S] [--rounds K]``.
"""

from __future__ import annotations

import argparse
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.ops import polylabel

from colregs9_cli.charts.water import Chart, load_chart
from colregs9_cli.core.manoeuvrability import (
    ManoeuvrabilityParams,
    SwingModel,
    VesselState,
    assess_manoeuvrability,
    target_rate_of_swing_deg_per_m,
    turning_arcs,
)
from colregs9_cli.core.vessel_defaults import VesselDimensions

ENC = Path(__file__).resolve().parents[2] / "fixtures" / "charts" / "noaa_enc_US5MD1MC.000"
DRAUGHT_M, LENGTH_M, BREADTH_M = 5.0, 50.0, 9.0
DIMENSIONS = VesselDimensions(LENGTH_M, BREADTH_M, DRAUGHT_M, defaulted=(), basis="")
SPEED_MPS = 7.0 * 1852.0 / 3600.0
SAMPLE_SIZE = 100


def _rate(run: Callable[[], object], seconds: float) -> float:
    """Calls per second over at least ``seconds``."""
    calls, start = 0, time.perf_counter()
    while (elapsed := time.perf_counter() - start) < seconds:
        run()
        calls += 1
    return calls / elapsed


def _interleaved_rates(
    runs: dict[str, Callable[[], object]], seconds: float, rounds: int
) -> dict[str, NDArray[np.float64]]:
    """Per method, its rate in each of ``rounds`` rounds; the methods alternate in a round."""
    for run in runs.values():
        run()
    rates: dict[str, list[float]] = {label: [] for label in runs}
    for _ in range(rounds):
        for label, run in runs.items():
            rates[label].append(_rate(run, seconds / rounds))
    return {label: np.array(values) for label, values in rates.items()}


def _loop_assessment(water: object, north: float, east: float, course: float) -> np.ndarray:
    params = ManoeuvrabilityParams(swing_model=SwingModel.FIXED)
    rate = params.alpha * target_rate_of_swing_deg_per_m(LENGTH_M, params)
    arcs = turning_arcs(north, east, course, SPEED_MPS, rate, params.horizon_s, params.step_s)
    a_m, b_m = params.domain_length_factor * LENGTH_M, params.domain_breadth_factor * BREADTH_M
    t_rad = np.linspace(0.0, 2.0 * np.pi, 33)
    flags = []
    for n, e, h in zip(arcs.north_m, arcs.east_m, arcs.heading_deg, strict=True):
        h_rad = math.radians(h)
        fwd, stbd = a_m * np.cos(t_rad), b_m * np.sin(t_rad)
        ring = np.column_stack(
            [
                e + fwd * math.sin(h_rad) + stbd * math.cos(h_rad),
                n + fwd * math.cos(h_rad) - stbd * math.sin(h_rad),
            ]
        )
        flags.append(not water.contains_properly(shapely.Polygon(ring)))
    return np.array(flags)


def _sample(chart: Chart, count: int) -> list[tuple[float, float, float]]:
    """``count`` starts drawn uniformly over the navigable water, with uniform courses."""
    water = chart.navigable_water(DRAUGHT_M)
    rng = np.random.default_rng(9)
    west, south, east, north = shapely.bounds(water)
    starts: list[tuple[float, float, float]] = []
    while len(starts) < count:
        x, y = rng.uniform(west, east), rng.uniform(south, north)
        if shapely.contains_xy(water, x, y):
            starts.append((y, x, rng.uniform(0.0, 360.0)))
    return starts


def _cycle(assess: Callable[[float, float, float], object], starts: list) -> Callable[[], object]:
    """One call assesses the next start of the sample, round and round."""
    position = iter(range(1 << 62))

    def run() -> object:
        north, east, course = starts[next(position) % len(starts)]
        return assess(north, east, course)

    return run


def _positions(chart: Chart) -> dict[str, tuple[float, float, float]]:
    water = chart.navigable_water(DRAUGHT_M)
    parts = shapely.get_parts(water)
    open_water = polylabel(parts[np.argmax(shapely.area(parts))], tolerance=1.0)
    # The Severn River reach used in tests/test_manoeuvrability.py, heading down the channel.
    reach = shapely.get_parts(shapely.intersection(water, shapely.box(-4e3, 2.6e3, 4e3, 3.4e3)))
    channel = reach[np.argmax(shapely.area(reach))].centroid
    return {
        "Severn channel (restricted)": (channel.y, channel.x, 145.0),
        "widest deep water (clear)": (open_water.y, open_water.x, 45.0),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=6.0, help="time per method and position")
    parser.add_argument("--rounds", type=int, default=20, help="interleaved rounds")
    args = parser.parse_args()

    chart = load_chart([ENC])
    start = time.perf_counter()
    index = chart.water_index(DRAUGHT_M)
    build_s = time.perf_counter() - start
    unprepared = shapely.from_wkb(shapely.to_wkb(index.water))
    params = ManoeuvrabilityParams(swing_model=SwingModel.FIXED)
    print(f"navigable water for {DRAUGHT_M} m built once in {build_s * 1e3:.0f} ms, then cached")
    print(f"{'':<49} {'assessments/s':>17} {'speed-up':>18}")
    print(f"{'position':<30} {'method':<18} {'best':>8} {'median':>8} {'best':>9} {'median':>8}")
    cases = {name: [start] for name, start in _positions(chart).items()}
    cases[f"{SAMPLE_SIZE} random starts in the water"] = _sample(chart, SAMPLE_SIZE)
    for name, starts in cases.items():
        red = 0
        for north, east, course in starts:
            fast = assess_manoeuvrability(
                chart, VesselState(north, east, course, SPEED_MPS), DIMENSIONS, params
            )
            for water in (index.water, unprepared):
                assert (_loop_assessment(water, north, east, course) == fast.restricted).all()
            red += int(fast.restricted.sum())
        runs: dict[str, Callable[[], object]] = {
            "vectorised": _cycle(
                lambda n, e, c: assess_manoeuvrability(
                    chart, VesselState(n, e, c, SPEED_MPS), DIMENSIONS, params
                ),
                starts,
            ),
            "loop, prepared": _cycle(
                lambda n, e, c: _loop_assessment(index.water, n, e, c), starts
            ),
            "loop, unprepared": _cycle(
                lambda n, e, c: _loop_assessment(unprepared, n, e, c), starts
            ),
        }
        rates = _interleaved_rates(runs, args.seconds, args.rounds)
        fast_rates = rates["vectorised"]
        for label, rate in rates.items():
            print(
                f"{name[:30]:<30} {label:<18} {rate.max():>8.0f} {np.median(rate):>8.0f}"
                f" {fast_rates.max() / rate.max():>8.1f}× {np.median(fast_rates / rate):>7.1f}×"
            )
        print(f"{'':<30} {red} of {360 * len(starts)} comfort zones red")


if __name__ == "__main__":
    main()
