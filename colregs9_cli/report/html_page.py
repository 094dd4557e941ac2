"""The page every report's ``index.html`` is made of: style, script, sortable tables, and
the page of ``stats``.

A page needs no network: its style and its script (sorting and filtering the tables) are in
the file; the figures are the PNG files beside it, linked relatively, so the report directory
opens as it is, offline, from a disk or a file share. A figure that is missing
(``--no-plots``, or a file moved) is marked on the page, not shown as a broken image. The
replay's page, with its map, is html_report.py.
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
import pandas as pd

from ..timebase import DISPLAY_TIME_FORMAT

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
table.key-only .more { display: none; }
/* Key columns only, long names wrap rather than push the table past the window. */
table.key-only td { white-space: normal; }
p.inputs { margin: 0.3em 0 0.8em; }
.filters { margin: 0.8em 0; } .filters input { width: 22em; }
section.encounter { border-top: 1px solid #ccc; padding-top: 0.5em; }
dl.facts { display: grid; grid-template-columns: max-content auto; gap: 2px 12px; }
dl.facts dt { font-weight: 600; } dl.facts dd { margin: 0; }
img.figure { max-width: 100%; border: 1px solid #ddd; display: block; margin: 0.5em 0; }
div.timeline { max-width: 100%; overflow-x: auto; }
table.timeline { font-size: 12px; }
table.timeline th { cursor: default; position: static; white-space: normal; }
table.timeline td:nth-child(2) { white-space: normal; min-width: 9em; }
table.timeline tr.event td { background: #fff4d6; font-weight: 600; }
p.rules { font-size: 13px; color: #444; }
.missing { color: #a00; font-style: italic; }
.map svg { max-width: 100%; height: auto; }
"""

# Sorts a table by a clicked header (numbers as numbers), filters its rows by the text box
# and the selects (a link to #pair-N sets the pair select), shows a table's extra columns
# (from a "more columns" box's data-from on) only while the box is ticked, and marks a
# figure that fails to load.
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
    // A link can carry a filter and a sort (a column number): index.html?q=head-on&sort=5
    const query = new URLSearchParams(location.search);
    if (box && query.has("q")) { box.value = query.get("q"); applyFilters(table); }
    if (query.has("sort")) sortBy(table.tHead.rows[0].cells[Number(query.get("sort"))]);
  });
  document.querySelectorAll("input.more-columns").forEach(box => {
    const table = document.getElementById(box.dataset.table);
    const from = Number(box.dataset.from);
    for (const row of table.rows)
      Array.from(row.cells).slice(from).forEach(cell => cell.classList.add("more"));
    const show = () => table.classList.toggle("key-only", !box.checked);
    box.addEventListener("change", show);
    show();
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
// A figure is marked missing on its own error event, never by a check at "load": a lazy
// figure below the fold has not loaded yet then, and loads when it is scrolled to. The
// listener captures on the document from the head, before any image can fail.
document.addEventListener("error", event => {
  const img = event.target;
  if (!(img instanceof HTMLImageElement) || !img.classList.contains("figure")) return;
  const note = document.createElement("p");
  note.className = "missing";
  note.textContent = "figure not found: " + img.getAttribute("src");
  img.replaceWith(note);
}, true);
"""


def page(title: str, body: Iterable[str]) -> str:
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


def cell_text(value: Any) -> str:
    if value is None or (isinstance(value, float) and np.isnan(value)):
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        # Tenths below 1000, so that a CPA of 149.8 m does not read as the 150 m threshold.
        return f"{value:.0f}" if abs(value) >= 1000 else f"{value:.1f}"
    if isinstance(value, pd.Timestamp):
        return value.strftime(DISPLAY_TIME_FORMAT)
    return str(getattr(value, "value", value))


def _cell(value: Any, href: str | None = None) -> str:
    numeric = isinstance(value, int | float | np.integer | np.floating) and not isinstance(
        value, bool | np.bool_
    )
    exact = f' data-value="{float(value)!r}"' if numeric and value == value else ""
    css = ' class="num"' if numeric else ""
    text = html.escape(cell_text(value))
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
            {cell_text(row[index]) for row in rows},
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


def file_links(files: Sequence[str]) -> str:
    return ", ".join(f'<a href="{html.escape(f)}">{html.escape(f)}</a>' for f in files)


def stats_html(
    title: str,
    tables: Sequence[tuple[str, pd.DataFrame]],
    images: Sequence[str],
    files: Sequence[str],
) -> str:
    """The stats' index.html: each table (sortable), each histogram (a PNG beside it), and
    links to the other ``files``."""
    body = [f"<h1>{html.escape(title)}</h1>", f"<p>Files: {file_links(files)}.</p>"]
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
    return page(title, body)
