"""Benchmark for issue 15 (scale): replay, stats and workers over a national day of AIS.

Builds "a national day at 2013 density" with ``gen_national_day.py`` (the real 5-minute
DMA NMEA sample dead-reckoned to each of ``--hours``, default 1, 6 and 24 h) in a temporary
directory, or reuses the files of ``--cache-dir``, then runs each command as users run it
(the venv's ``colregs9`` console script, in its own process) and measures:

a. ``replay FILE --no-plots`` per duration: wall time, peak RSS, CPU time, encounters;
b. ``ingest FILE --out DATASET`` once, then ``stats DATASET`` against ``stats FILE`` and
   against the same statistic in polars (``scan_parquet``) and duckdb over the dataset's
   Parquet files: per vessel the median length, breadth and draught of its rows (group by
   MMSI), then the count, mean, median, standard deviation, minimum and maximum over the
   vessels. Beside them, the floor of any ``stats`` command: a Python that only imports what
   the command cannot do without (Typer, ``pyarrow.dataset``, which imports pandas itself,
   and matplotlib's ``Figure`` for the histograms), and does nothing else. The five take
   turns ``--repeat`` times (round-robin, each round starting with the next one); the table
   gives the best and median wall time and the median over rounds of the time over the
   round's fastest. On the largest of ``--hours`` (``--stats-hours``);
c. ``replay --workers 1`` against ``--workers 2`` on the 6 h file (``--workers-hours``):
   wall time, peak RSS, and whether encounters.csv and pairs.csv are byte-identical;
d. the cost of one figure: replay of the real 5-minute sample with and without plots
   (``--repeat`` interleaved pairs, medians), the difference over the number of PNGs.

Parts b and c need ``colregs9 ingest`` and ``replay --workers``; the script looks for them
in the ``--help`` output and reports "not available" where they are missing.

Peak RSS: the child's process tree (the command and any Dask workers it starts) is polled
every ``POLL_S`` with psutil and the sum of the resident set sizes recorded; its maximum is
the figure given (sampled, so a peak shorter than the poll interval can be missed). The
command's own ``ru_maxrss`` (from ``os.wait4``, exact, for the main process only) is given
beside it. A child that passes ``--rss-limit-gb`` (16 GB; the machine has 24 GB and no swap)
or ``--timeout`` is killed with its whole process group and reported "exceeded" or "timeout".

Usage: python tests/benchmarks/bench_scale.py [--hours 1 6 24] [--parts replay stats workers
figure] [--repeat 3] [--timeout S] [--rss-limit-gb 16] [--cache-dir DIR]
Needs the ``bench`` extra (psutil; polars and duckdb for part b).
"""

from __future__ import annotations

import argparse
import contextlib
import filecmp
import json
import os
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import psutil

ROOT = Path(__file__).resolve().parents[2]
GENERATOR = Path(__file__).with_name("gen_national_day.py")
SAMPLE = ROOT / "fixtures" / "ais" / "dma_nmea_2013-11-12_5min.txt.gz"
COLREGS9 = Path(sys.executable).with_name("colregs9")
# How to run colregs9: the venv's console script, or ``python -m colregs9_cli`` with
# ``--code DIR`` first on PYTHONPATH (an older checkout, e.g. ``git archive REV colregs9_cli``).
CLI: list[str] = [str(COLREGS9)]
CODE: Path | None = None
PARTS = ("replay", "stats", "workers", "figure")
STATS_TOOLS = ("stats dataset", "stats CSV", "polars", "duckdb", "imports alone")
# What every ``colregs9 stats`` run imports before it reads a byte (see the docstring, b).
STATS_FLOOR_IMPORTS = "import typer, pyarrow.dataset, matplotlib.figure"
POLL_S = 0.1
MB = 1024 * 1024


