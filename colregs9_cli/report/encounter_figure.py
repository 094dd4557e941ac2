"""An encounter's map: the paper's result figure, with the time along both tracks and the
least separation marked (docs/design.md §5, Reports). Drawn with matplotlib's object API
(no pyplot, no global backend).
"""

from __future__ import annotations

import math
from datetime import datetime
from enum import Enum
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..charts.channels import load_channels
from ..core.audit import Fact
from ..core.replay_results import EncounterOutcome
from ..core.rows import EncounterSummary
from ..timebase import DISPLAY_TIME_FORMAT
from .chart_plot import (
    CHANNEL_AXIS_LABEL,
    CHANNEL_LABEL,
    DEPTH_LABEL,
    NOT_CHARTED_LABEL,
    TRACK_ZORDER,
    Bounds,
    draw_assessment,
    draw_channels,
    draw_chart,
    geographic_axes,
    show_view,
)

if TYPE_CHECKING:
    from ..charts.water import Chart
    from ..geo import LocalFrame

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
# Time ticks along the tracks: the first interval that puts at most this many on a track.
TIME_TICKS_S = (30.0, 60.0, 120.0, 300.0, 600.0, 900.0, 1800.0, 3600.0)
MOST_TIME_TICKS = 10
LEAST_SEPARATION_COLOUR = "tab:red"
LEAST_SEPARATION_LABEL = "least separation"
# Under the legend when a vessel's label has a dimension marked with ``*``.
DEFAULTED_NOTE = "* dimension not in AIS: a default was used"
# The map's figure, whose height holds a legend of up to LEGEND_ROWS_FITTED rows; each row
# more adds LEGEND_ROW_IN inches (a line of small text and its spacing).
FIGURE_WIDTH_IN = 8.5
FIGURE_HEIGHT_IN = 9.2
LEGEND_ROWS_FITTED = 8
LEGEND_ROW_IN = 0.22


def cell(value: Any) -> Any:
    """A summary value as a CSV/Markdown cell: enums by value, times in ISO 8601."""
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, datetime | pd.Timestamp):
        return value.isoformat()
    return value


def target_restricted_text(s: EncounterSummary) -> str:
    """The estimator's verdict on the target, and that her draught confines her to the
    channel where it does: either is G_d's d3."""
    estimated = cell(s.target_estimated_restricted) or ""
    if s.target_confined_to_channel is not Fact.TRUE:
        return estimated
    return f"{estimated or 'not estimated'} by her arcs, confined to the channel by her draught"


def verdict_text(outcome: EncounterOutcome) -> str:
    """The verdict in two lines, as the figure's title and index.md give it."""
    s = outcome.summary
    if s.situation is None:
        return (
            f"{s.interaction.value}, not a COLREGs encounter: {s.interaction_basis}"
            f"\nCPA {s.cpa_m:.0f} m in {s.tcpa_s:.0f} s"
        )
    rule9 = "rule 9 applied" if s.rule9_applied else "rule 9 not applied"
    ambiguous = ", ambiguous" if s.situation_ambiguous else ""
    return (
        f"{cell(s.situation)}{ambiguous}: own ship {cell(s.own_role_colregs)} → "
        f"{cell(s.own_role_final)} ({rule9}, {s.automaton_path}; rule {cell(s.deciding_rule)})"
        f"\ntarget restricted: {target_restricted_text(s)}, "
        f"CPA {s.cpa_m:.0f} m in {s.tcpa_s:.0f} s"
    )


def _passing_part(track: pd.DataFrame, outcome: EncounterOutcome) -> pd.DataFrame:
    """The rows of a track from the trigger to the end of the passing (the series' span)."""
    times = pd.to_datetime(track["timestamp"], utc=True)
    series_times = pd.to_datetime(outcome.series["timestamp"], utc=True)
    return track[(times >= series_times.min()) & (times <= series_times.max())]


