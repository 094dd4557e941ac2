"""Self-contained HTML pages for the reports: ``index.html`` of a replay and of ``stats``.

A page needs no network: its style, its script (sorting and filtering the table) and the
overview map (an inline SVG drawn by matplotlib from the data and the chart, no tiles) are in
the file; the per-encounter figures and the histograms are the PNG files beside it, linked
relatively, so the report directory opens as it is, offline, from a disk or a file share.
A figure that is missing (``--no-plots``, or a file moved) is marked on the page, not shown as
a broken image. The map numbers the pairs as the table's ``pair`` column does; a number on
the map links to ``#pair-N``, which filters the table to that pair.
"""

from __future__ import annotations

import html
import io
from collections.abc import Iterable, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..replay_results import EncounterOutcome, ReplayResult
from .chart_plot import Bounds, draw_chart, geographic_axes, show_view

if TYPE_CHECKING:
    from ..chart import Chart

HTML_NAME = "index.html"

_STYLE = """
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 2em; }
table { border-collapse: collapse; font-size: 13px; }
th, td { border: 1px solid #ccc; padding: 3px 6px; text-align: left; white-space: nowrap; }
th { background: #eef; cursor: pointer; position: sticky; top: 0; }
th.sorted-asc::after { content: " ▲"; } th.sorted-desc::after { content: " ▼"; }
td.num { text-align: right; }
tr.hidden { display: none; }
.filters { margin: 0.8em 0; } .filters input { width: 22em; }
section.encounter { border-top: 1px solid #ccc; padding-top: 0.5em; }
dl.facts { display: grid; grid-template-columns: max-content auto; gap: 2px 12px; }
dl.facts dt { font-weight: 600; } dl.facts dd { margin: 0; }
img.figure { max-width: 100%; border: 1px solid #ddd; }
.missing { color: #a00; font-style: italic; }
.map svg { max-width: 100%; height: auto; }
"""

# Sorts a table by a clicked header (numbers as numbers), filters its rows by the text box
# and the selects (a link to #pair-N sets the pair select), and marks figures that did not
# load.
_SCRIPT = r"""
function cellValue(row, index) {
  const text = row.cells[index].dataset.value ?? row.cells[index].textContent;
  const number = Number(text);
  return text !== "" && !Number.isNaN(number) ? number : text.toLowerCase();
}
function sortBy(header) {
  const table = header.closest("table");
  const index = Array.from(header.parentNode.cells).indexOf(header);
  const ascending = !header.classList.contains("sorted-asc");
  table.querySelectorAll("th").forEach(h => h.classList.remove("sorted-asc", "sorted-desc"));
  header.classList.add(ascending ? "sorted-asc" : "sorted-desc");
  const body = table.tBodies[0];
  const rows = Array.from(body.rows);
  rows.sort((a, b) => {
    const x = cellValue(a, index), y = cellValue(b, index);
    const order = x < y ? -1 : x > y ? 1 : 0;
    return ascending ? order : -order;
  });
  rows.forEach(row => body.appendChild(row));
}
function applyFilters(table) {
  const text = document.getElementById(table.id + "-text").value.toLowerCase();
  const selects = document.querySelectorAll("select[data-table='" + table.id + "']");
  let shown = 0;
  for (const row of table.tBodies[0].rows) {
    let keep = row.textContent.toLowerCase().includes(text);
    selects.forEach(select => {
      const index = Number(select.dataset.column);
      if (select.value !== "" && row.cells[index].textContent !== select.value) keep = false;
    });
    row.classList.toggle("hidden", !keep);
    shown += keep ? 1 : 0;
  }
  document.getElementById(table.id + "-shown").textContent = shown;
}
document.addEventListener("DOMContentLoaded", () => {
  document.querySelectorAll("table.sortable th").forEach(h =>
    h.addEventListener("click", () => sortBy(h)));
  document.querySelectorAll("table.sortable").forEach(table => {
    const box = document.getElementById(table.id + "-text");
    if (box) box.addEventListener("input", () => applyFilters(table));
    document.querySelectorAll("select[data-table='" + table.id + "']").forEach(s =>
      s.addEventListener("change", () => applyFilters(table)));
    // A link can carry a filter and a sort (a column number): index.html?q=head-on&sort=10
    const query = new URLSearchParams(location.search);
    if (box && query.has("q")) { box.value = query.get("q"); applyFilters(table); }
    if (query.has("sort")) sortBy(table.tHead.rows[0].cells[Number(query.get("sort"))]);
  });
  selectPair();
});
function selectPair() {
  const match = location.hash.match(/^#pair-(\d+)$/);
  const select = document.querySelector("select[data-name='pair']");
  if (!match || !select) return;
  select.value = match[1];
  const table = document.getElementById(select.dataset.table);
  applyFilters(table);
  table.scrollIntoView();
}
window.addEventListener("hashchange", selectPair);
window.addEventListener("load", () => {
  document.querySelectorAll("img.figure").forEach(img => {
    if (!img.complete || img.naturalWidth === 0) {
      const note = document.createElement("p");
      note.className = "missing";
      note.textContent = "figure not found: " + img.getAttribute("src");
      img.replaceWith(note);
    }
  });
});
"""