@dataclass
class Measured:
    """One run of one command."""

    wall_s: float
    peak_rss_mb: float  # the process tree, sampled
    main_rss_mb: float  # the command's own ru_maxrss (exact)
    cpu_s: float  # user + system of the command and the children it waited for
    status: str  # "ok", "failed (exit N)", "timeout", "exceeded"
    detail: str = ""  # the end of stderr when it failed, what it passed when stopped

    @property
    def ok(self) -> bool:
        return self.status == "ok"


def _environment(code: bool = True) -> dict[str, str]:
    # Cached bytecode, as on a user's machine (see bench_stats.py).
    environment = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    if CODE is not None and code:
        environment["PYTHONPATH"] = str(CODE)
    return environment


def _tree_rss(process: psutil.Process) -> int:
    total = 0
    try:
        members = [process, *process.children(recursive=True)]
    except psutil.NoSuchProcess:
        return 0
    for member in members:
        with contextlib.suppress(psutil.NoSuchProcess, psutil.AccessDenied):
            total += member.memory_info().rss
    return total


def measure(
    command: list[str], timeout_s: float | None, rss_limit_mb: float, code: bool = True
) -> Measured:
    """Run ``command``; wall time, peak RSS of its process tree, CPU time, how it ended.

    The child runs in a session of its own, so that stopping it (timeout or memory limit)
    kills exactly the processes it started (its process group). It runs in the system's
    temporary directory: with ``python -m``, the current directory comes first on sys.path
    and would hide ``--code`` (``code``: run with it; the generator runs with this tree).
    """
    with tempfile.TemporaryFile() as errors:
        started = time.perf_counter()
        child = subprocess.Popen(
            command,
            stdout=subprocess.DEVNULL,
            stderr=errors,
            env=_environment(code),
            cwd=tempfile.gettempdir(),
            start_new_session=True,
        )
        process = psutil.Process(child.pid)
        peak = 0
        stopped = ""
        while True:
            pid, status, usage = os.wait4(child.pid, os.WNOHANG)
            if pid == child.pid:
                break
            peak = max(peak, _tree_rss(process))
            elapsed = time.perf_counter() - started
            if not stopped and peak > rss_limit_mb * MB:
                stopped = f"exceeded: {peak / MB:,.0f} MB after {elapsed:.0f} s"
            elif not stopped and timeout_s is not None and elapsed > timeout_s:
                stopped = f"timeout: {elapsed:.0f} s, {peak / MB:,.0f} MB"
            if stopped:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(child.pid, signal.SIGKILL)
            time.sleep(POLL_S)
        wall_s = time.perf_counter() - started
        child.returncode = os.waitstatus_to_exitcode(status)
        errors.seek(0)
        tail = errors.read().decode(errors="replace").strip().splitlines()[-3:]
    if stopped:
        outcome, detail = stopped.split(": ", 1)
    elif child.returncode != 0:
        outcome, detail = f"failed (exit {child.returncode})", " / ".join(tail)
    else:
        outcome, detail = "ok", ""
    return Measured(
        wall_s=wall_s,
        peak_rss_mb=peak / MB,
        main_rss_mb=usage.ru_maxrss / 1024,  # kB
        cpu_s=usage.ru_utime + usage.ru_stime,
        status=outcome,
        detail=detail.strip(),
    )


def _fresh(path: Path) -> Path:
    shutil.rmtree(path, ignore_errors=True)
    return path


def _help(*words: str) -> str:
    done = subprocess.run(
        [*CLI, *words, "--help"],
        capture_output=True,
        text=True,
        check=False,
        env=_environment(),
        cwd=tempfile.gettempdir(),
    )
    return done.stdout


def _available() -> dict[str, bool]:
    top = _help()
    return {
        "ingest": " ingest " in top or "\n  ingest" in top,
        "workers": "--workers" in _help("replay"),
    }


# --- the day ------------------------------------------------------------------------------