def _view_box(outcome: EncounterOutcome) -> Bounds:
    """A square around the passing: both tracks from the trigger to the pass, the positions
    predicted at TCPA and the arcs; not the whole chart, nor the whole candidate run (two
    yachts that passed at 55 m within an 8 km run are drawn at the scale of their pass). The
    tracks are drawn whole and cut by the view."""
    own, target = (
        _passing_part(outcome.own_track, outcome),
        _passing_part(outcome.target_track, outcome),
    )
    east = np.concatenate(
        [
            own["east_m"].to_numpy(),
            target["east_m"].to_numpy(),
            [outcome.own_at_tcpa_m[1], outcome.target_at_tcpa_m[1]],
            outcome.assessment.east_m if outcome.in_run_frame else [],
        ]
    )
    north = np.concatenate(
        [
            own["north_m"].to_numpy(),
            target["north_m"].to_numpy(),
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


def _tick_text(tick_s: float) -> str:
    return f"{tick_s:g} s" if tick_s < 60 else f"{tick_s / 60:g} min"


def time_tick_s(duration_s: float) -> float:
    """The interval between the time ticks along a track: the first of ``TIME_TICKS_S`` that
    puts at most ``MOST_TIME_TICKS`` on it."""
    for tick_s in TIME_TICKS_S:
        if duration_s / tick_s <= MOST_TIME_TICKS:
            return tick_s
    return TIME_TICKS_S[-1]


def time_ticks(track: pd.DataFrame, tick_s: float) -> pd.DataFrame:
    """The rows of ``track`` at whole multiples of ``tick_s`` of UTC (12:05:00, 12:06:00 …)."""
    utc = pd.to_datetime(track["timestamp"], utc=True)
    seconds = (utc - pd.Timestamp(0, tz="UTC")).dt.total_seconds().to_numpy()
    return track[np.isclose(np.mod(seconds, tick_s), 0.0)]


def _draw_time_ticks(ax: Any, track: pd.DataFrame, tick_s: float, colour: str) -> None:
    """Dots at whole times along a track, labelled with the time, for reading the two
    tracks against each other and against the timeline."""
    ticks = time_ticks(track, tick_s)
    # Only those in the view: a label outside it would still push the layout.
    (west, east), (south, north) = ax.get_xlim(), ax.get_ylim()
    ticks = ticks[ticks["east_m"].between(west, east) & ticks["north_m"].between(south, north)]
    ax.plot(
        ticks["east_m"], ticks["north_m"], "o", color=colour, ms=3.0, zorder=MARKER_ZORDER - 0.5
    )
    form = "%H:%M" if tick_s % 60 == 0 else "%H:%M:%S"
    for row in ticks.itertuples(index=False):
        label = ax.annotate(
            pd.Timestamp(row.timestamp).strftime(form),
            (row.east_m, row.north_m),
            xytext=(4, 2),
            textcoords="offset points",
            fontsize=6.5,
            color=colour,
            zorder=MARKER_ZORDER,
            annotation_clip=True,
            clip_on=True,
        )
        label.set_in_layout(False)  # a label at the edge must not move the title


def least_separation_positions(
    outcome: EncounterOutcome,
) -> tuple[tuple[float, float], tuple[float, float]] | None:
    """Own ship's and the target's (east, north) at the least separation; None without one."""
    at = outcome.summary.actual_min_separation_utc
    if at is None:
        return None
    positions = []
    for track in (outcome.own_track, outcome.target_track):
        rows = track[pd.to_datetime(track["timestamp"], utc=True) == at]
        if rows.empty:
            return None
        positions.append((float(rows["east_m"].iloc[0]), float(rows["north_m"].iloc[0])))
    return positions[0], positions[1]


def _mark_least_separation(ax: Any, outcome: EncounterOutcome) -> None:
    positions = least_separation_positions(outcome)
    s = outcome.summary
    if positions is None or s.actual_min_separation_m is None:
        return
    (own_east, own_north), (target_east, target_north) = positions
    at = pd.Timestamp(s.actual_min_separation_utc).strftime("%H:%M:%S")
    ax.plot(
        [own_east, target_east],
        [own_north, target_north],
        color=LEAST_SEPARATION_COLOUR,
        marker="D",
        ms=5.0,
        lw=1.2,
        zorder=MARKER_ZORDER,
        label=f"{LEAST_SEPARATION_LABEL} {s.actual_min_separation_m:.0f} m at {at}",
    )


def _legend_below(figure: Figure, ax: Any) -> None:
    """A compact legend under the axes, so that it covers nothing: own ship, then the arcs
    and the chart, in one column; the target, then the ellipses, in the other, and what
    ``*`` means when a vessel's label has one. The figure grows by the rows past
    ``LEGEND_ROWS_FITTED``, so that a long legend does not squeeze the map and its title
    out of the figure."""
    handles, labels = ax.get_legend_handles_labels()
    entries = list(zip(handles, labels, strict=True))
    own = [
        e for e in entries if e[1].startswith(("own ship", LEAST_SEPARATION_LABEL, "time ticks"))
    ]
    target = [e for e in entries if e[1].startswith("target")]
    chart = [
        e
        for e in entries
        if e[1].endswith("arc")
        or e[1].startswith("navigable")
        or e[1] in (NOT_CHARTED_LABEL, CHANNEL_LABEL, CHANNEL_AXIS_LABEL)
    ]
    ellipses = [e for e in entries if " ellipses" in e[1]]
    blank = (Line2D([], [], linestyle="none"), "")
    defaulted = any("*" in label for _, label in own + target)
    columns = [own + chart, target + ellipses + ([(blank[0], DEFAULTED_NOTE)] if defaulted else [])]
    rows = max(len(c) for c in columns)
    # matplotlib fills a legend column by column: pad each to the same height.
    padded = [entry for c in columns for entry in c + [blank] * (rows - len(c))]
    extra_rows = max(0, rows - LEGEND_ROWS_FITTED)
    figure.set_figheight(FIGURE_HEIGHT_IN + extra_rows * LEGEND_ROW_IN)
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
    figure = Figure(figsize=(FIGURE_WIDTH_IN, FIGURE_HEIGHT_IN), layout="constrained")
    ax = figure.subplots()
    view = _view_box(outcome)
    # The chart lives in the run's frame; a pair beyond its reach has a frame of its own.
    if not outcome.in_run_frame:
        chart, frame = None, outcome.frame
    if chart is not None:
        depths = draw_chart(ax, chart, s.target_draught_m, ukc_m, view=view)
        figure.colorbar(depths, ax=ax, label=DEPTH_LABEL, shrink=0.6, pad=0.02)
        named = [
            getattr(s, f"{who}_{name}")
            for who in ("own", "target")
            for name in ("channel", "channel_at_min_separation")
        ]
        draw_channels(ax, load_channels(chart), view, [n for n in named if n])
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
    times = outcome.own_track["timestamp"]
    tick_s = time_tick_s((times.max() - times.min()).total_seconds())
    _draw_time_ticks(ax, outcome.own_track, tick_s, OWN_TRACK_COLOUR)
    _draw_time_ticks(ax, outcome.target_track, tick_s, TARGET_COLOUR)
    ax.plot([], [], "o", color="grey", ms=3.0, label=f"time ticks every {_tick_text(tick_s)} (UTC)")
    _mark_least_separation(ax, outcome)
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
    ax.set_title(f"{s.encounter_id}  ({times})\n{verdict_text(outcome)}", fontsize="medium")
    return figure
