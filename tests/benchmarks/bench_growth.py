"""Benchmark for issue 31 §5: how the cost of ``stats`` grows with the rows.

Times, on datasets of several durations (``--days CSV DATASET`` pairs, e.g. 1 h, 24 h and 7
days of ``gen_national_day.py``, each ingested with ``colregs9 ingest``): ``colregs9 stats``
on the dataset, the same on its CSV, and the same statistic in polars and duckdb over the
dataset's Parquet files (``bench_scale._child``), and a Python that only imports what any
``stats`` run must (``bench_scale.STATS_FLOOR_IMPORTS``). The tools take turns on every
dataset in each round (round-robin, ``--repeat`` rounds, each starting with the next
dataset and tool) and each tool's median wall time per dataset is kept.

The cost of a tool is then fitted as ``fixed + per_million × rows / 10⁶`` (least squares
over the datasets): ``fixed`` is the start-up (Python, imports, reading the footers),
``per_million`` the cost of each extra million rows, which is the product's speed. The
targets of issue 31: the dataset's per-million cost ≥ 5× smaller than the CSV's, and within
2× of the fastest engine's.

polars and duckdb are never the project's dependencies: give a Python that has them, and
psutil, with ``--engine-python`` (e.g. a venv made for the benchmark alone).

``--baseline DIR`` also times, in the same rounds, ``stats`` on the dataset with the
``colregs9_cli`` of DIR first on PYTHONPATH (an earlier tree, e.g. ``git archive REV
colregs9_cli | tar -x -C DIR``): before and after a change, under the same load.

Usage: python tests/benchmarks/bench_growth.py --days H1.csv DS1 --days H24.csv DS24
--days WEEK.csv DSWEEK --engine-python /tmp/venv/bin/python [--repeat 3] [--skip-csv-above N]
[--baseline DIR]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

sys.path.insert(0, str(Path(__file__).parent))
import bench_scale  # the harness beside this script

TOOLS = ("stats dataset", "stats CSV", "polars", "duckdb", "imports alone")
ENGINES = ("polars", "duckdb")
BASELINE = "stats dataset, baseline"


def dataset_rows(dataset: Path) -> int:
    return sum(pq.ParquetFile(path).metadata.num_rows for path in dataset.rglob("*.parquet"))


def command(tool: str, csv: Path, dataset: Path, out: Path, found: Path, engine: str) -> list[str]:
    if tool in ENGINES:
        return [engine, bench_scale.__file__, "--child", tool, str(dataset), str(found)]
    return bench_scale._stats_command(stats_tool(tool), str(csv), dataset, out)


def stats_tool(tool: str) -> str:
    """The bench_scale tool a tool of this script runs (the baseline runs its stats)."""
    return "stats dataset" if tool == BASELINE else tool


def measure(tool: str, command: list[str], baseline: Path | None) -> bench_scale.Measured:
    """``bench_scale.measure``, with the baseline's code first on PYTHONPATH for its tool."""
    bench_scale.CODE = baseline if tool == BASELINE else None
    try:
        return bench_scale.measure(command, None, 16 * 1024)
    finally:
        bench_scale.CODE = None


