"""The reports of ``colregs9 stats``: CSV, Markdown (the paper's table), histograms, run.json.

Every file is written atomically. The statistics themselves come from ``core.dimensions``; this
module only lays them out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib import colormaps
from matplotlib.colors import to_hex
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from ..outputs import report_directory, save_figure, write_csv, write_json, write_text
from ..provenance import query_manifest, run_header
from .html_page import HTML_NAME, stats_html

if TYPE_CHECKING:
    from ..core.dimensions import StatsResult, StatsTable
    from ..query import Query

CSV_NAME = "dimension_stats.csv"
MARKDOWN_NAME = "dimension_stats.md"
HISTOGRAM_NAME = "dimension_histograms.png"
MANIFEST_NAME = "run.json"

DIMENSION_LABELS: dict[str, str] = {
    "length_m": "Length (m)",
    "breadth_m": "Breadth (m)",
    "draught_m": "Draught (m)",
}
HISTOGRAM_MAX_BINS = 40
# Ship types stacked in the histograms: 40 colours before one repeats (DMA has 27 types).
TYPE_COLOURS = [to_hex(c) for name in ("tab20", "tab20b") for c in colormaps[name](np.arange(20))]


def _number(value: float, decimals: int) -> str:
    return "" if math.isnan(value) else f"{value:.{decimals}f}"


def _units(n: int, unit_name: str) -> str:
    return f"{n} {unit_name.removesuffix('s') if n == 1 else unit_name}"


def _title(result: StatsResult, query_name: str) -> str:
    counted = result.vessels if result.per.value == "vessel" else result.messages
    return (
        f"Vessel dimensions, query '{query_name}', per {result.per.value} "
        f"({_units(counted, result.unit_name)})"
    )


def _text_table(table: StatsTable) -> list[str]:
    header = ["dimension", "count", "mean", "median", "std", "min", "max", "missing"]
    lines = [header]
    for row in table.rows:
        lines.append(
            [
                row.dimension,
                str(row.count),
                *(_number(getattr(row, name), 2) for name in ("mean", "median", "std", "min")),
                _number(row.max, 2),
                str(row.missing),
            ]
        )
    widths = [max(len(line[i]) for line in lines) for i in range(len(header))]
    return [
        "  ".join(
            cell.ljust(width) if i == 0 else cell.rjust(width)
            for i, (cell, width) in enumerate(zip(line, widths, strict=True))
        ).rstrip()
        for line in lines
    ]


def format_text(result: StatsResult, query_name: str) -> str:
    """The plain, aligned table printed to stdout (NaN shown as an empty cell)."""
    lines = [_title(result, query_name), *_text_table(result.overall)]
    for table in result.groups:
        lines += ["", f"ship type {table.group} ({_units(table.units, result.unit_name)})"]
        lines += _text_table(table)
    return "\n".join(lines) + "\n"


def _markdown_table(table: StatsTable) -> list[str]:
    lines = [
        "| Dimension | mean | median | std | min | max | count | missing |",
        "|:--|--:|--:|--:|--:|--:|--:|--:|",
    ]
    for row in table.rows:
        cells = [
            _number(getattr(row, name), 1) or "–"
            for name in ("mean", "median", "std", "min", "max")
        ]
        lines.append(
            f"| {DIMENSION_LABELS[row.dimension]} | {' | '.join(cells)} "
            f"| {row.count} | {row.missing} |"
        )
    return lines


def format_markdown(result: StatsResult, query_name: str) -> str:
    """The paper's Table "Statistical overview of vessel dimensions", plus count and missing."""
    unit = "vessel" if result.per.value == "vessel" else "position message"
    lines = [
        f"# Statistical overview of vessel dimensions: {query_name}",
        "",
        f"{_title(result, query_name)}. `count` is the number of {unit}s with a value, "
        f"`missing` the number without one; std is the sample standard deviation "
        "(ddof = 1), shown as – when fewer than two values exist.",
        "",
        *_markdown_table(result.overall),
    ]
    for table in result.groups:
        units = _units(table.units, result.unit_name)
        lines += ["", f"## Ship type: {table.group} ({units})", ""]
        lines += _markdown_table(table)
    return "\n".join(lines) + "\n"


def type_colours(result: StatsResult) -> dict[str, str]:
    """One colour per ship type of the grouped statistics (the CSV's groups), the same in
    every panel whatever types a dimension has values for."""
    return {
        str(table.group): TYPE_COLOURS[i % len(TYPE_COLOURS)]
        for i, table in enumerate(result.groups)
    }


