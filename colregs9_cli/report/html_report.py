"""The replay's ``index.html`` (made of html_page.py's page and tables).

The page needs no network: the overview map is an inline SVG drawn by matplotlib from the
data and the chart (no tiles), the per-encounter figures are the PNG files beside it. The
map numbers the pairs as the table's ``pair`` column does; a number on the map links to
``#pair-N``, which filters the table to that pair.
"""

from __future__ import annotations

import html
import io
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..core.colregs import Role
from ..core.replay_results import EncounterOutcome, ReplayResult
from ..core.rows import EncounterSummary, situation_or_interaction
from ..core.rule9 import RULES_APPLIED
from ..timebase import DISPLAY_TIME_FORMAT
from .chart_plot import Bounds, draw_chart, geographic_axes, show_view
from .dossier import timeline_html
from .html_page import cell_text, file_links, page, sortable_table

if TYPE_CHECKING:
    from ..charts.water import Chart

# Key columns first, so that the table fits a desktop window (1400 px); the others are
# shown by the "more columns" box (the encounter's section lists every fact anyway).
KEY_COLUMNS = (
    "encounter",
    "pair",
    "trigger (UTC)",
    "situation",
    "give-way",
    "min sep (m)",
    "give-way acted",
    "deciding rule",
)
MORE_COLUMNS = (
    "own",
    "target",
    "own role (final)",
    "target role (final)",
    "rule 9",
    "CPA (m)",
    "data covers CPA",
)
ENCOUNTER_TABLE_COLUMNS = KEY_COLUMNS + MORE_COLUMNS
# The table's columns offered as selects.
_SELECTS = tuple(
    ENCOUNTER_TABLE_COLUMNS.index(name)
    for name in (
        "pair",
        "situation",
        "give-way acted",
        "deciding rule",
        "rule 9",
        "data covers CPA",
    )
)


def _vessel(name: str | None, mmsi: int) -> str:
    return f"{name} ({mmsi})" if name else str(mmsi)


def pair_numbers(result: ReplayResult) -> dict[str, int]:
    """Each triggered pair's number on the map and in the table: 1, 2, … in pairs.csv's
    order."""
    return {pair.summary.pair_id: number for number, pair in enumerate(result.pairs, start=1)}


def _give_way(summary: EncounterSummary) -> str:
    """The vessel(s) that keep out of the way at the end (final roles): blank without a
    verdict, ``none`` when neither does."""
    own, target = summary.own_role_final, summary.target_role_final
    if own is None and target is None:
        return ""
    vessels = [
        _vessel(name, mmsi)
        for role, name, mmsi in (
            (own, summary.own_name, summary.own_mmsi),
            (target, summary.target_name, summary.target_mmsi),
        )
        if role is Role.GIVE_WAY
    ]
    return ", ".join(vessels) if vessels else "none"


def _encounter_row(outcome: EncounterOutcome, numbers: Mapping[str, int]) -> list[Any]:
    """The table's row, in ``ENCOUNTER_TABLE_COLUMNS``' order."""
    s = outcome.summary
    return [
        s.encounter_id,
        numbers[s.pair_id],
        s.trigger_utc,
        situation_or_interaction(s),
        _give_way(s),
        s.actual_min_separation_m,
        s.give_way_vessel_acted,
        "" if s.deciding_rule is None else f"rule {cell_text(s.deciding_rule)}",
        _vessel(s.own_name, s.own_mmsi),
        _vessel(s.target_name, s.target_mmsi),
        cell_text(s.own_role_final),
        cell_text(s.target_role_final),
        "" if s.rule9_applied is None else "applied" if s.rule9_applied else "not applied",
        s.cpa_m,
        s.data_covers_cpa,
    ]


def _facts(outcome: EncounterOutcome) -> list[str]:
    fields = outcome.summary.__dataclass_fields__
    lines = ['<dl class="facts">']
    for name in fields:
        value = getattr(outcome.summary, name)
        # Positions to 1e-6° (0.1 m), as in encounters.csv's audit trail, not to table width.
        position = "lat_deg" in name or "lon_deg" in name
        if position and isinstance(value, float | np.floating) and not np.isnan(value):
            text = f"{value:.6f}"
        else:
            text = cell_text(value)
        lines.append(f"<dt>{html.escape(name)}</dt><dd>{html.escape(text)}</dd>")
    lines.append("</dl>")
    return lines


