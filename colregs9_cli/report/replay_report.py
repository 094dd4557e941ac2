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
from datetime import datetime
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TypeVar

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..core.replay_results import EncounterOutcome, PairOutcome, ReplayResult
from ..core.rows import (
    ENCOUNTER_COLUMNS,
    PAIR_COLUMNS,
    EncounterSummary,
    PairSummary,
    situation_or_interaction,
)
from ..outputs import report_directory, save_figure, write_csv, write_json, write_text
from ..timebase import DISPLAY_TIME_FORMAT
from .chart_plot import (
    DEPTH_LABEL,
    NOT_CHARTED_LABEL,
    TRACK_ZORDER,
    Bounds,
    draw_assessment,
    draw_chart,
    geographic_axes,
    show_view,
)
from .html_page import HTML_NAME
from .html_report import replay_html
from .replay_geopackage import GEOPACKAGE_NAME, encounter_layers, write_replay_geopackage

if TYPE_CHECKING:
    from ..charts.water import Chart
    from ..geo import LocalFrame
    from ..progress import ProgressSink

ENCOUNTERS_NAME = "encounters.csv"
PAIRS_NAME = "pairs.csv"
ENCOUNTER_DIR = "encounters"
INDEX_NAME = "index.md"
MANIFEST_NAME = "run.json"

# The paper marks own ship at TCPA with a red dot and the target with a black one. Own ship's
# track is dark orange so that it does not hide the red (restricted) ellipses.
OWN_DOT_COLOUR = "tab:red"
OWN_TRACK_COLOUR = "darkorange"
TARGET_COLOUR = "black"
# Markers above everything (the tracks are above the ellipses: chart_plot's order).
MARKER_ZORDER = 6.0
# Direction-of-travel arrows at these fractions of each track's length.
ARROW_FRACTIONS = (0.2, 0.5, 0.8)
# The smallest view: half a side of 200 m, so that a short encounter still shows its setting.
ZOOM_MIN_HALF_WIDTH_M = 200.0
# At most this many clear (or grey) ellipse outlines per arc, so that they stay apart.
OUTLINES_PER_ARC = 24
# Under the legend when a vessel's label has a dimension marked with ``*``.
DEFAULTED_NOTE = "* dimension not in AIS: a default was used"


def _cell(value: Any) -> Any:
    """A summary value as a CSV/Markdown cell: enums by value, times in ISO 8601."""
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, datetime | pd.Timestamp):
        return value.isoformat()
    return value


# The navigational status codes of pairs.csv and encounters.csv.
NAV_STATUS_COLUMNS = frozenset(
    {"nav_status_a", "nav_status_b", "own_nav_status", "target_nav_status"}
)


