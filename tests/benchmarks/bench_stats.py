"""Benchmark: the region filter of ``colregs9 stats`` against polars and duckdb.

Generates DMA 26-column CSVs (default 5 M and 10 M rows) in a temporary directory, then,
on the same file in the same run, times each tool in its own subprocess:

- ``colregs9 stats``: the whole command as users run it, the console script of this venv
  (start-up, read, filter, statistics, the four report files, exit);
- ``colregs9 load_ais``: only the streaming read and query filter behind it;
- ``polars``: ``scan_csv(...).filter(box).collect()``;
- ``duckdb``: ``SELECT * FROM read_csv(...) WHERE box``.

Wall time is measured by the parent around the subprocess (interpreter start, imports and
exit included, the same for all). The tools take turns ``--repeat`` times (rounds,
round-robin, each round starting with the next tool, so that a slow spell of the machine hits
all of them and no tool always runs after the same one). Reported per tool: its fastest run (the
usual choice on a machine shared with other work) and its median run, and the median over
rounds of its time over the fastest tool's time in the same round, which is steadier where
the machine's speed drifts from one minute to the next. CPU time (user + system, all threads) is
the child's own. Peak RSS is the child's ``VmHWM`` from ``/proc/self/status`` at exit:
unlike ``ru_maxrss``, which Linux carries over from the parent across fork and exec, it starts
afresh in the new process, so each figure belongs to one tool. The console script is timed
from this (small) parent process instead: its CPU time and ``ru_maxrss`` come from
``os.wait4``, and what it selected from its ``run.json``. The files are generated in a
subprocess too. Every tool reports the rows and vessels it selected, so that the results can
be seen to agree.

Issue 2 asks to time the region filter of ``colregs9 stats`` against the other two: the
verdicts printed at the end judge that (``colregs9 load_ais``) against the 1.5x target, and
give the whole command's ratio beside it.

Usage: python tests/benchmarks/bench_stats.py [--sizes 5000000 10000000] [--repeat 3] [--csv FILE]
Needs the ``bench`` extra (polars, duckdb).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
QUERY = ROOT / "queries" / "limfjorden.toml"
TOOLS = ("colregs9 stats", "colregs9 load_ais", "polars", "duckdb")
# Issue 2's targets: within 1.5x of the fastest tool, peak RSS under 1 GB.
TARGET_RATIO = 1.5
TARGET_RSS_MB = 1024


def _box() -> tuple[float, float, float, float]:
    region = tomllib.loads(QUERY.read_text(encoding="utf-8"))["region"]
    return region["lat_min"], region["lat_max"], region["lon_min"], region["lon_max"]


def _run_tool(tool: str, csv_path: Path, out_dir: Path) -> dict[str, Any]:
    """Run one tool in this (child) process; returns what it selected."""
    lat_min, lat_max, lon_min, lon_max = _box()
    if tool == "colregs9 load_ais":
        from colregs9_cli.ais.load import load_ais
        from colregs9_cli.query import load_query

        data = load_ais([csv_path], query=load_query(QUERY), quiet=True)
        return {"rows": len(data.positions), "vessels": int(data.positions["mmsi"].nunique())}
    if tool == "polars":
        import polars as pl

        frame = (
            pl.scan_csv(csv_path)
            .filter(
                pl.col("Latitude").is_between(lat_min, lat_max)
                & pl.col("Longitude").is_between(lon_min, lon_max)
            )
            .collect()
        )
        return {"rows": frame.height, "vessels": frame["MMSI"].n_unique()}
    if tool == "duckdb":
        import duckdb

        table = duckdb.sql(
            f"SELECT * FROM read_csv('{csv_path}') "
            f"WHERE Latitude BETWEEN {lat_min} AND {lat_max} "
            f"AND Longitude BETWEEN {lon_min} AND {lon_max}"
        ).to_arrow_table()
        return {"rows": table.num_rows, "vessels": len(table.column("MMSI").unique())}
    raise ValueError(tool)


def _peak_rss_mb() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024  # kB
    raise RuntimeError("no VmHWM in /proc/self/status (Linux only)")


def _child(tool: str, csv_path: Path, out_dir: Path) -> None:
    selected = _run_tool(tool, csv_path, out_dir)
    usage = resource.getrusage(resource.RUSAGE_SELF)
    cpu_s = usage.ru_utime + usage.ru_stime
    print(json.dumps({**selected, "peak_rss_mb": _peak_rss_mb(), "cpu_s": cpu_s}))


def _environment() -> dict[str, str]:
    # Cached bytecode, as on a user's machine: PYTHONDONTWRITEBYTECODE (set on some CI and
    # sandbox images) would have colregs9's own modules compiled again in every run.
    return {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def _measure_console_script(csv_path: Path, out_dir: Path) -> dict[str, Any]:
    script = Path(sys.executable).with_name("colregs9")
    if not script.exists():
        raise SystemExit(f"no console script {script}; install the project in this venv")
    command = [str(script), "stats", str(csv_path), "--query", str(QUERY), "--out", str(out_dir)]
    started = time.perf_counter()
    child = subprocess.Popen(
        [*command, "--quiet"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        env=_environment(),
    )
    _, status, usage = os.wait4(child.pid, 0)
    wall_s = time.perf_counter() - started
    assert child.stderr is not None
    errors = child.stderr.read().decode(errors="replace")
    child.stderr.close()
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"colregs9 stats failed on {csv_path}:\n{errors}")
    manifest = json.loads((out_dir / "run.json").read_text(encoding="utf-8"))
    return {
        "rows": manifest["rows_in_query"],
        "vessels": manifest["vessels"],
        "peak_rss_mb": usage.ru_maxrss / 1024,  # kB
        "cpu_s": usage.ru_utime + usage.ru_stime,
        "wall_s": wall_s,
    }


def _measure(tool: str, csv_path: Path, out_dir: Path) -> dict[str, Any]:
    if tool == "colregs9 stats":
        return _measure_console_script(csv_path, out_dir)
    environment = _environment()
    started = time.perf_counter()
    completed = subprocess.run(
        [sys.executable, __file__, "--child", tool, str(csv_path), str(out_dir)],
        capture_output=True,
        text=True,
        check=False,
        env=environment,
    )
    wall_s = time.perf_counter() - started
    if completed.returncode != 0:
        raise SystemExit(f"{tool} failed on {csv_path}:\n{completed.stderr}")
    return {**json.loads(completed.stdout.strip().splitlines()[-1]), "wall_s": wall_s}


def _rotated(tools: tuple[str, ...], by: int) -> tuple[str, ...]:
    by %= len(tools)
    return tools[by:] + tools[:by]


def _data_rows(csv_path: Path) -> int:
    with csv_path.open("rb") as stream:
        return sum(block.count(b"\n") for block in iter(lambda: stream.read(1 << 24), b"")) - 1


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[5_000_000, 10_000_000])
    parser.add_argument("--repeat", type=int, default=3, help="rounds of runs (round-robin)")
    parser.add_argument("--keep", action="store_true", help="keep the generated files")
    parser.add_argument(
        "--csv",
        type=Path,
        help="time this DMA 26-column CSV (made by gen_dma_csv.py) instead of generating files",
    )
    parser.add_argument("--child", nargs=3, metavar=("TOOL", "CSV", "OUT"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        tool, csv_path, out_dir = args.child
        _child(tool, Path(csv_path), Path(out_dir))
        return

    generator = Path(__file__).with_name("gen_dma_csv.py")
    # A given file: its data rows (the header line aside).
    sizes = args.sizes if args.csv is None else [_data_rows(args.csv)]
    workdir = Path(tempfile.mkdtemp(prefix="colregs9-bench-"))
    print(f"box {_box()} from {QUERY.relative_to(ROOT)}; files in {workdir}")
    results: list[dict[str, Any]] = []
    try:
        for rows in sizes:
            csv_path = args.csv if args.csv is not None else workdir / f"aisdk_{rows}.csv"
            if args.csv is None:
                subprocess.run(
                    [sys.executable, str(generator), "--rows", str(rows), "--out", str(csv_path)],
                    check=True,
                    stdout=subprocess.DEVNULL,
                )
            size_mb = csv_path.stat().st_size / 1e6
            print(f"\n{rows:,} rows, {size_mb:,.0f} MB")
            # Round-robin, so that a slow spell of the machine hits every tool alike.
            # Each round starts with the next tool, so that no tool always follows another.
            rounds = [
                {tool: _measure(tool, csv_path, workdir / "out") for tool in _rotated(TOOLS, n)}
                for n in range(args.repeat)
            ]
            for tool in TOOLS:
                runs = [measured[tool] for measured in rounds]
                # This machine's speed drifts within minutes: within one round the tools ran
                # close together, so the ratio to the round's fastest tool is steadier.
                ratios = [
                    measured[tool]["wall_s"] / min(m["wall_s"] for m in measured.values())
                    for measured in rounds
                ]
                result = {
                    "rows_in_file": rows,
                    "file_mb": size_mb,
                    "tool": tool,
                    "wall_s": min(r["wall_s"] for r in runs),
                    "median_wall_s": statistics.median(r["wall_s"] for r in runs),
                    "round_ratio": statistics.median(ratios),
                    "cpu_s": min(r["cpu_s"] for r in runs),
                    "peak_rss_mb": max(r["peak_rss_mb"] for r in runs),
                    "rows": runs[0]["rows"],
                    "vessels": runs[0]["vessels"],
                }
                results.append(result)
                print(
                    f"  {tool:18s} {result['wall_s']:7.2f} s (median {result['median_wall_s']:.2f})"
                    f"  × round's fastest {result['round_ratio']:.2f}"
                    f"  cpu {result['cpu_s']:6.2f} s  {result['peak_rss_mb']:7.0f} MB"
                    f"  rows {result['rows']:,}  vessels {result['vessels']:,}"
                )
            at_size = results[-len(TOOLS) :]
            fastest = min(r["wall_s"] for r in at_size)
            for r in at_size:
                r["best_ratio"] = r["wall_s"] / fastest
            if args.csv is None:
                csv_path.unlink()
    finally:
        if not args.keep:
            shutil.rmtree(workdir, ignore_errors=True)

    _print_table(results)
    _print_verdicts(results)


def _print_table(results: list[dict[str, Any]]) -> None:
    print(
        "\n| rows in file | file size | tool | best wall | × fastest | median wall "
        "| × round's fastest (median) | CPU time | peak RSS | rows selected | vessels |"
    )
    print("|--:|--:|:--|--:|--:|--:|--:|--:|--:|--:|--:|")
    for r in results:
        print(
            f"| {r['rows_in_file']:,} | {r['file_mb']:,.0f} MB | {r['tool']} | {r['wall_s']:.1f} s "
            f"| {r['best_ratio']:.2f} | {r['median_wall_s']:.1f} s "
            f"| {r['round_ratio']:.2f} | {r['cpu_s']:.1f} s | {r['peak_rss_mb']:,.0f} MB "
            f"| {r['rows']:,} | {r['vessels']:,} |"
        )


def _print_verdicts(results: list[dict[str, Any]]) -> None:
    """Issue 2's targets, for the region filter and, beside it, for the whole command."""

    def verdict(met: bool) -> str:
        return "met" if met else "NOT met"

    print("\nTargets (issue 2):")
    for tool, what in (
        ("colregs9 load_ais", "region filter (what the issue times)"),
        ("colregs9 stats", "whole command (beside it)"),
    ):
        for r in (r for r in results if r["tool"] == tool):
            best, rounds = r["best_ratio"], r["round_ratio"]
            print(
                f"  {what}, {r['rows_in_file']:,} rows: {best:.2f} (best) / {rounds:.2f} (rounds)"
                f" x fastest, within {TARGET_RATIO}x: {verdict(max(best, rounds) <= TARGET_RATIO)}"
            )
    rss = [r["peak_rss_mb"] for r in results if r["tool"] == "colregs9 stats"]
    print(
        f"  peak RSS of colregs9 stats: {', '.join(f'{mb:,.0f}' for mb in rss)} MB, under"
        f" {TARGET_RSS_MB:,} MB: {verdict(max(rss) < TARGET_RSS_MB)}; from the smallest to"
        f" the largest file {rss[-1] - rss[0]:+,.0f} MB"
    )


if __name__ == "__main__":
    main()
