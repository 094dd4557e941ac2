"""The reports of ``colregs9 replay``: pairs.csv, encounters.csv, one CSV and PNG per
encounter (per seat), index.md and run.json.

Every file is written atomically. The verdicts and time series come from
``colregs9_cli.jobs.replay``; this module only lays them out and draws them.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

import numpy as np
import pandas as pd

from ..core.replay_results import EncounterOutcome, PairOutcome, ReplayResult
from ..core.rows import (
    ENCOUNTER_COLUMNS,
    PAIR_COLUMNS,
    EncounterSummary,
    PairSummary,
    situation_or_interaction,
)
from ..core.rule9 import RULES_APPLIED
from ..outputs import report_directory, save_figure, write_csv, write_json, write_text
from .dossier import motion_figure, timeline_markdown
from .encounter_figure import cell, encounter_figure, target_restricted_text, verdict_text
from .html_page import HTML_NAME
from .html_report import page_title, replay_html
from .replay_geopackage import (
    GEOPACKAGE_NAME,
    Domains,
    encounter_layers,
    write_replay_geopackage,
)

if TYPE_CHECKING:
    from ..charts.water import Chart
    from ..geo import LocalFrame
    from ..progress import ProgressSink

ENCOUNTERS_NAME = "encounters.csv"
PAIRS_NAME = "pairs.csv"
ENCOUNTER_DIR = "encounters"
INDEX_NAME = "index.md"
MANIFEST_NAME = "run.json"
MOTION_SUFFIX = "-motion.png"


# The navigational status codes of pairs.csv and encounters.csv.
NAV_STATUS_COLUMNS = frozenset(
    {"nav_status_a", "nav_status_b", "own_nav_status", "target_nav_status"}
)


def _summary_table(summaries: list[Any], columns: tuple[str, ...]) -> pd.DataFrame:
    records = [
        {name: cell(value) for name, value in dataclasses.asdict(summary).items()}
        for summary in summaries
    ]
    table = pd.DataFrame.from_records(records, columns=list(columns))
    # Codes, not measurements: 0 not 0.0, empty when the vessel never sent one.
    for name in columns:
        if name in NAV_STATUS_COLUMNS:
            table[name] = table[name].astype("Int64")
    return table


def encounters_frame(outcomes: tuple[EncounterOutcome, ...]) -> pd.DataFrame:
    """encounters.csv: one row per triggered encounter per seat, ``EncounterSummary``'s columns."""
    return _summary_table([o.summary for o in outcomes], ENCOUNTER_COLUMNS)


def pairs_frame(pairs: tuple[PairOutcome, ...]) -> pd.DataFrame:
    """pairs.csv: one row per triggered pair, ``PairSummary``'s columns."""
    return _summary_table([p.summary for p in pairs], PAIR_COLUMNS)


def _lowercase_booleans(frame: pd.DataFrame) -> pd.DataFrame:
    """Booleans as ``true``/``false`` (empty for none), as the three-valued restriction column."""
    result = frame.copy()
    for name in result.columns:
        values = result[name]
        if values.dtype == bool or (
            values.dtype == object
            and values.map(lambda v: v is None or isinstance(v, bool | np.bool_)).all()
            and values.notna().any()
        ):
            result[name] = values.map(lambda v: "" if v is None else str(bool(v)).lower())
    return result


def _number(value: float | None, decimals: int) -> str:
    return (
        ""
        if value is None or (isinstance(value, float) and math.isnan(value))
        else (f"{value:.{decimals}f}")
    )


SUMMARY_HEADER: tuple[str, ...] = (
    "pair",
    "situation",
    "ambiguous",
    "give-way (final)",
    "rule",
    "CPA m",
    "TCPA s",
    "min sep m",
    "give-way acted",
)