def _summary_table(summaries: list[Any], columns: tuple[str, ...]) -> pd.DataFrame:
    records = [
        {name: _cell(value) for name, value in dataclasses.asdict(summary).items()}
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
                "" if s.deciding_rule is None else _cell(s.deciding_rule),
                _number(s.cpa_m, 1),  # 149.8, not the 150 m threshold
                _number(s.tcpa_s, 0),
                _number(s.actual_min_separation_m, 1),
                "" if s.give_way_vessel_acted is None else _cell(s.give_way_vessel_acted),
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


def _verdict(outcome: EncounterOutcome) -> str:
    s = outcome.summary
    if s.situation is None:
        return (
            f"{s.interaction.value}, not a COLREGs encounter: {s.interaction_basis}"
            f"\nCPA {s.cpa_m:.0f} m in {s.tcpa_s:.0f} s"
        )
    rule9 = "rule 9 applied" if s.rule9_applied else "rule 9 not applied"
    ambiguous = ", ambiguous" if s.situation_ambiguous else ""
    return (
        f"{_cell(s.situation)}{ambiguous}: own ship {_cell(s.own_role_colregs)} → "
        f"{_cell(s.own_role_final)} ({rule9}, {s.automaton_path}; rule {_cell(s.deciding_rule)})"
        f"\ntarget restricted: {_cell(s.target_estimated_restricted)}, "
        f"CPA {s.cpa_m:.0f} m in {s.tcpa_s:.0f} s"
    )


def _view_box(outcome: EncounterOutcome) -> Bounds:
    """A square around the tracks, the positions at TCPA and the arcs, not the whole chart."""
    east = np.concatenate(
        [
            outcome.own_track["east_m"].to_numpy(),
            outcome.target_track["east_m"].to_numpy(),
            [outcome.own_at_tcpa_m[1], outcome.target_at_tcpa_m[1]],
            outcome.assessment.east_m if outcome.in_run_frame else [],
        ]
    )
    north = np.concatenate(
        [
            outcome.own_track["north_m"].to_numpy(),
            outcome.target_track["north_m"].to_numpy(),
            [outcome.own_at_tcpa_m[0], outcome.target_at_tcpa_m[0]],
            outcome.assessment.north_m if outcome.in_run_frame else [],
        ]
    )
    centre_east = (np.nanmin(east) + np.nanmax(east)) / 2.0
    centre_north = (np.nanmin(north) + np.nanmax(north)) / 2.0
    half = max(np.nanmax(east) - np.nanmin(east), np.nanmax(north) - np.nanmin(north)) * 0.6
    half = max(half, ZOOM_MIN_HALF_WIDTH_M)
    return (
        float(centre_east - half),
        float(centre_north - half),
        float(centre_east + half),
        float(centre_north + half),
    )


def trigger_positions_m(outcome: EncounterOutcome) -> tuple[tuple[float, float], ...]:
    """Own ship's and the target's (north, east) at the trigger, in the outcome's frame."""
    return outcome.own_at_trigger_m, outcome.target_at_trigger_m


def direction_arrows(
    track: pd.DataFrame, fractions: tuple[float, ...] = ARROW_FRACTIONS
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Arrow positions (east, north) along a track and unit directions (east, north) of travel.

    Each direction is the chord over 4 % of the track's length around the point, so that the
    jitter between AIS positions does not turn an arrow. Empty when the track does not move.
    """
    east = track["east_m"].to_numpy(dtype=float)
    north = track["north_m"].to_numpy(dtype=float)
    keep = np.isfinite(east) & np.isfinite(north)
    east, north = east[keep], north[keep]
    along_m = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(east), np.diff(north)))])
    empty = np.empty(0)
    if len(along_m) < 2 or along_m[-1] <= 0.0:
        return empty, empty, empty, empty
    at_m = np.asarray(fractions) * along_m[-1]
    half_chord_m = 0.02 * along_m[-1]
    behind_m, ahead_m = at_m - half_chord_m, at_m + half_chord_m
    d_east = np.interp(ahead_m, along_m, east) - np.interp(behind_m, along_m, east)
    d_north = np.interp(ahead_m, along_m, north) - np.interp(behind_m, along_m, north)
    length_m = np.hypot(d_east, d_north)
    moved = length_m > 0.0
    return (
        np.interp(at_m, along_m, east)[moved],
        np.interp(at_m, along_m, north)[moved],
        d_east[moved] / length_m[moved],
        d_north[moved] / length_m[moved],
    )


def _draw_track(
    ax: Any, track: pd.DataFrame, colour: str, linestyle: str, name: str, gid: str
) -> None:
    """A vessel's track over the encounter with small arrows (``gid``) for its direction."""
    ax.plot(
        track["east_m"],
        track["north_m"],
        color=colour,
        linewidth=1.4,
        linestyle=linestyle,
        zorder=TRACK_ZORDER,
        label=name,
        gid=gid.replace("direction", "track"),
    )
    east, north, unit_east, unit_north = direction_arrows(track)
    if len(east):
        arrows = ax.quiver(
            east,
            north,
            unit_east,
            unit_north,
            color=colour,
            angles="xy",
            scale_units="inches",
            scale=4.0,  # 0.25 in long, whatever the zoom
            width=0.006,
            headwidth=4.0,
            headlength=4.5,
            headaxislength=4.0,
            pivot="mid",
            zorder=TRACK_ZORDER + 0.1,
        )
        arrows.set_gid(gid)


def _draw_positions(
    ax: Any,
    name: str,
    at_trigger_m: tuple[float, float],
    at_tcpa_m: tuple[float, float],
    dot_colour: str,
    marker_colour: str,
) -> None:
    """The position at the trigger (hollow), the predicted one at TCPA (dot), and between them
    the constant-velocity prediction (dotted)."""
    (trigger_north, trigger_east), (tcpa_north, tcpa_east) = at_trigger_m, at_tcpa_m
    ax.plot(
        [trigger_east, tcpa_east],
        [trigger_north, tcpa_north],
        ":",
        color=dot_colour,
        linewidth=1.0,
        zorder=MARKER_ZORDER - 0.1,
        label=f"_{name} prediction",
    )
    ax.plot(
        trigger_east,
        trigger_north,
        "s",
        markersize=9,
        markerfacecolor="none",
        markeredgecolor=marker_colour,
        markeredgewidth=2.0,
        zorder=MARKER_ZORDER,
        label=f"{name} at trigger",
    )
    ax.plot(
        tcpa_east,
        tcpa_north,
        "o",
        color=dot_colour,
        markersize=7,
        zorder=MARKER_ZORDER,
        label=f"{name} at TCPA",
    )


def _legend_below(figure: Figure, ax: Any) -> None:
    """A compact legend under the axes, so that it covers nothing: own ship, then the arcs
    and the chart, in one column; the target, then the ellipses, in the other, and what
    ``*`` means when a vessel's label has one."""
    handles, labels = ax.get_legend_handles_labels()
    entries = list(zip(handles, labels, strict=True))
    own = [e for e in entries if e[1].startswith("own ship")]
    target = [e for e in entries if e[1].startswith("target")]
    chart = [
        e
        for e in entries
        if e[1].endswith("arc") or e[1].startswith("navigable") or e[1] == NOT_CHARTED_LABEL
    ]
    ellipses = [e for e in entries if " ellipses" in e[1]]
    blank = (Line2D([], [], linestyle="none"), "")
    defaulted = any("*" in label for _, label in own + target)
    columns = [own + chart, target + ellipses + ([(blank[0], DEFAULTED_NOTE)] if defaulted else [])]
    rows = max(len(c) for c in columns)
    # matplotlib fills a legend column by column: pad each to the same height.
    padded = [entry for c in columns for entry in c + [blank] * (rows - len(c))]
    figure.legend(
        [h for h, _ in padded],
        [label for _, label in padded],
        loc="outside lower center",
        ncols=2,
        fontsize="small",
        frameon=False,
    )


def _vessel_label(role: str, name: str | None, mmsi: int, dims: tuple[Any, ...]) -> str:
    """``own ship NAME (MMSI), 50 × 9 m, T 3.2* m`` with ``*`` on the dimensions defaulted
    (``dims`` ends with ``VesselDimensions.defaulted_text``, e.g. ``breadth;draught``)."""
    length_m, breadth_m, draught_m, defaulted = dims
    marked = set(str(defaulted or "").split(";"))

    def value(dimension: str, metres: float) -> str:
        return f"{metres:.3g}{'*' if dimension in marked else ''}"

    who = f"{name} ({mmsi})" if name else str(mmsi)
    return (
        f"{role} {who}, {value('length', length_m)} × {value('breadth', breadth_m)} m, "
        f"T {value('draught', draught_m)} m"
    )


def _mark_data_end(ax: Any, track: pd.DataFrame, colour: str, role: str, early: bool) -> None:
    """An × at a track's last position: where the series stops before the pass (``early``:
    the data stop, or the window of TCPA + ``tcpa_act_s`` ends while the pair still closes),
    else where the figure's series ends."""
    east = track["east_m"].to_numpy(dtype=float)
    north = track["north_m"].to_numpy(dtype=float)
    known = np.isfinite(east) & np.isfinite(north)
    if known.any():
        last = np.flatnonzero(known)[-1]
        ax.plot(
            east[last],
            north[last],
            "x",
            color=colour,
            markersize=10,
            markeredgewidth=2.0,
            zorder=MARKER_ZORDER,
            label=f"{role} series ends before the pass" if early else f"{role} end of track",
            gid=f"{role.replace(' ', '-')}-data-end",
        )


def encounter_figure(
    outcome: EncounterOutcome, chart: Chart | None, ukc_m: float, frame: LocalFrame
) -> Figure:
    """The paper's result figure for one encounter, in the run's local frame, with latitude
    and longitude on the axes and a scale bar (``chart_plot.geographic_axes``).

    The chart background (depth areas with a DRVAL1 colour bar, land, navigable water for the
    target's draught, and hatched grey where the chart does not reach) when a chart covers
    the run, cut to the view; both tracks over the encounter with arrows for the direction of
    travel (own ship dark orange, target black dashed) and an × at each one's end; both
    vessels at the trigger (hollow squares) and predicted at TCPA from the trigger (own ship
    red dot, target black dot); and the target's projected arcs with red (restricted) and blue
    (clear) ellipses at the trigger, light and under the tracks, every red one and at most
    ``OUTLINES_PER_ARC`` others per arc. The legend under the axes names both vessels with
    their dimensions (``*``: a default, not reported); the title gives the times of the
    trigger and of the predicted CPA.
    """
    s = outcome.summary
    figure = Figure(figsize=(8.5, 9.2), layout="constrained")
    ax = figure.subplots()
    view = _view_box(outcome)
    # The chart lives in the run's frame; a pair beyond its reach has a frame of its own.
    if not outcome.in_run_frame:
        chart, frame = None, outcome.frame
    if chart is not None:
        depths = draw_chart(ax, chart, s.target_draught_m, ukc_m, view=view)
        figure.colorbar(depths, ax=ax, label=DEPTH_LABEL, shrink=0.6, pad=0.02)
    else:
        show_view(ax, view)
    own_label = _vessel_label(
        "own ship",
        s.own_name,
        s.own_mmsi,
        (s.own_length_m, s.own_breadth_m, s.own_draught_m, s.own_dimensions_defaulted),
    )
    target_label = _vessel_label(
        "target",
        s.target_name,
        s.target_mmsi,
        (s.target_length_m, s.target_breadth_m, s.target_draught_m, s.target_dimensions_defaulted),
    )
    _draw_track(ax, outcome.own_track, OWN_TRACK_COLOUR, "-", own_label, "own-direction")
    _draw_track(ax, outcome.target_track, TARGET_COLOUR, "--", target_label, "target-direction")
    early = not s.data_covers_cpa
    _mark_data_end(ax, outcome.own_track, OWN_TRACK_COLOUR, "own ship", early)
    _mark_data_end(ax, outcome.target_track, TARGET_COLOUR, "target", early)
    if outcome.in_run_frame:
        steps_per_arc = int(outcome.assessment.step.max(initial=1))
        every = math.ceil(steps_per_arc / OUTLINES_PER_ARC)
        draw_assessment(ax, outcome.assessment, every=every)
    own_at_trigger_m, target_at_trigger_m = trigger_positions_m(outcome)
    _draw_positions(
        ax, "own ship", own_at_trigger_m, outcome.own_at_tcpa_m, OWN_DOT_COLOUR, OWN_TRACK_COLOUR
    )
    _draw_positions(
        ax, "target", target_at_trigger_m, outcome.target_at_tcpa_m, TARGET_COLOUR, TARGET_COLOUR
    )
    geographic_axes(ax, frame)
    _legend_below(figure, ax)
    at_cpa = s.trigger_utc + pd.Timedelta(seconds=s.tcpa_s)
    trigger = s.trigger_utc.strftime(DISPLAY_TIME_FORMAT)
    times = f"trigger {trigger} UTC, CPA predicted at {at_cpa:%H:%M:%S}"
    ax.set_title(f"{s.encounter_id}  ({times})\n{_verdict(outcome)}", fontsize="medium")
    return figure


def format_index(result: ReplayResult, plots: bool) -> str:
    """index.md: what each file holds, then a table of the triggered encounters (per seat)."""
    counts = result.counts
    untriggered = counts.encounters - counts.triggered
    lines = [
        f"# Replay: {result.query_name}",
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
        + (" and figure (PNG)." if plots else "."),
        f"- [{MANIFEST_NAME}]({MANIFEST_NAME}): inputs, parameters, rejects ledger and counts.",
        f"- [{HTML_NAME}]({HTML_NAME}): this report as a web page, with a map and a table "
        "to sort and filter.",
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
        acted = "" if s.give_way_vessel_acted is None else _cell(s.give_way_vessel_acted)
        lines.append(
            f"| {s.encounter_id} | {_cell(s.trigger_utc)} | {s.own_mmsi} | {s.target_mmsi} "
            f"| {situation_or_interaction(s)} | {'yes' if s.situation_ambiguous else ''} "
            f"| {_cell(s.own_role_colregs) or ''} | {_cell(s.target_estimated_restricted) or ''} "
            f"| {s.automaton_path or ''} | {_cell(s.deciding_rule) or ''} | {_give_way_text(s)} "
            f"| {_number(s.cpa_m, 0)} | {_number(s.actual_min_separation_m, 0)} | {acted} "
            f"| {links} |"
        )
    return "\n".join(lines) + "\n"


def draw_encounter(
    outcome: EncounterOutcome, target: Path, chart: Chart | None, ukc_m: float, frame: LocalFrame
) -> Path:
    """One encounter's figure, saved to ``target``."""
    save_figure(target, encounter_figure(outcome, chart, ukc_m, frame), dpi=120)
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
) -> tuple[Path, ...]:
    """Write every report file into ``result.out_dir``, which is replaced (no file of an
    earlier run stays; files colregs9 did not write stay: ``outputs.report_directory``, with
    ``overwrite``); returns the paths written. ``drawer`` draws the figures (here, or on the
    workers of a cluster: ``dask_run.dask_drawer``); ``parts``: where the encounters' series
    CSVs and map layers are made (default: here)."""
    parts = parts if parts is not None else EncountersHere(result.encounters)
    with report_directory(result.out_dir, overwrite) as staging:
        try:
            written = _write_replay_files(result, staging, chart, plots, progress, drawer, parts)
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
) -> tuple[Path, ...]:
    series_dir = out_dir / ENCOUNTER_DIR
    outcomes = result.encounters
    # The map layers first: the GeoPackage, written here, waits for them.
    layers = parts.map(functools.partial(encounter_layers, frame=result.frame)) if outcomes else []
    series_written = parts.map(functools.partial(write_series, series_dir=series_dir))
    files: list[Path] = []
    figures: list[tuple[EncounterOutcome, Path]] = []
    for outcome in outcomes:
        target = series_path(series_dir, outcome)
        files.append(target)
        if plots:
            png = target.with_suffix(".png")
            figures.append((outcome, png))
            files.append(png)
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
        page, replay_html(result, chart, plots, ENCOUNTER_DIR, [path.name for path in linked])
    )
    if geopackage is not None:
        write_replay_geopackage(geopackage, result, chart, [wait() for wait in layers])
        files.append(geopackage)
    for wait in series_written:
        written = wait()
        if not plots:
            progress.advance(written)
    return (pairs_csv, encounters_csv, *files, index, page, manifest)