def _page(title: str, body: Iterable[str]) -> str:
    return "\n".join(
        [
            "<!DOCTYPE html>",
            '<html lang="en"><head><meta charset="utf-8">',
            f"<title>{html.escape(title)}</title>",
            f"<style>{_STYLE}</style>",
            f"<script>{_SCRIPT}</script>",
            "</head><body>",
            *body,
            "</body></html>",
            "",
        ]
    )


def _text(value: Any) -> str:
    if value is None or (isinstance(value, float) and np.isnan(value)):
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:.0f}" if abs(value) >= 100 else f"{value:.1f}"
    if isinstance(value, pd.Timestamp):
        return value.strftime("%Y-%m-%d %H:%M:%S")
    return str(getattr(value, "value", value))


def _cell(value: Any, href: str | None = None) -> str:
    numeric = isinstance(value, int | float | np.integer | np.floating) and not isinstance(
        value, bool | np.bool_
    )
    exact = f' data-value="{float(value)!r}"' if numeric and value == value else ""
    css = ' class="num"' if numeric else ""
    text = html.escape(_text(value))
    if href is not None:
        text = f'<a href="{html.escape(href)}">{text}</a>'
    return f"<td{css}{exact}>{text}</td>"


def sortable_table(
    table_id: str,
    columns: Sequence[str],
    rows: Sequence[Sequence[Any]],
    select_columns: Sequence[int] = (),
    links: Sequence[str] | None = None,
) -> list[str]:
    """A table whose headers sort it, with a text filter and a select per listed column;
    ``links`` makes each row's first cell a link."""
    lines = ['<div class="filters">']
    lines.append(
        f'<label>Filter: <input id="{table_id}-text" type="search" '
        'placeholder="any text in the row"></label>'
    )
    for index in select_columns:
        # Numbers in numeric order (2 before 10), then text.
        values = sorted(
            {_text(row[index]) for row in rows},
            key=lambda v: (0, int(v), "") if v.isdigit() else (1, 0, v),
        )
        options = "".join(
            f'<option value="{html.escape(v)}">{html.escape(v)}</option>' for v in values
        )
        lines.append(
            f' <label>{html.escape(columns[index])}: <select data-table="{table_id}" '
            f'data-column="{index}" data-name="{html.escape(columns[index])}">'
            f'<option value="">all</option>{options}</select></label>'
        )
    lines.append(
        f' <span><span id="{table_id}-shown">{len(rows)}</span> of {len(rows)} shown</span>'
    )
    lines.append("</div>")
    lines.append(f'<table class="sortable" id="{table_id}"><thead><tr>')
    lines.append("".join(f"<th>{html.escape(c)}</th>" for c in columns))
    lines.append("</tr></thead><tbody>")
    for number, row in enumerate(rows):
        cells = [
            _cell(value, links[number] if links is not None and i == 0 else None)
            for i, value in enumerate(row)
        ]
        lines.append("<tr>" + "".join(cells) + "</tr>")
    lines.append("</tbody></table>")
    return lines


# -- replay ---------------------------------------------------------------------------------

ENCOUNTER_TABLE_COLUMNS = (
    "encounter",
    "pair",
    "trigger (UTC)",
    "own",
    "target",
    "situation",
    "own role (final)",
    "target role (final)",
    "rule 9",
    "deciding rule",
    "CPA (m)",
    "min sep (m)",
    "data covers CPA",
    "give-way acted",
)
# The table's columns offered as selects.
_SELECTS = tuple(
    ENCOUNTER_TABLE_COLUMNS.index(name)
    for name in (
        "pair",
        "situation",
        "rule 9",
        "deciding rule",
        "data covers CPA",
        "give-way acted",
    )
)


def _vessel(name: str | None, mmsi: int) -> str:
    return f"{name} ({mmsi})" if name else str(mmsi)


def pair_numbers(result: ReplayResult) -> dict[str, int]:
    """Each triggered pair's number on the map and in the table: 1, 2, … in pairs.csv's
    order."""
    return {pair.summary.pair_id: number for number, pair in enumerate(result.pairs, start=1)}


