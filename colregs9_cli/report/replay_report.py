"""The reports of ``colregs9 replay``: encounters.csv, one CSV and PNG per encounter, index.md
and run.json.

Every file is written atomically. The verdicts and time series come from
``colregs9_cli.replay``; this module only lays them out and draws them.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from datetime import datetime
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from .atomic import save_figure, write_csv, write_json, write_text
from .chart_plot import draw_assessment, draw_chart

if TYPE_CHECKING:
    from ..chart import Chart
    from ..progress import ProgressSink
    from ..replay import EncounterOutcome, ReplayResult

ENCOUNTERS_NAME = "encounters.csv"
ENCOUNTER_DIR = "encounters"
INDEX_NAME = "index.md"
MANIFEST_NAME = "run.json"

OWN_COLOUR = "tab:red"
TARGET_COLOUR = "black"
# The smallest view: half a side of 200 m, so that a short encounter still shows its setting.
ZOOM_MIN_HALF_WIDTH_M = 200.0


def _cell(value: Any) -> Any:
    """A summary value as a CSV/Markdown cell: enums by value, times in ISO 8601."""
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, datetime | pd.Timestamp):
        return value.isoformat()
    return value


def encounters_frame(outcomes: tuple[EncounterOutcome, ...]) -> pd.DataFrame:
    """encounters.csv: one row per encounter, the columns of ``EncounterSummary`` in order."""
    from ..replay import ENCOUNTER_COLUMNS

    records = [
        {name: _cell(value) for name, value in dataclasses.asdict(o.summary).items()}
        for o in outcomes
    ]
    table = pd.DataFrame.from_records(records, columns=list(ENCOUNTER_COLUMNS))
    # A code, not a measurement: 0 not 0.0, empty when the target never sent one.
    table["target_nav_status"] = table["target_nav_status"].astype("Int64")
    return table


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


def _number(value: float, decimals: int) -> str:
    return (
        ""
        if value is None or (isinstance(value, float) and math.isnan(value))
        else (f"{value:.{decimals}f}")
    )


SUMMARY_HEADER: tuple[str, ...] = (
    "encounter",
    "situation",
    "own role",
    "target restricted",
    "path",
    "final role",
    "CPA m",
    "TCPA s",
    "min sep m",
)


def format_summary(result: ReplayResult) -> str:
    """The short table printed to stdout: one line per encounter, then the counts."""
    counts = result.counts
    lines = [
        f"Replay '{result.query_name}': {counts.vessels} vessels, {counts.segments} segments, "
        f"{counts.candidate_pairs} candidate pairs, {counts.encounters} encounters, "
        f"{counts.triggered} triggered."
    ]
    if not result.encounters:
        lines.append(
            "No triggered encounters: no pair came within "
            f"CPA < {result.params.replay.cpa_req_m:g} m with 0 <= TCPA <= "
            f"{result.params.replay.tcpa_act_s:g} s. encounters.csv has a header only."
        )
        return "\n".join(lines) + "\n"
    rows = [list(SUMMARY_HEADER)]
    for outcome in result.encounters:
        s = outcome.summary
        rows.append(
            [
                s.encounter_id,
                _cell(s.situation),
                _cell(s.own_role_colregs),
                _cell(s.target_estimated_restricted),
                s.automaton_path,
                _cell(s.own_role_final),
                _number(s.cpa_m, 0),
                _number(s.tcpa_s, 0),
                _number(s.actual_min_separation_m, 0),
            ]
        )
    widths = [max(len(str(row[i])) for row in rows) for i in range(len(SUMMARY_HEADER))]
    for row in rows:
        lines.append("  ".join(str(c).ljust(w) for c, w in zip(row, widths, strict=True)).rstrip())
    return "\n".join(lines) + "\n"


def _verdict(outcome: EncounterOutcome) -> str:
    s = outcome.summary
    rule9 = "rule 9 applied" if s.rule9_applied else "rule 9 not applied"
    return (
        f"{_cell(s.situation)}: own ship {_cell(s.own_role_colregs)} → "
        f"{_cell(s.own_role_final)} ({rule9}, {s.automaton_path})\ntarget restricted: "
        f"{_cell(s.target_estimated_restricted)}, CPA {s.cpa_m:.0f} m in {s.tcpa_s:.0f} s"
    )


def _zoom_to_encounter(ax: Any, outcome: EncounterOutcome) -> None:
    """Show the tracks, the positions at TCPA and the arcs, not the whole chart."""
    east = np.concatenate(
        [
            outcome.own_track["east_m"].to_numpy(),
            outcome.target_track["east_m"].to_numpy(),
            [outcome.own_at_tcpa_m[1], outcome.target_at_tcpa_m[1]],
            outcome.assessment.east_m,
        ]
    )
    north = np.concatenate(
        [
            outcome.own_track["north_m"].to_numpy(),
            outcome.target_track["north_m"].to_numpy(),
            [outcome.own_at_tcpa_m[0], outcome.target_at_tcpa_m[0]],
            outcome.assessment.north_m,
        ]
    )
    centre_east = (np.nanmin(east) + np.nanmax(east)) / 2.0
    centre_north = (np.nanmin(north) + np.nanmax(north)) / 2.0
    half = max(np.nanmax(east) - np.nanmin(east), np.nanmax(north) - np.nanmin(north)) * 0.6
    half = max(half, ZOOM_MIN_HALF_WIDTH_M)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlim(centre_east - half, centre_east + half)
    ax.set_ylim(centre_north - half, centre_north + half)


def encounter_figure(outcome: EncounterOutcome, chart: Chart | None, ukc_m: float) -> Figure:
    """The paper's result figure for one encounter, in the run's local frame (east, north).

    The chart background (depth areas, land, navigable water for the target's draught) when a
    chart covers the run, both tracks over the encounter, both vessels' predicted positions at
    TCPA from the trigger (own ship red, target black), and the target's projected arcs with
    red (restricted) and blue (clear) ellipses at the trigger.
    """
    s = outcome.summary
    figure, ax = plt.subplots(figsize=(8, 8), layout="constrained")
    if chart is not None:
        draw_chart(ax, chart, s.target_draught_m, ukc_m)
    ax.plot(
        outcome.own_track["east_m"],
        outcome.own_track["north_m"],
        color=OWN_COLOUR,
        linewidth=1.2,
        label=f"own ship {s.own_mmsi}",
    )
    ax.plot(
        outcome.target_track["east_m"],
        outcome.target_track["north_m"],
        color=TARGET_COLOUR,
        linewidth=1.2,
        linestyle="--",
        label=f"target {s.target_mmsi}",
    )
    draw_assessment(ax, outcome.assessment)
    own_north, own_east = outcome.own_at_tcpa_m
    target_north, target_east = outcome.target_at_tcpa_m
    ax.plot(own_east, own_north, "o", color=OWN_COLOUR, markersize=7, label="own ship at TCPA")
    ax.plot(
        target_east, target_north, "o", color=TARGET_COLOUR, markersize=7, label="target at TCPA"
    )
    _zoom_to_encounter(ax, outcome)
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.legend(loc="best", fontsize="small")
    ax.set_title(f"{s.encounter_id}\n{_verdict(outcome)}", fontsize="medium")
    return figure


def format_index(result: ReplayResult, plots: bool) -> str:
    """index.md: a table of all encounters linking to their CSV and PNG."""
    lines = [
        f"# Replay: {result.query_name}",
        "",
        f"{result.counts.encounters} encounters ({result.counts.triggered} triggered) among "
        f"{result.counts.vessels} vessels. All encounters: [{ENCOUNTERS_NAME}]({ENCOUNTERS_NAME})."
        f" Run manifest: [{MANIFEST_NAME}]({MANIFEST_NAME}).",
        "",
    ]
    if not result.encounters:
        lines.append("No triggered encounters.")
        return "\n".join(lines) + "\n"
    lines += [
        "| encounter | trigger (UTC) | own | target | situation | own role | target restricted "
        "| path | final role | CPA (m) | min sep (m) | give-way acted | files |",
        "|:--|:--|--:|--:|:--|:--|:--|:--|:--|--:|--:|:--|:--|",
    ]
    for outcome in result.encounters:
        s = outcome.summary
        links = f"[csv]({ENCOUNTER_DIR}/{s.encounter_id}.csv)"
        if plots:
            links += f" [png]({ENCOUNTER_DIR}/{s.encounter_id}.png)"
        acted = "" if s.give_way_vessel_acted is None else str(s.give_way_vessel_acted).lower()
        lines.append(
            f"| {s.encounter_id} | {_cell(s.trigger_utc)} | {s.own_mmsi} | {s.target_mmsi} "
            f"| {_cell(s.situation)} | {_cell(s.own_role_colregs)} "
            f"| {_cell(s.target_estimated_restricted)} | {s.automaton_path} "
            f"| {_cell(s.own_role_final)} | {_number(s.cpa_m, 0)} "
            f"| {_number(s.actual_min_separation_m, 0)} | {acted} | {links} |"
        )
    return "\n".join(lines) + "\n"


def jsonable(value: Any) -> Any:
    """Parameters and inputs (dataclasses, enums, paths, times, sets) as JSON values."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {
            f.name: jsonable(getattr(value, f.name)) for f in dataclasses.fields(value) if f.repr
        }
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, set | frozenset):
        return sorted((jsonable(v) for v in value), key=str)
    if isinstance(value, list | tuple):
        return [jsonable(v) for v in value]
    if isinstance(value, datetime | pd.Timestamp):
        return value.isoformat()
    if isinstance(value, float) and math.isnan(value):
        return None
    if value is None or isinstance(value, str | int | float | bool):
        return value
    if hasattr(value, "wkt"):
        return value.wkt
    if hasattr(value, "item"):  # numpy scalars
        return jsonable(value.item())
    return str(value)


def write_replay_reports(
    result: ReplayResult,
    chart: Chart | None,
    plots: bool,
    progress: ProgressSink,
) -> tuple[Path, ...]:
    """Write every report file into ``result.out_dir``; returns the paths written."""
    out_dir = result.out_dir
    series_dir = out_dir / ENCOUNTER_DIR
    files: list[Path] = []
    for outcome in result.encounters:
        target = series_dir / f"{outcome.summary.encounter_id}.csv"
        write_csv(target, _lowercase_booleans(outcome.series))
        files.append(target)
        if plots:
            figure = encounter_figure(outcome, chart, result.params.manoeuvrability.ukc_m)
            try:
                png = series_dir / f"{outcome.summary.encounter_id}.png"
                save_figure(png, figure, dpi=120)
                files.append(png)
            finally:
                plt.close(figure)
        progress.advance()
    encounters_csv = out_dir / ENCOUNTERS_NAME
    write_csv(encounters_csv, _lowercase_booleans(encounters_frame(result.encounters)))
    index = out_dir / INDEX_NAME
    write_text(index, format_index(result, plots))
    manifest = out_dir / MANIFEST_NAME
    write_json(manifest, result.manifest)
    return (encounters_csv, *files, index, manifest)