def national_day(hours: float, cache: Path, args: argparse.Namespace) -> dict[str, Any]:
    """The day's CSV in ``cache`` (generated once); its generator summary and measurement."""
    path = cache / f"national_{hours:g}h.csv"
    summary_path = path.with_suffix(".json")
    if path.exists() and summary_path.exists():
        summary = json.loads(summary_path.read_text(encoding="utf-8"))
        summary["generated"] = None
        print(f"reusing {path} ({summary['rows']:,} rows)")
        return summary
    command = [sys.executable, str(GENERATOR), "--hours", f"{hours:g}", "--out", str(path)]
    command += ["--seed", str(args.seed), "--json", str(summary_path)]
    measured = measure(command, None, args.rss_limit_gb * 1024, code=False)
    if not measured.ok:
        raise SystemExit(f"generating {hours:g} h failed: {measured.detail}")
    summary = json.loads(summary_path.read_text(encoding="utf-8"))
    summary["generated"] = measured
    print(
        f"generated {path}: {summary['rows']:,} rows, {summary['vessels']:,} vessels"
        f" ({summary['moving']:,} moving), {summary['bytes'] / 1e6:,.0f} MB,"
        f" {measured.wall_s:.1f} s, {measured.peak_rss_mb:,.0f} MB"
    )
    return summary


# --- a. replay -----------------------------------------------------------------------------


def _replay_counts(out: Path) -> dict[str, Any]:
    try:
        return json.loads((out / "run.json").read_text(encoding="utf-8")).get("counts", {})
    except (OSError, ValueError):
        return {}


def bench_replay(
    days: dict[float, dict[str, Any]], work: Path, args: argparse.Namespace
) -> list[dict[str, Any]]:
    results = []
    for hours, day in days.items():
        out = _fresh(work / f"replay_{hours:g}h")
        command = [*CLI, "replay", day["path"], "--no-plots", "--quiet", "--out", str(out)]
        print(f"replay {hours:g} h ...", flush=True)
        measured = measure(command, args.timeout, args.rss_limit_gb * 1024)
        counts = _replay_counts(out) if measured.ok else {}
        print(f"  {_line(measured)}  {counts}")
        results.append({"hours": hours, "rows": day["rows"], "run": measured, "counts": counts})
        shutil.rmtree(out, ignore_errors=True)
    return results


# --- b. stats over the dataset, the CSV, polars and duckdb ----------------------------------


def _child(tool: str, dataset: str, found: Path) -> None:
    """Per vessel the median dimensions, then the statistics over the vessels (one engine);
    writes the vessels and the mean length to ``found`` (JSON)."""
    files = f"{dataset}/date=*/*.parquet"
    dims = ("length_m", "breadth_m", "draught_m")
    if tool == "polars":
        import polars as pl

        per_vessel = (
            pl.scan_parquet(files, hive_partitioning=False)
            .select("mmsi", *dims)
            .group_by("mmsi")
            .agg(pl.col(d).median() for d in dims)
        )
        summary = per_vessel.select(
            pl.len().alias("vessels"),
            *(pl.col(d).count().alias(f"{d}_count") for d in dims),
            *(pl.col(d).mean().alias(f"{d}_mean") for d in dims),
            *(pl.col(d).median().alias(f"{d}_median") for d in dims),
            *(pl.col(d).std().alias(f"{d}_std") for d in dims),
            *(pl.col(d).min().alias(f"{d}_min") for d in dims),
            *(pl.col(d).max().alias(f"{d}_max") for d in dims),
        ).collect()
        row = summary.row(0, named=True)
    elif tool == "duckdb":
        import duckdb

        medians = ", ".join(f"median({d}) AS {d}" for d in dims)
        stats = ", ".join(
            f"count({d}) AS {d}_count, avg({d}) AS {d}_mean, median({d}) AS {d}_median, "
            f"stddev_samp({d}) AS {d}_std, min({d}) AS {d}_min, max({d}) AS {d}_max"
            for d in dims
        )
        connection = duckdb.connect()
        cursor = connection.execute(
            f"WITH v AS (SELECT mmsi, {medians} FROM read_parquet('{files}') GROUP BY mmsi) "
            f"SELECT count(*) AS vessels, {stats} FROM v"
        )
        names = [d[0] for d in cursor.description]
        row = dict(zip(names, cursor.fetchone(), strict=True))
    else:
        raise ValueError(tool)
    result = {"vessels": row["vessels"], "length_mean": row["length_m_mean"]}
    found.write_text(json.dumps(result), encoding="utf-8")