# The overview map's margin around the trigger positions: a share of their spread, at least
# a few hundred metres, so that the setting of a lone pair shows.
MAP_MARGIN_SHARE = 0.1
MAP_MIN_MARGIN_M = 500.0
MAP_MIN_MARGIN_DEG = 0.01
SITUATION_COLOURS = {"crossing": "tab:blue", "head-on": "tab:red", "overtaking": "tab:green"}
# The map is 8 in high and as wide as its view needs (5 to 12 in), with these margins
# (inches: left for the latitudes, right, bottom for the longitudes, top for the title),
# so that a metre is the same number of points on the map however the view is shaped.
MAP_HEIGHT_IN = 8.0
MAP_MARGINS_IN = (1.1, 0.2, 0.9, 0.6)
LABEL_POINTS = 7.0
# Where a label may go: rings (points from its pair's position), 8 directions on each.
LABEL_RADII_PT = (7.0, 14.0, 22.0, 32.0, 44.0, 58.0)


def _map_view(east: np.ndarray, north: np.ndarray, least_margin: float) -> Bounds:
    margin = max(MAP_MARGIN_SHARE * max(np.ptp(east), np.ptp(north)), least_margin)
    return (
        float(east.min() - margin),
        float(north.min() - margin),
        float(east.max() + margin),
        float(north.max() + margin),
    )


def place_labels(
    anchors_pt: np.ndarray, widths_pt: Sequence[float], obstacles_pt: np.ndarray
) -> np.ndarray:
    """Offsets (points) of labels centred near their anchors: for each label in turn, the
    nearest candidate whose box overlaps no label placed before it and no plotted point
    (``obstacles_pt``), so that a cluster of pairs gets numbers that can be read (joined
    to their pairs by leader lines); the farthest candidate when none is free."""
    height = LABEL_POINTS + 1.0
    angles = np.deg2rad(np.arange(45.0, 405.0, 45.0))
    candidates = [(r * np.cos(a), r * np.sin(a)) for r in LABEL_RADII_PT for a in angles]
    placed = np.empty((0, 4))
    offsets = np.zeros((len(anchors_pt), 2))
    for i, ((x, y), width) in enumerate(zip(anchors_pt, widths_pt, strict=True)):
        for dx, dy in candidates:
            centre_x, centre_y = x + dx, y + dy
            box = np.array(
                [
                    centre_x - width / 2,
                    centre_y - height / 2,
                    centre_x + width / 2,
                    centre_y + height / 2,
                ]
            )
            overlaps = (
                (placed[:, 0] < box[2])
                & (box[0] < placed[:, 2])
                & (placed[:, 1] < box[3])
                & (box[1] < placed[:, 3])
            )
            covers = (
                (obstacles_pt[:, 0] > box[0] - 2)
                & (obstacles_pt[:, 0] < box[2] + 2)
                & (obstacles_pt[:, 1] > box[1] - 2)
                & (obstacles_pt[:, 1] < box[3] + 2)
            )
            if not overlaps.any() and not covers.any():
                break
        placed = np.vstack([placed, box])
        offsets[i] = (dx, dy)
    return offsets