def format_summary(result: ReplayResult) -> str:
    """The short table printed to stdout: one line per triggered pair, then the counts."""
    counts = result.counts
    lines = [
        f"Replay '{result.query_name}': {counts.vessels} vessels, {counts.segments} segments, "
        f"{counts.candidate_pairs} candidate pairs, {counts.encounters} encounters, "
        f"{counts.triggered} triggered ({counts.triggered_pairs} pairs)."
    ]
    if result.pairs:
        lines.append(f"{result.interaction_summary}; only encounters get a verdict.")
    if not result.pairs:
        # No word of files: the API writes none, and the CLI says where its report went.
        lines.append(
            "No triggered encounters: no pair came within "
            f"CPA < {result.params.encounters.cpa_req_m:g} m with 0 <= TCPA <= "
            f"{result.params.encounters.tcpa_act_s:g} s."
        )
        return "\n".join(lines) + "\n"
    rows = [list(SUMMARY_HEADER)]
    for pair in result.pairs:
        s = pair.summary
        rows.append(
            [
                s.pair_id,
                situation_or_interaction(s),
                "yes" if s.situation_ambiguous else "",
                _give_way_text(s),
                "" if s.deciding_rule is None else cell(s.deciding_rule),
                _number(s.cpa_m, 1),  # 149.8, not the 150 m threshold
                _number(s.tcpa_s, 0),
                _number(s.actual_min_separation_m, 1),
                "" if s.give_way_vessel_acted is None else cell(s.give_way_vessel_acted),
            ]
        )
    widths = [max(len(str(row[i])) for row in rows) for i in range(len(SUMMARY_HEADER))]
    for row in rows:
        lines.append("  ".join(str(c).ljust(w) for c, w in zip(row, widths, strict=True)).rstrip())
    return "\n".join(lines) + "\n"


def _give_way_text(summary: PairSummary | EncounterSummary) -> str:
    """The final give-way vessels; empty for a pair that is not an encounter."""
    if summary.situation is None:
        return ""
    return summary.give_way_vessels or "none"


def format_index(result: ReplayResult, plots: bool) -> str:
    """index.md: what each file holds, then a table of the triggered encounters (per seat)."""
    counts = result.counts
    untriggered = counts.encounters - counts.triggered
    lines = [
        f"# {page_title(result)}",
        "",
        f"{RULES_APPLIED}",
        "",
        f"{counts.vessels} vessels; {counts.encounters} encounters (a pair within range of "
        f"each other, seen from each reported seat), {counts.triggered} of them triggered "
        f"(CPA < {result.params.encounters.cpa_req_m:g} m within 0 <= TCPA <= "
        f"{result.params.encounters.tcpa_act_s:g} s) in {counts.triggered_pairs} pairs; "
        f"{result.interaction_summary} (only encounters get a verdict).",
        "",
        f"- [{PAIRS_NAME}]({PAIRS_NAME}): one row per triggered pair, with the pair-level "
        "verdict (the same whichever vessel is own ship).",
        f"- [{ENCOUNTERS_NAME}]({ENCOUNTERS_NAME}): one row per triggered encounter per seat "
        f"({counts.triggered} rows). The {untriggered} encounters that never triggered are "
        "counted in run.json only.",
        f"- `{ENCOUNTER_DIR}/`: each triggered encounter's time series (CSV)"
        + (" and figures (PNG: its map, and its range and relative motion)." if plots else "."),
        f"- [{MANIFEST_NAME}]({MANIFEST_NAME}): inputs, parameters, rejects ledger and counts.",
        f"- [{HTML_NAME}]({HTML_NAME}): this report as a web page, with a map and a table "
        "to sort and filter.",
        *(
            [
                f"- [{GEOPACKAGE_NAME}]({GEOPACKAGE_NAME}): the encounters, their tracks, "
                "positions at TCPA and ship domains"
                + (", every vessel's track" if result.vessel_tracks.size else "")
                + " and, with a chart, the navigable water and the channels used, in WGS84 "
                "with QGIS styles."
            ]
            if result.encounters
            else []
        ),
        "",
    ]
    if not result.pairs:
        lines.append("No triggered encounters.")
        return "\n".join(lines) + "\n"
    lines += [
        "| encounter | trigger (UTC) | own | target | situation | ambiguous | own role "
        "| target restricted | path | rule | final give-way | CPA (m) | min sep (m) "
        "| give-way acted | files |",
        "|:--|:--|--:|--:|:--|:--|:--|:--|:--|:--|:--|--:|--:|:--|:--|",
    ]
    for outcome in result.encounters:
        s = outcome.summary
        links = f"[csv]({ENCOUNTER_DIR}/{s.encounter_id}.csv)"
        if plots:
            links += f" [png]({ENCOUNTER_DIR}/{s.encounter_id}.png)"
        acted = "" if s.give_way_vessel_acted is None else cell(s.give_way_vessel_acted)
        lines.append(
            f"| {s.encounter_id} | {cell(s.trigger_utc)} | {s.own_mmsi} | {s.target_mmsi} "
            f"| {situation_or_interaction(s)} | {'yes' if s.situation_ambiguous else ''} "
            f"| {cell(s.own_role_colregs) or ''} | {target_restricted_text(s)} "
            f"| {s.automaton_path or ''} | {cell(s.deciding_rule) or ''} | {_give_way_text(s)} "
            f"| {_number(s.cpa_m, 0)} | {_number(s.actual_min_separation_m, 0)} | {acted} "
            f"| {links} |"
        )
    for outcome in result.encounters:
        lines += ["", *_dossier_markdown(outcome, plots)]
    return "\n".join(lines) + "\n"