def _encounter_row(outcome: EncounterOutcome, numbers: Mapping[str, int]) -> list[Any]:
    s = outcome.summary
    return [
        s.encounter_id,
        numbers[s.pair_id],
        s.trigger_utc,
        _vessel(s.own_name, s.own_mmsi),
        _vessel(s.target_name, s.target_mmsi),
        _text(s.situation),
        _text(s.own_role_final),
        _text(s.target_role_final),
        "applied" if s.rule9_applied else "not applied",
        f"rule {_text(s.deciding_rule)}",
        s.cpa_m,
        s.actual_min_separation_m,
        s.data_covers_cpa,
        s.give_way_vessel_acted,
    ]


def _facts(outcome: EncounterOutcome) -> list[str]:
    fields = outcome.summary.__dataclass_fields__
    lines = ['<dl class="facts">']
    for name in fields:
        value = getattr(outcome.summary, name)
        lines.append(f"<dt>{html.escape(name)}</dt><dd>{html.escape(_text(value))}</dd>")
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
    figure, ax = plt.subplots(figsize=(width_in, MAP_HEIGHT_IN))
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
        situation = _text(pair.summary.situation)
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
        # Beside the map: matplotlib's "best" place costs a second over hundreds of pairs.
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
    try:
        buffer = io.StringIO()
        # No date and fixed element ids: the same run gives the same page.
        with matplotlib.rc_context({"svg.hashsalt": "colregs9"}):
            figure.savefig(buffer, format="svg", bbox_inches="tight", metadata={"Date": None})
    finally:
        plt.close(figure)
    svg = buffer.getvalue()
    # matplotlib opens every link in a new window; a pair's number filters this page's table.
    return svg[svg.index("<svg") :].replace(' target="_blank"', "")


def _file_links(files: Sequence[str]) -> str:
    return ", ".join(f'<a href="{html.escape(f)}">{html.escape(f)}</a>' for f in files)


def replay_html(
    result: ReplayResult,
    chart: Chart | None,
    plots: bool,
    encounter_dir: str,
    files: Sequence[str],
) -> str:
    """The replay's index.html (see the module docstring); ``files`` are the report's other
    files written beside it, linked from the top."""
    counts = result.counts
    title = f"Replay: {result.query_name}"
    body = [
        f"<h1>{html.escape(title)}</h1>",
        f"<p>{counts.vessels} vessels; {counts.encounters} encounters, {counts.triggered} "
        f"triggered (CPA &lt; {result.params.replay.cpa_req_m:g} m within 0 ≤ TCPA ≤ "
        f"{result.params.replay.tcpa_act_s:g} s) in {counts.triggered_pairs} pairs. Files: "
        f"{_file_links(files)}.</p>",
    ]
    if result.pairs:
        body += ['<h2>Map</h2><div class="map">', overview_svg(result, chart), "</div>"]
    body.append("<h2>Encounters</h2>")
    numbers = pair_numbers(result)
    rows = [_encounter_row(outcome, numbers) for outcome in result.encounters]
    links = [f"#enc-{outcome.summary.encounter_id}" for outcome in result.encounters]
    if rows:
        body += sortable_table("encounters", ENCOUNTER_TABLE_COLUMNS, rows, _SELECTS, links)
    else:
        body.append("<p>No triggered encounters.</p>")
    for outcome in result.encounters:
        identifier = outcome.summary.encounter_id
        body.append(f'<section class="encounter" id="enc-{html.escape(identifier)}">')
        body.append(f"<h3>{html.escape(identifier)}</h3>")
        if plots:
            body.append(
                f'<img class="figure" src="{encounter_dir}/{html.escape(identifier)}.png" '
                f'alt="figure of {html.escape(identifier)}" loading="lazy">'
            )
        body.append(
            f'<p><a href="{encounter_dir}/{html.escape(identifier)}.csv">time series (CSV)</a>'
            ' · <a href="#encounters">back to the table</a></p>'
        )
        body += _facts(outcome)
        body.append("</section>")
    return _page(title, body)


# -- stats ----------------------------------------------------------------------------------


def stats_html(
    title: str,
    tables: Sequence[tuple[str, pd.DataFrame]],
    images: Sequence[str],
    files: Sequence[str],
) -> str:
    """The stats' index.html: each table (sortable), each histogram (a PNG beside it), and
    links to the other ``files``."""
    body = [f"<h1>{html.escape(title)}</h1>", f"<p>Files: {_file_links(files)}.</p>"]
    for number, (heading, frame) in enumerate(tables):
        body.append(f"<h2>{html.escape(heading)}</h2>")
        rows = [list(row) for row in frame.itertuples(index=False)]
        body += sortable_table(f"table{number}", [str(c) for c in frame.columns], rows)
    if images:
        body.append("<h2>Histograms</h2>")
    for image in images:
        body.append(
            f'<p><img class="figure" src="{html.escape(image)}" alt="{html.escape(image)}"></p>'
        )
    return _page(title, body)