def _stats_command(tool: str, csv: str, dataset: Path, out: Path) -> list[str]:
    if tool == "stats dataset":
        return [*CLI, "stats", str(dataset), "--quiet", "--out", str(out)]
    if tool == "stats CSV":
        return [*CLI, "stats", csv, "--quiet", "--out", str(out)]
    if tool == "imports alone":
        return [sys.executable, "-c", STATS_FLOOR_IMPORTS]
    return [sys.executable, __file__, "--child", tool, str(dataset)]


def _stats_result(tool: str, out: Path, measured: Measured) -> dict[str, Any]:
    """What the run found: vessels and mean of the per-vessel length (as a check)."""
    if not measured.ok or not tool.startswith("stats"):
        return {}
    try:
        manifest = json.loads((out / "run.json").read_text(encoding="utf-8"))
        table = (out / "dimension_stats.csv").read_text(encoding="utf-8").splitlines()
    except OSError:
        return {}
    header = table[0].split(",")
    length = next(
        (dict(zip(header, r.split(","), strict=False)) for r in table[1:] if "length_m" in r), {}
    )
    return {"vessels": manifest.get("vessels"), "length_mean": length.get("mean")}


def bench_stats(day: dict[str, Any], work: Path, args: argparse.Namespace) -> dict[str, Any]:
    dataset = _fresh(work / f"dataset_{day['hours']:g}h")
    print(f"ingest {day['hours']:g} h ...", flush=True)
    ingest = measure(
        [*CLI, "ingest", day["path"], "--out", str(dataset), "--quiet"],
        args.timeout,
        args.rss_limit_gb * 1024,
    )
    print(f"  {_line(ingest)}")
    if not ingest.ok:
        return {"hours": day["hours"], "ingest": ingest, "tools": {}}
    size = sum(f.stat().st_size for f in dataset.rglob("*.parquet"))
    rounds: list[dict[str, tuple[Measured, dict[str, Any]]]] = []
    for n in range(args.repeat):
        measured_round = {}
        turn = n % len(STATS_TOOLS)
        for tool in STATS_TOOLS[turn:] + STATS_TOOLS[:turn]:
            out = _fresh(work / "stats_out")
            command = _stats_command(tool, day["path"], dataset, out)
            if tool in ("polars", "duckdb"):
                measured, found = _measure_engine(command, work, args)
            else:
                measured = measure(command, args.timeout, args.rss_limit_gb * 1024)
                found = _stats_result(tool, out, measured)
            measured_round[tool] = (measured, found)
            print(f"  round {n + 1} {tool:14s} {_line(measured)}  {found}")
        rounds.append(measured_round)
    tools = {}
    for tool in STATS_TOOLS:
        runs = [r[tool][0] for r in rounds]
        if not all(m.ok for m in runs):
            tools[tool] = {"runs": runs, "found": {}, "status": next(m for m in runs if not m.ok)}
            continue
        ratios = [r[tool][0].wall_s / min(m.wall_s for m, _ in r.values() if m.ok) for r in rounds]
        tools[tool] = {
            "best_s": min(m.wall_s for m in runs),
            "median_s": statistics.median(m.wall_s for m in runs),
            "round_ratio": statistics.median(ratios),
            "rss_mb": max(m.peak_rss_mb for m in runs),
            "found": rounds[0][tool][1],
        }
    return {"hours": day["hours"], "ingest": ingest, "dataset_mb": size / 1e6, "tools": tools}


