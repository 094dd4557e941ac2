"""The command line. Each command parses its arguments, calls one library function and turns
``Colregs9Error`` into one ``Error: …`` line and an exit code. No logic lives here."""

from __future__ import annotations

import errno
import os
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated, Any

import typer
from typer.core import TyperCommand, TyperGroup

from . import __version__
from .ais.layouts import LAYOUTS
from .errors import Colregs9Error, OutputError

# --quiet means the same everywhere: stdout carries the results, stderr the progress and the
# closing line that says where the files went; --quiet silences stderr but for errors.
QUIET_HELP = (
    "No progress bars and no closing line naming the files written, both on stderr "
    "(progress bars are also off when stderr is not a terminal). Results and errors still print."
)
OVERWRITE_HELP = (
    "Write into an --out that holds a report of another command or files colregs9 did not "
    "write; only colregs9's files are replaced, yours stay."
)
# What every AIS reader takes (ais/sources.py tells the compression from the first bytes).
AIS_FILES_HELP = (
    "AIS files: DMA CSV (22 or 26 columns), MarineCadastre CSV (2015 on), exactEarth/Spire CSV, "
    "any CSV with --columns, raw NMEA or canonical Parquet; plain or compressed (gzip, bzip2, "
    "xz, zstd, or a zip holding one file)"
)
DATASETS_HELP = "; or dataset directories made by colregs9 ingest."
# The layouts' names, from their registry (a light module: --help does not load pyarrow).
LAYOUT_HELP = (
    f"Input layout instead of detecting it: {', '.join(LAYOUTS)}. "
    "Needed for a CSV without its header."
)
COLUMNS_HELP = (
    "Column map (TOML) for any other CSV: source column -> canonical column, time format, "
    "units, sentinels (README: Column maps)."
)
# What charts/read.py reads, told by the suffix.
CHART_FORMATS = (
    "S-57 base cell .000 (with its updates .001, .002 … beside it), GeoJSON (.geojson, .json) "
    "or GeoPackage (.gpkg)"
)


class _Command(TyperCommand):
    """A command whose help lists each argument by its metavar alone.

    typer 0.29 writes an argument as ``AIS <list[Path]>``: the metavar, then its Python type,
    which means nothing to a user. Options already show their metavar alone.
    """

    # Any: the context and formatter are of the click that typer vendors (typer._click), a
    # private module.
    def format_options(self, ctx: Any, formatter: Any) -> None:
        arguments: list[tuple[str, str]] = []
        options: list[tuple[str, str]] = []
        for param in self.get_params(ctx):
            record = param.get_help_record(ctx)
            if record is None:
                continue
            if param.param_type_name == "argument":
                name = param.metavar or (param.name or "").upper()
                arguments.append((name + ("..." if param.nargs != 1 else ""), record[1]))
            else:
                options.append(record)
        for title, rows in (("Arguments", arguments), ("Options", options)):
            if rows:
                with formatter.section(title):
                    formatter.write_dl(rows)


class _App(TyperGroup):
    """The command group, with Click's own errors (an unknown option, a missing argument, a
    value that is not a number) as one ``Error:`` line like every other error, instead of
    Click's usage block: the usage line, a hint and a blank line before the error."""

    def main(  # type: ignore[override]
        self,
        args: Sequence[str] | None = None,
        prog_name: str | None = None,
        complete_var: str | None = None,
        standalone_mode: bool = True,
        **extra: Any,
    ) -> Any:
        arguments = sys.argv[1:] if args is None else list(args)
        if not standalone_mode or not arguments:  # no arguments: the help, as Click shows it
            return super().main(arguments, prog_name, complete_var, standalone_mode, **extra)
        try:
            status = super().main(arguments, prog_name, complete_var, False, **extra)
        except typer.TyperException as exc:  # Click's exceptions derive from it
            typer.echo(f"Error: {usage_error_line(exc)}", err=True)
            sys.exit(exc.exit_code)
        except typer.Abort:
            typer.echo("Aborted!", err=True)
            sys.exit(1)
        # An explicit typer.Exit comes back as its status; a command's return value is None.
        sys.exit(status if isinstance(status, int) else 0)