def _dossier_markdown(outcome: EncounterOutcome, plots: bool) -> list[str]:
    """An encounter's section of index.md: its verdict, figures and timeline."""
    s = outcome.summary
    verdict = [f"{line}  " for line in verdict_text(outcome).split("\n")]
    lines = [f"## {s.encounter_id}", "", *verdict]
    if plots:
        figure = f"{ENCOUNTER_DIR}/{s.encounter_id}"
        lines += [
            "",
            f"![map of {s.encounter_id}]({figure}.png)",
            "",
            f"![range and relative motion of {s.encounter_id}]({figure}{MOTION_SUFFIX})",
        ]
    return [*lines, "", *timeline_markdown(outcome)]


def motion_path(figure_path: Path) -> Path:
    """Where an encounter's range and relative-motion figure is saved, beside its map."""
    return figure_path.with_name(figure_path.stem + MOTION_SUFFIX)


def draw_encounter(
    outcome: EncounterOutcome, target: Path, chart: Chart | None, ukc_m: float, frame: LocalFrame
) -> Path:
    """One encounter's figures: its map saved to ``target``, its range and relative motion
    (``dossier.motion_figure``) to ``motion_path(target)``."""
    save_figure(target, encounter_figure(outcome, chart, ukc_m, frame), dpi=120)
    save_figure(motion_path(target), motion_figure(outcome), dpi=100)
    return target


FigureJobs = Sequence[tuple[EncounterOutcome, Path]]
# Draws the figures of ``FigureJobs`` (chart, UKC), advancing the progress sink once each.
Drawer = Callable[[FigureJobs, "Chart | None", float, "LocalFrame", "ProgressSink"], None]


def draw_here(
    jobs: FigureJobs,
    chart: Chart | None,
    ukc_m: float,
    frame: LocalFrame,
    progress: ProgressSink,
) -> None:
    """The figures drawn one after the other in this process."""
    for outcome, target in jobs:
        draw_encounter(outcome, target, chart, ukc_m, frame)
        progress.advance()


Part = TypeVar("Part")


class EncounterParts(Protocol):
    """The run's encounters in consecutive parts, each where it is: all of them here
    (``EncountersHere``), or a slab's on the worker that holds its result
    (``dask_run.EncountersOnCluster``), so that the per-encounter files are made there."""

    def map(
        self, function: Callable[[tuple[EncounterOutcome, ...]], Part]
    ) -> list[Callable[[], Part]]:
        """Start ``function`` on each part's encounters, in order; the returned callables
        wait for the parts' results."""

    def settle(self) -> None:
        """After a failure: return once no task started here writes any more (those not
        begun are dropped), so that the report's staging directory can go."""


@dataclasses.dataclass(frozen=True)
class EncountersHere:
    """All the encounters, as one part, in this process."""

    encounters: tuple[EncounterOutcome, ...]

    def map(
        self, function: Callable[[tuple[EncounterOutcome, ...]], Part]
    ) -> list[Callable[[], Part]]:
        result = function(self.encounters)
        return [lambda: result]

    def settle(self) -> None:
        """Nothing runs elsewhere."""