def histogram_bins(values: np.ndarray, units: np.ndarray) -> int:
    """How many bins for sorted ``values``, each standing for ``units`` units: the finer of
    Sturges' and Freedman-Diaconis' rules over the units (numpy's classic ``"auto"``, which
    takes no weights), at most ``HISTOGRAM_MAX_BINS``."""
    n = int(units.sum())
    span = float(values[-1] - values[0])
    if span <= 0.0:
        return 1
    bins = math.ceil(math.log2(n) + 1.0)
    # The quartiles of the units' values: the values at those places of the sorted units.
    cumulative = np.cumsum(units)
    lower_quartile, upper_quartile = values[
        np.searchsorted(cumulative, [(n - 1) // 4, 3 * (n - 1) // 4], side="right")
    ]
    spread = float(upper_quartile - lower_quartile)
    if spread > 0.0:
        bins = max(bins, math.ceil(span / (2.0 * spread * n ** (-1.0 / 3.0))))
    return min(bins, HISTOGRAM_MAX_BINS)


def histogram_figure(result: StatsResult, query_name: str) -> Figure:
    """Three histograms (length, breadth, draught) of the counted units' values, stacked by
    ship type when the statistics are grouped by it: each type in its colour in every panel
    (``type_colours``), each stack (a ``BarContainer``) labelled with its type, and one legend
    for all the types."""
    # A bare Figure renders with Agg on save, without pyplot's backend machinery. Fixed
    # margins: a layout engine would cost more than drawing these three panels does
    # (figures: tests/benchmarks/README.md).
    figure = Figure(figsize=(13, 4))
    figure.subplots_adjust(left=0.05, right=0.99, bottom=0.13, top=0.82, wspace=0.22)
    axes = figure.subplots(1, 3)
    colours = type_colours(result)
    for axis, (dimension, label) in zip(axes, DIMENSION_LABELS.items(), strict=True):
        samples = result.samples.loc[result.samples["units"] > 0, ["ship_type", dimension, "units"]]
        samples = samples.dropna(subset=[dimension]).sort_values(dimension, kind="stable")
        values = samples[dimension].to_numpy(dtype=float)
        units = samples["units"].to_numpy(dtype=np.int64)
        if values.size:
            edges = np.histogram_bin_edges(values, bins=histogram_bins(values, units))
            if result.by is None:
                axis.hist(values, bins=edges, weights=units, color="tab:blue", edgecolor="white")
            else:
                # Stacked by ship type: the bars' heights are the overall histogram's.
                types = samples["ship_type"].astype(str).to_numpy()
                groups = [name for name in colours if (types == name).any()]
                axis.hist(
                    [values[types == name] for name in groups],
                    bins=edges,
                    weights=[units[types == name] for name in groups],
                    stacked=True,
                    color=[colours[name] for name in groups],
                    edgecolor="white",
                    linewidth=0.3,
                )
                # One bar container per type, in the order given.
                for stack, name in zip(axis.containers, groups, strict=True):
                    stack.set_label(name)
        else:
            axis.text(0.5, 0.5, "no values", ha="center", va="center", transform=axis.transAxes)
        # Few ticks: each tick label is costly to make and draw.
        axis.xaxis.set_major_locator(MaxNLocator(nbins=6))
        axis.yaxis.set_major_locator(MaxNLocator(nbins=5, integer=True))
        axis.set_xlabel(label)
        axis.set_ylabel(result.unit_name)
        # A set height spares matplotlib its search for tick labels above the axes.
        axis.set_title(f"{label}: n = {int(units.sum())}", y=1.0)
    figure.suptitle(_title(result, query_name))
    if colours:
        figure.subplots_adjust(right=0.86)
        figure.legend(
            [Patch(facecolor=colour) for colour in colours.values()],
            list(colours),
            loc="center right",
            fontsize="x-small",
        )
    return figure


@dataclass(frozen=True)
class StatsInputs:
    """What the statistics were computed from, as run.json records it: each input file
    (``provenance.inputs_manifest``), the rows read, the rows the query kept, and the rejects
    ledger (its ``to_dict``)."""

    inputs: list[dict[str, Any]]
    rows_read: int
    rows_in_query: int
    ledger: dict[str, Any]


def build_manifest(result: StatsResult, query: Query, read: StatsInputs) -> dict[str, Any]:
    """The content of run.json: what was read, what the query kept, and the result."""
    return {
        **run_header("stats"),
        "query": query_manifest(query),
        "inputs": read.inputs,
        "rows_read": read.rows_read,
        "rows_in_query": read.rows_in_query,
        "ledger": read.ledger,
        "per": result.per.value,
        "by": None if result.by is None else result.by.value,
        "vessels": result.vessels,
        "messages": result.messages,
        "table": result.overall.to_dict(),
        "groups": [table.to_dict() for table in result.groups],
    }


def write_stats_reports(
    out_dir: Path,
    result: StatsResult,
    query_name: str,
    manifest: dict[str, Any],
    overwrite: bool = False,
) -> tuple[Path, ...]:
    """Write the five report files into ``out_dir``, which is replaced (files colregs9 did
    not write stay: ``outputs.report_directory``, with ``overwrite``); returns their paths."""
    names = (CSV_NAME, MARKDOWN_NAME, HISTOGRAM_NAME, HTML_NAME, MANIFEST_NAME)
    with report_directory(out_dir, overwrite) as staging:
        csv_path, markdown_path, histogram_path, html_path, manifest_path = (
            staging / n for n in names
        )
        table = result.to_frame()
        write_csv(csv_path, table)
        write_text(markdown_path, format_markdown(result, query_name))
        save_figure(histogram_path, histogram_figure(result, query_name), dpi=110)
        write_text(
            html_path,
            stats_html(
                _title(result, query_name),
                [("Dimension statistics", table)],
                [HISTOGRAM_NAME],
                [CSV_NAME, MARKDOWN_NAME, MANIFEST_NAME],
            ),
        )
        write_json(manifest_path, manifest)
    return tuple(out_dir / name for name in names)