def overview_figure(result: ReplayResult, chart: Chart | None) -> Figure:
    """The triggered pairs (at least one) on one map, with latitude and longitude on the
    axes and the chart under them when there is one (cut to the view): each pair's two
    positions at the trigger, joined, coloured by situation, and numbered as in the table's
    ``pair`` column (``place_labels``); each number links to ``#pair-N``."""
    frame = result.frame
    numbers = pair_numbers(result)
    lat_lon = [
        (
            np.array([p.summary.lat_deg_at_trigger_a, p.summary.lat_deg_at_trigger_b]),
            np.array([p.summary.lon_deg_at_trigger_a, p.summary.lon_deg_at_trigger_b]),
        )
        for p in result.pairs
    ]
    # Pairs spread beyond the run frame's reach (a satellite feed) are mapped in degrees,
    # longitude against latitude, without the chart.
    in_frame = all(frame.within_reach(lat, lon).all() for lat, lon in lat_lon)
    positions = [frame.to_local(lat, lon) if in_frame else (lat, lon) for lat, lon in lat_lon]
    if not in_frame:
        chart = None
    north = np.concatenate([n for n, _ in positions])
    east = np.concatenate([e for _, e in positions])
    view = _map_view(east, north, MAP_MIN_MARGIN_M if in_frame else MAP_MIN_MARGIN_DEG)
    left, right, bottom, top = MAP_MARGINS_IN
    map_height_in = MAP_HEIGHT_IN - bottom - top
    view_width_m, view_height_m = view[2] - view[0], view[3] - view[1]
    width_in = float(np.clip(map_height_in * view_width_m / view_height_m + left + right, 5, 12))
    figure = Figure(figsize=(width_in, MAP_HEIGHT_IN))
    ax = figure.subplots()
    figure.subplots_adjust(
        left=left / width_in,
        right=1 - right / width_in,
        bottom=bottom / MAP_HEIGHT_IN,
        top=1 - top / MAP_HEIGHT_IN,
    )
    if chart is not None:
        draw_chart(ax, chart, None, view=view)
    else:
        show_view(ax, view)
    # Points per metre on the map (an equal-aspect box fits the view in the margins).
    scale = min((width_in - left - right) * 72 / view_width_m, map_height_in * 72 / view_height_m)
    texts = [str(numbers[p.summary.pair_id]) for p in result.pairs]
    anchors = np.array([(e[0], n[0]) for n, e in positions])
    offsets = place_labels(
        anchors * scale,
        [0.62 * LABEL_POINTS * len(t) + 2 for t in texts],
        np.column_stack([east, north]) * scale,
    )
    seen: set[str] = set()
    for pair, (pair_north, pair_east), text, anchor, offset in zip(
        result.pairs, positions, texts, anchors, offsets, strict=True
    ):
        situation = situation_or_interaction(pair.summary)
        ax.plot(
            pair_east,
            pair_north,
            "o-",
            color=SITUATION_COLOURS.get(situation, "0.3"),
            markersize=4,
            label=None if situation in seen else situation,
        )
        seen.add(situation)
        label = ax.annotate(
            text,
            tuple(anchor),
            xytext=tuple(offset),
            textcoords="offset points",
            fontsize=LABEL_POINTS,
            ha="center",
            va="center",
            arrowprops={"arrowstyle": "-", "color": "0.3", "linewidth": 0.4, "shrinkB": 2},
        )
        label.set_url(f"#pair-{text}")
        label.set_gid(f"pair-{text}")
    if in_frame:
        geographic_axes(ax, frame)
    else:
        ax.set_xlabel("longitude (°E)")
        ax.set_ylabel("latitude (°N)")
    if seen:
        # Beside the map: matplotlib's "best" place is slow to find over hundreds of pairs.
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0, fontsize="small")
    ax.set_title(
        f"{len(result.pairs)} triggered pairs at their trigger positions,\n"
        "numbered as in the table's pair column",
        fontsize="medium",
    )
    return figure


def overview_svg(result: ReplayResult, chart: Chart | None) -> str:
    """``overview_figure`` as an inline SVG."""
    figure = overview_figure(result, chart)
    buffer = io.StringIO()
    # No date and fixed element ids: the same run gives the same page.
    with matplotlib.rc_context({"svg.hashsalt": "colregs9"}):
        figure.savefig(buffer, format="svg", bbox_inches="tight", metadata={"Date": None})
    svg = buffer.getvalue()
    # matplotlib opens every link in a new window; a pair's number filters this page's table.
    return svg[svg.index("<svg") :].replace(' target="_blank"', "")


def _names(entries: Sequence[Mapping[str, Any]]) -> list[str]:
    """The file names (no directories) of run.json's ``inputs`` or ``charts``."""
    return [Path(str(entry["path"])).name for entry in entries]


def _listed(names: Sequence[str], most: int = 3) -> str:
    shown = ", ".join(names[:most])
    return shown + (f" and {len(names) - most} more" if len(names) > most else "")


def _span(first: pd.Timestamp, last: pd.Timestamp) -> str:
    start = first.strftime(DISPLAY_TIME_FORMAT)
    # The end's date only when it is another day.
    end = last.strftime("%H:%M:%S" if first.date() == last.date() else DISPLAY_TIME_FORMAT)
    return f"{start} – {end} UTC"


def time_span(result: ReplayResult) -> tuple[str, str] | None:
    """The time span the page names, and what it is: the query's window when it has both
    ends, else the first and last trigger (the run keeps no span of the data read); None
    without either."""
    window = result.manifest.get("query", {}).get("time") or {}
    if window.get("start") is not None and window.get("end") is not None:
        return _span(pd.Timestamp(window["start"]), pd.Timestamp(window["end"])), "query window"
    triggers = [outcome.summary.trigger_utc for outcome in result.encounters]
    if not triggers:
        return None
    return _span(min(triggers), max(triggers)), "first to last trigger"