def _one_line(message: str) -> str:
    """An error message on one line, whatever a file name or a value in it holds."""
    return message.replace("\r", "\\r").replace("\n", "\\n")


def usage_error_line(exc: typer.TyperException) -> str:
    """Click's error message on one line, with where to find the command's help."""
    message = _one_line(exc.format_message())
    context = getattr(exc, "ctx", None)
    if context is None:
        return message
    return f"{message} (see '{context.command_path} --help')"


app = typer.Typer(
    name="colregs9",
    cls=_App,
    help="COLREGs rule 9 (narrow channels) audits of historical AIS.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
)


def _input_format(fmt: str | None, columns: Path | None) -> str | None:
    """The layout given by --format, or the one that stands for --columns MAP.toml."""
    if columns is None:
        return fmt
    from .errors import ParameterError

    if fmt is not None:
        raise ParameterError(f"--format {fmt} and --columns {columns}: give one of them, not both")
    from .ais.column_map import map_layout

    return map_layout(columns)


@contextmanager
def _user_errors() -> Iterator[None]:
    try:
        yield
    except Colregs9Error as exc:
        typer.echo(f"Error: {_one_line(str(exc))}", err=True)
        raise typer.Exit(exc.exit_code) from None
    except OSError as exc:
        # Python 3.11's Path.exists, is_file and is_dir raise this one, wherever a path is
        # first looked at.
        if exc.errno != errno.ENAMETOOLONG:
            raise
        typer.echo(
            f"Error: {_one_line(str(exc.filename))}: a file name longer than the file system "
            "allows; give a shorter one",
            err=True,
        )
        raise typer.Exit(2) from None


def _out_file(raw: str | None) -> Path | None:
    """An ``--out`` that names a file, as typed: a trailing separator names a directory,
    which ``Path`` would drop (``trail.png/`` would write ``trail.png``)."""
    if raw is None:
        return None
    if raw.endswith(tuple(sep for sep in (os.sep, os.altsep) if sep)):
        raise OutputError(
            f"{raw}: --out ends in a path separator, so it names a directory; "
            "give the path of a file to write"
        )
    return Path(raw)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"colregs9 {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="Show the version and exit."
    ),
) -> None:
    """COLREGs rule 9 (narrow channels) audits of historical AIS.

    Example: colregs9 stats fixtures/ais/aisdk_2024-09-09_sample.csv
    """