def time_days(
    days: list[tuple[Path, Path]], args: argparse.Namespace, work: Path
) -> list[dict[str, dict[str, float]]]:
    """Each tool's median wall and peak RSS on each dataset. Every round runs every tool on
    every dataset, each round starting with the next dataset and the next tool, so that a
    change of load on the machine falls on all of them alike (a load that fell on one
    dataset's runs alone would tilt the slopes)."""
    rows = [dataset_rows(dataset) for _, dataset in days]
    runs = [
        (day, tool)
        for day in range(len(days))
        for tool in tools_of(args)
        if not (tool == "stats CSV" and rows[day] > args.skip_csv_above)
    ]
    walls: dict[tuple[int, str], list[float]] = {run: [] for run in runs}
    rss: dict[tuple[int, str], float] = {run: 0.0 for run in runs}
    for n in range(args.repeat):
        turn = n * (len(tools_of(args)) + 1) % len(runs)
        for day, tool in runs[turn:] + runs[:turn]:
            csv, dataset = days[day]
            out = bench_scale._fresh(work / "out")
            found = work / "found.json"
            found.unlink(missing_ok=True)
            measured = measure(
                tool, command(tool, csv, dataset, out, found, args.engine_python), args.baseline
            )
            if not measured.ok:
                raise SystemExit(f"{tool} on {dataset}: {measured.status} {measured.detail}")
            result = json.loads(found.read_text()) if found.exists() else {}
            if tool.startswith("stats"):
                result = bench_scale._stats_result(stats_tool(tool), out, measured)
            walls[day, tool].append(measured.wall_s)
            rss[day, tool] = max(rss[day, tool], measured.peak_rss_mb)
            print(
                f"  {rows[day]:>11,} rows round {n + 1} {tool:14s} {measured.wall_s:7.2f} s "
                f"{measured.peak_rss_mb:6.0f} MB {result}",
                flush=True,
            )
    return [
        {
            tool: {"rows": rows[d], "median_s": statistics.median(w), "rss_mb": rss[d, tool]}
            for (d, tool), w in walls.items()
            if d == day
        }
        for day in range(len(days))
    ]


def tools_of(args: argparse.Namespace) -> tuple[str, ...]:
    return (*TOOLS, BASELINE) if args.baseline is not None else TOOLS


def fit(points: list[tuple[int, float]]) -> tuple[float, float]:
    """(fixed s, s per million rows) by least squares."""
    rows = np.array([p[0] for p in points], dtype=float) / 1e6
    walls = np.array([p[1] for p in points])
    per_million, fixed = np.polyfit(rows, walls, 1)
    return float(fixed), float(per_million)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--days", nargs=2, action="append", metavar=("CSV", "DATASET"), required=True
    )
    parser.add_argument("--engine-python", required=True)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument(
        "--skip-csv-above",
        type=int,
        default=10**12,
        help="leave out stats CSV on datasets of more rows than this",
    )
    parser.add_argument(
        "--baseline",
        type=Path,
        help="also time stats on the dataset with the colregs9_cli in this directory",
    )
    args = parser.parse_args()
    # The harness waits for a child in steps of POLL_S: 0.1 s would round the walls by as
    # much as the tens of milliseconds per million rows measured here.
    bench_scale.POLL_S = 0.01
    if args.baseline is not None:
        args.baseline = args.baseline.resolve()
        if not (args.baseline / "colregs9_cli" / "__main__.py").exists():
            raise SystemExit(f"--baseline {args.baseline}: no colregs9_cli/__main__.py in it")
    with tempfile.TemporaryDirectory(prefix="bench-growth-") as scratch:
        days = time_days([(Path(c), Path(d)) for c, d in args.days], args, Path(scratch))
    print(
        "\n| tool | "
        + " | ".join(f"{d['stats dataset']['rows']:,} rows" for d in days)
        + " | fixed | per extra million rows |"
    )
    print("|:--|" + "--:|" * (len(days) + 2))
    slopes = {}
    for tool in tools_of(args):
        points = [(d[tool]["rows"], d[tool]["median_s"]) for d in days if tool in d]
        cells = [
            f"{d[tool]['median_s']:.2f} s, {d[tool]['rss_mb']:,.0f} MB" if tool in d else "–"
            for d in days
        ]
        fixed, slopes[tool] = fit(points) if len(points) > 1 else (float("nan"),) * 2
        print(f"| {tool} | " + " | ".join(cells) + f" | {fixed:.2f} s | {slopes[tool]:.3f} s |")
    engine = min(ENGINES, key=slopes.__getitem__)
    over_csv = slopes["stats CSV"] / slopes["stats dataset"]
    over_engine = slopes["stats dataset"] / slopes[engine]
    print(
        f"\nPer extra million rows: the dataset {over_csv:.1f}x cheaper than the CSV (>= 5x: "
        f"{'met' if over_csv >= 5 else 'NOT met'}); {over_engine:.2f}x the fastest engine, "
        f"{engine} (within 2x: {'met' if over_engine <= 2 else 'NOT met'})."
    )
    if args.baseline is not None:
        print(f"The baseline: {slopes[BASELINE] / slopes[engine]:.2f}x {engine}.")


if __name__ == "__main__":
    main()