def _print_stats_targets(tools: dict[str, dict[str, Any]]) -> None:
    """Issue 15's two targets for ``stats``, by median wall times, and the floor beside."""
    if any("status" in tools[t] for t in STATS_TOOLS):
        return
    median = {tool: t["median_s"] for tool, t in tools.items()}
    engine = min(("polars", "duckdb"), key=median.__getitem__)
    over_csv = median["stats CSV"] / median["stats dataset"]
    over_engine = median["stats dataset"] / median[engine]
    floor = median["imports alone"] / median[engine]
    print(
        f"\nTargets (issue 15), median walls: the dataset {over_csv:.1f}x faster than the CSV "
        f"(>= 5x: {'met' if over_csv >= 5 else 'NOT met'}); {over_engine:.2f}x the fastest "
        f"engine, {engine} (within 2x: {'met' if over_engine <= 2 else 'NOT met'}); the imports "
        f"alone take {floor:.2f}x {engine}'s whole run."
    )


def _measure_engine(
    command: list[str], work: Path, args: argparse.Namespace
) -> tuple[Measured, dict[str, Any]]:
    found = work / "engine.json"
    found.unlink(missing_ok=True)
    measured = measure([*command, str(found)], args.timeout, args.rss_limit_gb * 1024)
    if not measured.ok or not found.exists():
        return measured, {}
    return measured, json.loads(found.read_text(encoding="utf-8"))


# --- c. workers ----------------------------------------------------------------------------


def bench_workers(day: dict[str, Any], work: Path, args: argparse.Namespace) -> dict[str, Any]:
    runs: dict[int, Measured] = {}
    outs = {}
    for workers in (1, 2):
        out = _fresh(work / f"workers_{workers}")
        outs[workers] = out
        command = [*CLI, "replay", day["path"], "--no-plots", "--quiet"]
        command += ["--out", str(out), "--workers", str(workers)]
        print(f"replay --workers {workers} on {day['hours']:g} h ...", flush=True)
        runs[workers] = measure(command, args.timeout, args.rss_limit_gb * 1024)
        print(f"  {_line(runs[workers])}")
    identical = None
    if all(m.ok for m in runs.values()):
        identical = all(
            filecmp.cmp(outs[1] / name, outs[2] / name, shallow=False)
            for name in ("encounters.csv", "pairs.csv")
        )
    for out in outs.values():
        shutil.rmtree(out, ignore_errors=True)
    return {"hours": day["hours"], "runs": runs, "identical": identical}


# --- d. a figure ---------------------------------------------------------------------------


def bench_figure(work: Path, args: argparse.Namespace) -> dict[str, Any]:
    walls: dict[bool, list[float]] = {False: [], True: []}
    figures = 0
    for n in range(args.repeat):
        for plots in (n % 2 == 0, n % 2 != 0):
            out = _fresh(work / "figure")
            command = [*CLI, "replay", str(SAMPLE), "--quiet", "--out", str(out)]
            command += [] if plots else ["--no-plots"]
            measured = measure(command, args.timeout, args.rss_limit_gb * 1024)
            if not measured.ok:
                return {"status": measured}
            walls[plots].append(measured.wall_s)
            if plots:
                figures = len(list(out.rglob("*.png")))
            print(f"  figure round {n + 1}, plots {plots!s:5}: {_line(measured)}")
    no_plots, with_plots = (statistics.median(walls[p]) for p in (False, True))
    return {
        "no_plots_s": no_plots,
        "plots_s": with_plots,
        "figures": figures,
        "per_figure_s": (with_plots - no_plots) / figures if figures else float("nan"),
    }


# --- output --------------------------------------------------------------------------------


def _line(m: Measured) -> str:
    text = f"{m.status}: {m.wall_s:.1f} s, peak {m.peak_rss_mb:,.0f} MB (tree)"
    text += f", {m.main_rss_mb:,.0f} MB (main), cpu {m.cpu_s:.1f} s"
    return text + (f" [{m.detail}]" if m.detail else "")


def _cell(m: Measured) -> str:
    return m.status if m.ok else f"{m.status} ({m.detail})"