@app.command("replay", cls=_Command)
def replay_command(
    ais: Annotated[
        list[Path],
        typer.Argument(
            metavar="AIS",
            help=AIS_FILES_HELP + DATASETS_HELP,
        ),
    ],
    chart: Annotated[
        list[Path] | None,
        typer.Option(
            "--chart",
            metavar="CHART",
            help=f"Chart file: {CHART_FORMATS}; repeatable.",
        ),
    ] = None,
    query: Annotated[
        Path | None,
        typer.Option(
            "--query",
            metavar="FILE",
            help="Query TOML: region, time window, vessels and the [replay], [colregs] and "
            "[manoeuvrability] parameters. Without it: all the data, the paper's defaults.",
        ),
    ] = None,
    own_mmsi: Annotated[
        list[int] | None,
        typer.Option(
            "--own-mmsi",
            metavar="MMSI",
            help="Vessel in the own-ship seat; repeatable. Default: every vessel.",
        ),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out", metavar="DIR", help="Output directory. Default: reports/replay-<query name>/."
        ),
    ] = None,
    no_plots: Annotated[
        bool, typer.Option("--no-plots", help="Do not draw the per-encounter PNGs.")
    ] = False,
    fmt: Annotated[
        str | None,
        typer.Option(
            "--format",
            metavar="LAYOUT",
            help=LAYOUT_HELP,
        ),
    ] = None,
    columns: Annotated[
        Path | None,
        typer.Option("--columns", metavar="MAP.toml", help=COLUMNS_HELP),
    ] = None,
    step_s: Annotated[
        float | None, typer.Option("--step-s", metavar="S", help="Replay time step Δt (s); 1.")
    ] = None,
    tcpa_act_s: Annotated[
        float | None,
        typer.Option("--tcpa-act-s", metavar="S", help="Trigger when 0 <= TCPA <= this (s); 180."),
    ] = None,
    cpa_req_m: Annotated[
        float | None,
        typer.Option("--cpa-req-m", metavar="M", help="Trigger when CPA is below this (m); 150."),
    ] = None,
    candidate_range_m: Annotated[
        float | None,
        typer.Option(
            "--candidate-range-m",
            metavar="M",
            help="Pairs within this range are candidates (m); 3704 (2 nm).",
        ),
    ] = None,
    min_sog_kn: Annotated[
        float | None,
        typer.Option(
            "--min-sog-kn", metavar="KN", help="Vessels slower than this form no pairs (kn); 0.5."
        ),
    ] = None,
    alpha: Annotated[
        float | None,
        typer.Option("--alpha", metavar="A", help="Scale α of the rate of swing, in [0, 1]; 0.4."),
    ] = None,
    accept_chart_gaps: Annotated[
        bool,
        typer.Option(
            "--accept-chart-gaps",
            help="Use an S-57 cell whose update sequence has a gap, as updated up to the gap "
            "(recorded in run.json).",
        ),
    ] = False,
    overwrite: Annotated[
        bool,
        typer.Option("--overwrite", help=OVERWRITE_HELP),
    ] = False,
    domains: Annotated[
        str,
        typer.Option(
            "--domains",
            metavar="all|restricted|none",
            help="Ship-domain ellipses in report.gpkg: restricted, those not inside navigable "
            "water (what an auditor checks against the chart); all, every ellipse of every "
            "assessment, red, blue and grey (10 of the 13 MB of the San Diego fixture's "
            "report.gpkg); none.",
        ),
    ] = "restricted",
    vessel_tracks: Annotated[
        bool,
        typer.Option(
            "--vessel-tracks/--no-vessel-tracks",
            help="Every vessel's track over the run in report.gpkg (vessel_tracks, "
            "lone_reports), for QGIS's Temporal Controller: about 50 bytes a vertex, 149 MB "
            "of a national day; leave them out of long runs.",
        ),
    ] = True,
    slab_minutes: Annotated[
        float | None,
        typer.Option(
            "--slab-minutes",
            metavar="MIN",
            help="Work through time in slabs this long: memory grows with it, results do not "
            "change; 30.",
        ),
    ] = None,
    workers: Annotated[
        int,
        typer.Option(
            "--workers",
            metavar="N",
            help="Run the slabs on a local Dask cluster of N worker processes; 1 runs them here.",
        ),
    ] = 1,
    scheduler: Annotated[
        str | None,
        typer.Option(
            "--scheduler",
            metavar="ADDRESS",
            help="Run the slabs on the Dask cluster whose scheduler is at ADDRESS "
            "(tcp://host:8786) instead.",
        ),
    ] = None,
    scratch: Annotated[
        Path | None,
        typer.Option(
            "--scratch",
            metavar="DIR",
            help="Where to spill the decided reports (default: the system's temporary "
            "directory); on a multi-machine cluster, a directory every worker mounts.",
        ),
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", help=QUIET_HELP)] = False,
) -> None:
    """Replay AIS pair by pair through COLREGs rules 13–15 and the rule 9 automaton.

    Prints one line per triggered pair and writes to --out: pairs.csv (one verdict per pair,
    the same from both seats), encounters.csv (one row per seat), encounters/<id>.csv and
    .png, report.gpkg (the encounters, tracks, CPAs and domains in WGS84, for QGIS),
    index.html (the report as one web page), index.md and run.json. Without --chart,
    manoeuvrability is "unknown".

    \b
    Example:
      colregs9 replay fixtures/ais/dma_nmea_2013-11-12_5min.txt.gz --no-plots
    """
    from .jobs.replay import run_replay

    with _user_errors():
        fmt = _input_format(fmt, columns)
        result = run_replay(
            ais,
            chart_paths=chart or [],
            query_path=query,
            own_mmsi=own_mmsi or [],
            out_dir=out,
            plots=not no_plots,
            overrides={
                "replay": {
                    "step_s": step_s,
                    "tcpa_act_s": tcpa_act_s,
                    "cpa_req_m": cpa_req_m,
                    "candidate_range_m": candidate_range_m,
                    "min_sog_kn": min_sog_kn,
                    "slab_s": None if slab_minutes is None else slab_minutes * 60.0,
                },
                "manoeuvrability": {"alpha": alpha},
            },
            fmt=fmt,
            quiet=quiet,
            overwrite=overwrite,
            accept_chart_gaps=accept_chart_gaps,
            workers=workers,
            scheduler=scheduler,
            scratch_dir=scratch,
            domains=domains,
            vessel_tracks=vessel_tracks,
        )
    typer.echo(result.text, nl=False)
    if not quiet:
        typer.echo(f"Reports in {result.out_dir}", err=True)


