"""Benchmark for issue 31 §5: how the cost of ``stats`` grows with the rows.

Times, on datasets of several durations (``--days CSV DATASET`` pairs, e.g. 1 h, 24 h and 7
days of ``gen_national_day.py``, each ingested with ``colregs9 ingest``): ``colregs9 stats``
on the dataset, the same on its CSV, and the same statistic in polars and duckdb over the
dataset's Parquet files (``bench_scale._child``), and a Python that only imports what any
``stats`` run must (``bench_scale.STATS_FLOOR_IMPORTS``). The tools take turns (round-robin,
``--repeat`` rounds, each starting with the next tool) and each tool's median wall time per
dataset is kept.

The cost of a tool is then fitted as ``fixed + per_million × rows / 10⁶`` (least squares
over the datasets): ``fixed`` is the start-up (Python, imports, reading the footers),
``per_million`` the cost of each extra million rows, which is the product's speed. The
targets of issue 31: the dataset's per-million cost ≥ 5× smaller than the CSV's, and within
2× of the fastest engine's.

polars and duckdb are never the project's dependencies: give a Python that has them, and
psutil, with ``--engine-python`` (e.g. a venv made for the benchmark alone).

Usage: python tests/benchmarks/bench_growth.py --days H1.csv DS1 --days H24.csv DS24
--days WEEK.csv DSWEEK --engine-python /tmp/venv/bin/python [--repeat 3] [--skip-csv-above N]
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


def dataset_rows(dataset: Path) -> int:
    return sum(pq.ParquetFile(path).metadata.num_rows for path in dataset.rglob("*.parquet"))


def command(tool: str, csv: Path, dataset: Path, out: Path, found: Path, engine: str) -> list[str]:
    if tool in ENGINES:
        return [engine, bench_scale.__file__, "--child", tool, str(dataset), str(found)]
    return bench_scale._stats_command(tool, str(csv), dataset, out)


def time_day(
    csv: Path, dataset: Path, args: argparse.Namespace, work: Path
) -> dict[str, dict[str, float]]:
    """Each tool's median wall and peak RSS on one dataset, round-robin."""
    rows = dataset_rows(dataset)
    tools = [t for t in TOOLS if not (t == "stats CSV" and rows > args.skip_csv_above)]
    walls: dict[str, list[float]] = {tool: [] for tool in tools}
    rss: dict[str, float] = {tool: 0.0 for tool in tools}
    for n in range(args.repeat):
        turn = n % len(tools)
        for tool in tools[turn:] + tools[:turn]:
            out = bench_scale._fresh(work / "out")
            found = work / "found.json"
            found.unlink(missing_ok=True)
            measured = bench_scale.measure(
                command(tool, csv, dataset, out, found, args.engine_python), None, 16 * 1024
            )
            if not measured.ok:
                raise SystemExit(f"{tool} on {dataset}: {measured.status} {measured.detail}")
            result = json.loads(found.read_text()) if found.exists() else {}
            if tool.startswith("stats"):
                result = bench_scale._stats_result(tool, out, measured)
            walls[tool].append(measured.wall_s)
            rss[tool] = max(rss[tool], measured.peak_rss_mb)
            print(
                f"  {rows:>11,} rows round {n + 1} {tool:14s} {measured.wall_s:7.2f} s "
                f"{measured.peak_rss_mb:6.0f} MB {result}",
                flush=True,
            )
    return {
        tool: {"rows": rows, "median_s": statistics.median(w), "rss_mb": rss[tool]}
        for tool, w in walls.items()
    }


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
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-growth-") as scratch:
        days = [time_day(Path(c), Path(d), args, Path(scratch)) for c, d in args.days]
    print(
        "\n| tool | "
        + " | ".join(f"{d['stats dataset']['rows']:,} rows" for d in days)
        + " | fixed | per extra million rows |"
    )
    print("|:--|" + "--:|" * (len(days) + 2))
    slopes = {}
    for tool in TOOLS:
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


if __name__ == "__main__":
    main()