def print_tables(
    days: dict[float, dict[str, Any]],
    replay: list[dict[str, Any]] | None,
    stats: dict[str, Any] | str | None,
    workers: dict[str, Any] | str | None,
    figure: dict[str, Any] | None,
) -> None:
    print("\n### The national day (gen_national_day.py)\n")
    print(
        "| hours | rows | rows per hour | vessels | moving | CSV size | generated in | peak RSS |"
    )
    print("|--:|--:|--:|--:|--:|--:|--:|--:|")
    for hours, d in days.items():
        g = d["generated"]
        made = (f"{g.wall_s:.1f} s", f"{g.peak_rss_mb:,.0f} MB") if g else ("(cached)", "")
        print(
            f"| {hours:g} | {d['rows']:,} | {d['rows'] / hours:,.0f} | {d['vessels']:,} "
            f"| {d['moving']:,} | {d['bytes'] / 1e6:,.0f} MB | {made[0]} | {made[1]} |"
        )
    if replay is not None:
        print("\n### a. `replay --no-plots`\n")
        print(
            "| hours | rows | wall | peak RSS (tree) | ru_maxrss | CPU | encounters "
            "| triggered | status |"
        )
        print("|--:|--:|--:|--:|--:|--:|--:|--:|:--|")
        for r in replay:
            m, c = r["run"], r["counts"]
            print(
                f"| {r['hours']:g} | {r['rows']:,} | {m.wall_s:,.1f} s | {m.peak_rss_mb:,.0f} MB "
                f"| {m.main_rss_mb:,.0f} MB | {m.cpu_s:,.1f} s | {c.get('encounters', '')} "
                f"| {c.get('triggered', '')} | {_cell(m)} |"
            )
    if stats is not None:
        print("\n### b. `stats` over the dataset, the CSV, polars and duckdb\n")
        if isinstance(stats, str):
            print(stats)
        else:
            ingest = stats["ingest"]
            print(
                f"`ingest` of the {stats['hours']:g} h CSV: {_cell(ingest)}, "
                f"{ingest.wall_s:.1f} s, peak RSS {ingest.peak_rss_mb:,.0f} MB"
                + (f", dataset {stats['dataset_mb']:,.0f} MB" if "dataset_mb" in stats else "")
                + "\n"
            )
            print(
                "| tool | best wall | median wall | × round's fastest (median) | peak RSS "
                "| vessels | mean length |"
            )
            print("|:--|--:|--:|--:|--:|--:|--:|")
            for tool, t in stats["tools"].items():
                if "status" in t:
                    print(f"| {tool} | {_cell(t['status'])} | | | | | |")
                    continue
                f = t["found"]
                mean = f.get("length_mean")
                mean = f"{float(mean):.2f}" if mean not in (None, "") else ""
                print(
                    f"| {tool} | {t['best_s']:.2f} s | {t['median_s']:.2f} s "
                    f"| {t['round_ratio']:.2f} | {t['rss_mb']:,.0f} MB "
                    f"| {f.get('vessels', '')} | {mean} |"
                )
            _print_stats_targets(stats["tools"])
    if workers is not None:
        print("\n### c. `replay --workers 1` against `--workers 2`\n")
        if isinstance(workers, str):
            print(workers)
        else:
            print("| workers | hours | wall | peak RSS (tree) | CPU | status |")
            print("|--:|--:|--:|--:|--:|:--|")
            for n, m in workers["runs"].items():
                print(
                    f"| {n} | {workers['hours']:g} | {m.wall_s:,.1f} s | {m.peak_rss_mb:,.0f} MB "
                    f"| {m.cpu_s:,.1f} s | {_cell(m)} |"
                )
            runs = workers["runs"]
            if all(m.ok for m in runs.values()):
                print(
                    f"\nspeed-up {runs[1].wall_s / runs[2].wall_s:.2f}x; encounters.csv and "
                    f"pairs.csv identical: {'yes' if workers['identical'] else 'NO'}"
                )
    if figure is not None:
        print("\n### d. The cost of a figure (the real 5-minute sample)\n")
        if "status" in figure:
            print(f"replay failed: {_cell(figure['status'])}")
        else:
            print("| no plots (median) | with plots (median) | figures | per figure |")
            print("|--:|--:|--:|--:|")
            print(
                f"| {figure['no_plots_s']:.1f} s | {figure['plots_s']:.1f} s "
                f"| {figure['figures']} | {figure['per_figure_s']:.2f} s |"
            )
            for r in replay or []:
                triggered = r["counts"].get("triggered")
                if triggered is not None:
                    print(
                        f"\n{r['hours']:g} h: {triggered:,} triggered encounters (one PNG each),"
                        f" so about {triggered * figure['per_figure_s']:,.0f} s of figures"
                        " on top of the run without plots."
                    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, nargs="+", default=[1.0, 6.0, 24.0])
    parser.add_argument("--parts", nargs="+", choices=PARTS, default=list(PARTS))
    parser.add_argument("--repeat", type=int, default=3, help="rounds for parts b and d")
    parser.add_argument("--timeout", type=float, default=None, help="stop a run after S s")
    parser.add_argument("--rss-limit-gb", type=float, default=16.0, help="stop a run above it")
    parser.add_argument("--stats-hours", type=float, default=None, help="default: max --hours")
    parser.add_argument("--workers-hours", type=float, default=6.0)
    parser.add_argument("--seed", type=int, default=15)
    parser.add_argument("--cache-dir", type=Path, default=None, help="keep and reuse the days")
    parser.add_argument(
        "--code",
        type=Path,
        default=None,
        help="run `python -m colregs9_cli` from this directory (holding colregs9_cli/) instead"
        " of the venv's console script, e.g. an older revision from `git archive`",
    )
    parser.add_argument(
        "--child", nargs=3, metavar=("TOOL", "DATASET", "FOUND"), help=argparse.SUPPRESS
    )
    args = parser.parse_args()
    if args.child:
        tool, dataset, found = args.child
        _child(tool, dataset, Path(found))
        return
    global CODE
    if args.code is not None:
        CODE = args.code.resolve()
        if not (CODE / "colregs9_cli" / "__main__.py").exists():
            raise SystemExit(f"--code {CODE}: no colregs9_cli/__main__.py in it")
        CLI[:] = [sys.executable, "-m", "colregs9_cli"]
    elif not COLREGS9.exists():
        raise SystemExit(f"no console script {COLREGS9}; install the project in this venv")

    available = _available()
    work = Path(tempfile.mkdtemp(prefix="colregs9-scale-"))
    cache = (args.cache_dir or work).resolve()
    cache.mkdir(parents=True, exist_ok=True)
    print(f"running {' '.join(CLI)}" + (f" from {CODE}" if CODE else ""))
    print(f"days in {cache}, outputs in {work}; available: {available}")
    stats_hours = args.stats_hours or max(args.hours)
    try:
        needed = set(args.hours if "replay" in args.parts else [])
        if "stats" in args.parts and available["ingest"]:
            needed.add(stats_hours)
        if "workers" in args.parts and available["workers"]:
            needed.add(args.workers_hours)
        days = {h: {**national_day(h, cache, args), "hours": h} for h in sorted(needed)}
        replay = (
            bench_replay({h: days[h] for h in args.hours}, work, args)
            if "replay" in args.parts
            else None
        )
        stats: dict[str, Any] | str | None = None
        if "stats" in args.parts:
            stats = (
                bench_stats(days[stats_hours], work, args)
                if available["ingest"]
                else "not available: `colregs9 ingest` is not in `colregs9 --help`"
            )
        workers: dict[str, Any] | str | None = None
        if "workers" in args.parts:
            workers = (
                bench_workers(days[args.workers_hours], work, args)
                if available["workers"]
                else "not available: `--workers` is not in `colregs9 replay --help`"
            )
        figure = bench_figure(work, args) if "figure" in args.parts else None
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print_tables(days, replay, stats, workers, figure)


if __name__ == "__main__":
    main()