@app.command("simulate", cls=_Command)
def simulate_command(
    scenario: Annotated[
        Path,
        typer.Argument(
            metavar="SCENARIO.toml",
            help="Scenario TOML (vessels, routes, speeds, timing) naming its chart: "
            f"{CHART_FORMATS}.",
        ),
    ],
    out: Annotated[
        str | None,  # as typed: see _out_file
        typer.Option(
            "--out",
            metavar="FILE.csv",
            help="Output CSV. Default: reports/simulate-<scenario name>.csv.",
        ),
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", help=QUIET_HELP)] = False,
) -> None:
    """Simulate a scenario into synthetic AIS in the DMA 26-column CSV layout.

    Checks that every route lies in water navigable for that vessel's draught on the
    scenario's chart, then writes one report per vessel every ais_interval_s.

    \b
    Example:
      colregs9 simulate colregs9_cli/data/demo/greenhopper_restricted.toml
    """
    from .jobs.simulate import simulate_scenario

    with _user_errors():
        result = simulate_scenario(scenario, _out_file(out), quiet=quiet)
    typer.echo(result.text, nl=False)
    if not quiet:
        typer.echo(f"AIS written to {result.out_path}", err=True)


@app.command("stats", cls=_Command)
def stats_command(
    ais: Annotated[
        list[Path],
        typer.Argument(
            metavar="AIS",
            help=AIS_FILES_HELP + DATASETS_HELP,
        ),
    ],
    query: Annotated[
        Path | None,
        typer.Option(
            "--query",
            metavar="FILE",
            help="Query TOML (region, time window, vessels). Default: all the data.",
        ),
    ] = None,
    per: Annotated[
        str,
        typer.Option(
            "--per",
            metavar="vessel|message",
            help="vessel: one value per vessel, the median of its reports; message: every "
            "position message in the query that has a value.",
        ),
    ] = "vessel",
    by: Annotated[
        str | None,
        typer.Option("--by", metavar="ship_type", help="ship_type: also one table per ship type."),
    ] = None,
    fmt: Annotated[
        str | None,
        typer.Option(
            "--format",
            metavar="LAYOUT",
            help=LAYOUT_HELP,
        ),
    ] = None,
    columns: Annotated[
        Path | None,
        typer.Option("--columns", metavar="MAP.toml", help=COLUMNS_HELP),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option(
            "--out", metavar="DIR", help="Output directory. Default: reports/stats-<query name>/."
        ),
    ] = None,
    overwrite: Annotated[
        bool,
        typer.Option("--overwrite", help=OVERWRITE_HELP),
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", help=QUIET_HELP)] = False,
) -> None:
    """Vessel dimension statistics (length, breadth, draught), like the paper's table.

    Prints the table and writes to --out: dimension_stats.csv, dimension_stats.md,
    dimension_histograms.png, index.html (the table and histograms as one web page) and
    run.json. std is the sample standard deviation (ddof = 1), empty below 2 values.
    Exit codes: 0 done, 2 bad input file, query or option, 3 the query selects no rows.

    \b
    Example:
      colregs9 stats fixtures/ais/aisdk_2024-09-09_sample.csv --by ship_type
    """
    from .jobs.stats import run_stats

    with _user_errors():
        fmt = _input_format(fmt, columns)
        result = run_stats(
            ais,
            query_path=query,
            per=per,
            by=by,
            fmt=fmt,
            out_dir=out,
            quiet=quiet,
            overwrite=overwrite,
        )
    typer.echo(result.text, nl=False)
    if not quiet:
        typer.echo(f"Reports in {result.out_dir}", err=True)


@app.command("ingest", cls=_Command)
def ingest_command(
    ais: Annotated[
        list[Path],
        typer.Argument(
            metavar="AIS",
            help=AIS_FILES_HELP + ".",
        ),
    ],
    out: Annotated[
        Path,
        typer.Option(
            "--out",
            metavar="DATASET",
            help="Dataset directory: new, empty, or a dataset to append to.",
        ),
    ],
    query: Annotated[
        Path | None,
        typer.Option(
            "--query",
            metavar="FILE",
            help="Query TOML: keep only the rows in its region, time window and vessels. "
            "Default: all the data.",
        ),
    ] = None,
    fmt: Annotated[
        str | None,
        typer.Option(
            "--format",
            metavar="LAYOUT",
            help=LAYOUT_HELP,
        ),
    ] = None,
    columns: Annotated[
        Path | None,
        typer.Option("--columns", metavar="MAP.toml", help=COLUMNS_HELP),
    ] = None,
    quiet: Annotated[bool, typer.Option("--quiet", help=QUIET_HELP)] = False,
) -> None:
    """Clean AIS files into a Parquet dataset partitioned by date, for stats and replay.

    Writes DATASET/date=YYYY-MM-DD/part-*.parquet (canonical columns, sorted so that a time
    and region query skips most row groups) and DATASET/colregs9-dataset.json (each input's
    sha256 and rejects ledger). A file already in the dataset is skipped; a new one (the next
    day) is added. Give DATASET to stats or replay in place of the files.

    \b
    Example:
      colregs9 ingest fixtures/ais/aisdk_2024-09-09_sample.csv \\
          --out reports/ais-dataset
    """
    from .jobs.ingest import ingest

    with _user_errors():
        fmt = _input_format(fmt, columns)
        result = ingest(ais, out, query_path=query, fmt=fmt, quiet=quiet)
    typer.echo(result.text, nl=False)
    if not quiet:
        typer.echo(f"Dataset in {result.out_dir}", err=True)


@app.command("swing", cls=_Command)
def swing_command(
    out: Annotated[
        Path | None,
        typer.Option("--out", metavar="DIR", help="Output directory. Default: reports/swing/."),
    ] = None,
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    quiet: Annotated[bool, typer.Option("--quiet", help=QUIET_HELP)] = False,
) -> None:
    """The rate of swing of the paper's 14 reference vessels: table, CSV and figure.

    Prints the table with rate_of_swing_deg_per_m = 360 / (2π·turn_radius_m) and writes to
    --out: rate_of_swing.csv, rate_of_swing.png (rate of swing against length, one marker per
    class) and run.json.

    \b
    Example:
      colregs9 swing --out reports/swing
    """
    from .jobs.swing import run_swing

    with _user_errors():
        report = run_swing(out, overwrite=overwrite)
    typer.echo(report.text, nl=False)
    if not quiet:
        typer.echo(f"Reports in {report.out_dir}", err=True)


@app.command("chart", cls=_Command)
def chart_command(
    charts: Annotated[
        list[Path],
        typer.Argument(
            metavar="CHART",
            help=f"Chart files: {CHART_FORMATS}; several are merged.",
        ),
    ],
    draught: Annotated[
        float | None,
        typer.Option(
            "--draught",
            metavar="M",
            help="Draught (m): print the navigable area for it and draw the chart.",
        ),
    ] = None,
    ukc: Annotated[
        float,
        typer.Option("--ukc", metavar="M", help="Under-keel clearance added to the draught (m)."),
    ] = 0.0,
    out: Annotated[
        str | None,  # as typed: see _out_file
        typer.Option(
            "--out",
            metavar="FILE.png|FILE.gpkg",
            help="With --draught: the plot (.png; default reports/chart-<stem>.png) or a "
            "GeoPackage in WGS84 with the depth areas, coverage, land, navigable water and the "
            "charted channels with their axes (.gpkg).",
        ),
    ] = None,
    accept_chart_gaps: Annotated[
        bool,
        typer.Option(
            "--accept-chart-gaps",
            help="Use an S-57 cell whose update sequence has a gap, as updated up to the gap "
            "(the summary names the missing files).",
        ),
    ] = False,
    quiet: Annotated[bool, typer.Option("--quiet", help=QUIET_HELP)] = False,
) -> None:
    """Summarise charts: layers, depth range, extent, charted channels; with --draught, the
    navigable water.

    \b
    Example:
      colregs9 chart fixtures/charts/noaa_enc_US5MD1MC.000 --draught 5
    """
    from .jobs.chartinfo import summarise_chart

    with _user_errors():
        summary = summarise_chart(
            charts,
            draught_m=draught,
            ukc_m=ukc,
            out=_out_file(out),
            quiet=quiet,
            accept_gaps=accept_chart_gaps,
        )
    typer.echo(summary.text, nl=False)
    if summary.written and not quiet:
        typer.echo(summary.written, err=True)


@app.command("demo", cls=_Command)
def demo_command(
    out: Annotated[
        Path | None,
        typer.Option("--out", metavar="DIR", help="Output directory. Default: reports/demo/."),
    ] = None,
    scenarios: Annotated[
        Path | None,
        typer.Option(
            "--scenarios",
            metavar="DIR",
            help="Directory with greenhopper_restricted.toml and greenhopper_not_restricted.toml."
            " Default: the package's own (colregs9_cli/data/demo).",
        ),
    ] = None,
    chart: Annotated[
        Path | None,
        typer.Option(
            "--chart",
            metavar="CHART",
            help=f"Chart for the replay: {CHART_FORMATS}. Default: the modelled chart.",
        ),
    ] = None,
    query: Annotated[
        Path | None,
        typer.Option(
            "--query",
            metavar="FILE",
            help="Query TOML with the paper's parameters. Default: the package's greenhopper.toml.",
        ),
    ] = None,
    domains: Annotated[
        str,
        typer.Option(
            "--domains",
            metavar="all|restricted|none",
            help="Ship-domain ellipses in each replay's report.gpkg: all (as the paper's "
            "figures draw them, red and blue), restricted or none (see replay --domains).",
        ),
    ] = "all",
    overwrite: Annotated[bool, typer.Option("--overwrite", help=OVERWRITE_HELP)] = False,
    quiet: Annotated[bool, typer.Option("--quiet", help=QUIET_HELP)] = False,
) -> None:
    """The paper's Greenhopper case study: simulate and replay both scenarios, print the verdicts.

    Runs from any directory: the scenarios, the modelled chart and the query are package data.
    Writes to --out, for each scenario, the AIS (simulate-<scenario>.csv), the replay's report
    (<scenario>/) and its figure (<scenario>.png), and run.json. Exit code 3 if a scenario
    gives own ship no triggered encounter.

    \b
    Example:
      colregs9 demo --out reports/demo
    """
    from .jobs.demo import DEFAULT_CHART, DEFAULT_QUERY, DEFAULT_SCENARIOS_DIR, run_demo

    with _user_errors():
        result = run_demo(
            out,
            quiet=quiet,
            scenarios_dir=scenarios or DEFAULT_SCENARIOS_DIR,
            chart=chart or DEFAULT_CHART,
            query=query or DEFAULT_QUERY,
            overwrite=overwrite,
            domains=domains,
        )
    typer.echo(result.text, nl=False)


def run() -> None:
    """The ``colregs9`` console script: the app, then a quick exit (see ``quick_exit``).

    Only here: the SIGTERM handler, the collector's thresholds and ``os._exit`` are the
    console script's. ``app`` itself (``CliRunner``, an embedding program) and the library
    leave the process as they find it."""
    from .quick_exit import run_and_exit

    run_and_exit(app)