def series_path(series_dir: Path, outcome: EncounterOutcome) -> Path:
    """Where an encounter's time series is written (its figure: the same name, ``.png``)."""
    return series_dir / f"{outcome.summary.encounter_id}.csv"


def write_series(outcomes: tuple[EncounterOutcome, ...], series_dir: Path) -> int:
    """Each encounter's time series to its CSV in ``series_dir``; gives how many."""
    for outcome in outcomes:
        write_csv(series_path(series_dir, outcome), _lowercase_booleans(outcome.series))
    return len(outcomes)


def write_replay_reports(
    result: ReplayResult,
    chart: Chart | None,
    plots: bool,
    progress: ProgressSink,
    drawer: Drawer = draw_here,
    parts: EncounterParts | None = None,
    overwrite: bool = False,
    domains: Domains = Domains.RESTRICTED,
) -> tuple[Path, ...]:
    """Write every report file into ``result.out_dir``, which is replaced (no file of an
    earlier run stays; files colregs9 did not write stay: ``outputs.report_directory``, with
    ``overwrite``); returns the paths written. ``drawer`` draws the figures (here, or on the
    workers of a cluster: ``dask_run.dask_drawer``); ``parts``: where the encounters' series
    CSVs and map layers are made (default: here); ``domains``: which ship-domain ellipses
    report.gpkg holds."""
    parts = parts if parts is not None else EncountersHere(result.encounters)
    with report_directory(result.out_dir, overwrite) as staging:
        try:
            written = _write_replay_files(
                result, staging, chart, plots, progress, drawer, parts, domains
            )
        except BaseException:
            parts.settle()  # no late file in the staging directory once it is removed
            raise
    return tuple(result.out_dir / path.relative_to(staging) for path in written)


def _write_replay_files(
    result: ReplayResult,
    out_dir: Path,
    chart: Chart | None,
    plots: bool,
    progress: ProgressSink,
    drawer: Drawer,
    parts: EncounterParts,
    domains: Domains,
) -> tuple[Path, ...]:
    series_dir = out_dir / ENCOUNTER_DIR
    outcomes = result.encounters
    # The map layers first: the GeoPackage, written here, waits for them.
    layers = (
        parts.map(functools.partial(encounter_layers, frame=result.frame, domains=domains))
        if outcomes
        else []
    )
    series_written = parts.map(functools.partial(write_series, series_dir=series_dir))
    files: list[Path] = []
    figures: list[tuple[EncounterOutcome, Path]] = []
    for outcome in outcomes:
        target = series_path(series_dir, outcome)
        files.append(target)
        if plots:
            png = target.with_suffix(".png")
            figures.append((outcome, png))
            files += [png, motion_path(png)]
    if figures:
        drawer(figures, chart, result.params.manoeuvrability.ukc_m, result.frame, progress)
    # The tables and the page while the parts are made; the GeoPackage waits for them.
    encounters_csv = out_dir / ENCOUNTERS_NAME
    write_csv(encounters_csv, _lowercase_booleans(encounters_frame(outcomes)))
    pairs_csv = out_dir / PAIRS_NAME
    write_csv(pairs_csv, _lowercase_booleans(pairs_frame(result.pairs)))
    index = out_dir / INDEX_NAME
    write_text(index, format_index(result, plots))
    manifest = out_dir / MANIFEST_NAME
    write_json(manifest, result.manifest)
    geopackage = out_dir / GEOPACKAGE_NAME if outcomes else None
    # The page links only the files written (no report.gpkg without encounters).
    linked = [pairs_csv, encounters_csv, *([geopackage] if geopackage else []), index, manifest]
    page = out_dir / HTML_NAME
    write_text(
        page,
        replay_html(
            result, chart, plots, ENCOUNTER_DIR, [path.name for path in linked], MOTION_SUFFIX
        ),
    )
    if geopackage is not None:
        write_replay_geopackage(geopackage, result, chart, [wait() for wait in layers], domains)
        files.append(geopackage)
    for wait in series_written:
        written = wait()
        if not plots:
            progress.advance(written)
    return (pairs_csv, encounters_csv, *files, index, page, manifest)