def page_title(result: ReplayResult) -> str:
    """E.g. ``Replay of a.csv, 2022-01-03 00:00:09 – 00:13:17 UTC, query all, chart
    US5CA72M.000``: the inputs, time span, query and charts, as the page's first line
    gives them in full."""
    inputs = _names(result.manifest.get("inputs", []))
    charts = _names(result.manifest.get("charts", []))
    span = time_span(result)
    parts = [f"Replay of {_listed(inputs)}" if inputs else "Replay"]
    if span is not None:
        parts.append(span[0])
    parts.append(f"query {result.query_name}")
    if charts:
        parts.append(f"chart{'s' if len(charts) > 1 else ''} {_listed(charts)}")
    return ", ".join(parts)


def _first_line(result: ReplayResult) -> str:
    inputs = _names(result.manifest.get("inputs", []))
    charts = _names(result.manifest.get("charts", []))
    span = time_span(result)
    description = result.manifest.get("query", {}).get("description")
    query = html.escape(result.query_name) + (
        f" ({html.escape(description)})" if description else ""
    )
    parts = [
        f"<b>Input{'s' if len(inputs) != 1 else ''}:</b> "
        + (html.escape(", ".join(inputs)) if inputs else "none named"),
        "<b>Time span:</b> "
        + ("none (no trigger)" if span is None else f"{html.escape(span[0])} ({span[1]})"),
        f"<b>Query:</b> {query}",
        f"<b>Chart{'s' if len(charts) != 1 else ''}:</b> "
        + (html.escape(", ".join(charts)) if charts else "none"),
    ]
    return '<p class="inputs">' + ". ".join(parts) + ".</p>"


def replay_html(
    result: ReplayResult,
    chart: Chart | None,
    plots: bool,
    encounter_dir: str,
    files: Sequence[str],
    motion_suffix: str,
) -> str:
    """The replay's index.html (see the module docstring); ``files`` are the report's other
    files written beside it, linked from the top."""
    counts = result.counts
    title = page_title(result)
    body = [
        f"<h1>{html.escape(title)}</h1>",
        _first_line(result),
        f'<p class="rules">{html.escape(RULES_APPLIED)}</p>',
        f"<p>{counts.vessels} vessels; {counts.encounters} encounters, {counts.triggered} "
        f"triggered (CPA &lt; {result.params.encounters.cpa_req_m:g} m within 0 ≤ TCPA ≤ "
        f"{result.params.encounters.tcpa_act_s:g} s) in {counts.triggered_pairs} pairs; "
        f"{html.escape(result.interaction_summary)} (only encounters get a verdict). Files: "
        f"{file_links(files)}.</p>",
    ]
    if result.pairs:
        body += ['<h2>Map</h2><div class="map">', overview_svg(result, chart), "</div>"]
    body.append("<h2>Encounters</h2>")
    numbers = pair_numbers(result)
    rows = [_encounter_row(outcome, numbers) for outcome in result.encounters]
    links = [f"#enc-{outcome.summary.encounter_id}" for outcome in result.encounters]
    if rows:
        # The script hides the columns from data-from on while the box is not ticked.
        body.append(
            '<p><label><input type="checkbox" class="more-columns" id="encounters-more" '
            f'data-table="encounters" data-from="{len(KEY_COLUMNS)}"> more columns: '
            f"{html.escape(', '.join(MORE_COLUMNS))}</label></p>"
        )
        body += sortable_table("encounters", ENCOUNTER_TABLE_COLUMNS, rows, _SELECTS, links)
    else:
        body.append("<p>No triggered encounters.</p>")
    for outcome in result.encounters:
        identifier = outcome.summary.encounter_id
        body.append(f'<section class="encounter" id="enc-{html.escape(identifier)}">')
        body.append(f"<h3>{html.escape(identifier)}</h3>")
        if plots:
            # Lazy: a report of hundreds of figures loads each as it is scrolled to.
            figure = f"{encounter_dir}/{html.escape(identifier)}"
            body.append(
                f'<img class="figure" src="{figure}.png" '
                f'alt="map of {html.escape(identifier)}" loading="lazy">'
            )
            body.append(
                f'<img class="figure" src="{figure}{motion_suffix}" '
                f'alt="range and relative motion of {html.escape(identifier)}" loading="lazy">'
            )
        body.append(
            f'<p><a href="{encounter_dir}/{html.escape(identifier)}.csv">time series (CSV, '
            'every second)</a> · <a href="#encounters">back to the table</a></p>'
        )
        body += timeline_html(outcome)
        body.append(f"<h4>Facts of {html.escape(identifier)}</h4>")
        body += _facts(outcome)
        body.append("</section>")
    return page(title, body)
