"""``colregs9 chart``: a chart's summary with its charted channels and, for a draught, its
navigable water and a plot or a GeoPackage."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyogrio
import shapely
from matplotlib.figure import Figure

from ..charts.cells import CellInfo
from ..charts.channels import (
    AxisSource,
    Channels,
    NavigableWidth,
    load_channels,
    navigable_widths,
)
from ..charts.water import Chart, load_chart
from ..errors import OutputError, ParameterError
from ..outputs import atomic_path, check_out_file, save_figure
from ..progress import progress_bar, progress_enabled
from ..report.chart_plot import draw_chart, geographic_axes

DEFAULT_REPORTS_DIR = Path("reports")
GEOPACKAGE_LAYERS = (
    "depth_areas",
    "coverage",
    "land",
    "navigable_water",
    "channels",
    "channel_axes",
)
GEOPACKAGE_SUFFIX = ".gpkg"
PLOT_SUFFIXES = (".png", ".svg", ".pdf")
PURPOSES = {1: "overview", 2: "general", 3: "coastal", 4: "approach", 5: "harbour", 6: "berthing"}


def _multipolygons(values: Any) -> np.ndarray:
    """Each geometry as a MultiPolygon of its polygonal parts (MULTIPOLYGON EMPTY when it has
    none): a GeoPackage layer of type MultiPolygon takes nothing else."""
    geometries = np.atleast_1d(np.asarray(values, dtype=object))
    parts, owner = shapely.get_parts(geometries, return_index=True)
    keep = (shapely.get_type_id(parts) == shapely.GeometryType.POLYGON) & ~shapely.is_empty(parts)
    out = np.array([shapely.MultiPolygon() for _ in geometries], dtype=object)
    if keep.any():
        # Indices left out keep their value in ``out``: the empty MultiPolygon.
        shapely.multipolygons(parts[keep], indices=owner[keep], out=out)
    return out


def write_chart_geopackage(
    path: Path,
    chart: Chart,
    draught_m: float,
    ukc_m: float,
    channels: Channels | None = None,
    navigable: Sequence[NavigableWidth | None] = (),
) -> None:
    """The chart as a GeoPackage in WGS84 (EPSG:4326), written with GDAL through pyogrio,
    whole or not at all: ``depth_areas`` (with DRVAL1, DRVAL2, the S-57 class and the chart
    file it comes from), ``coverage`` (one feature per chart file: the part it decides, with
    its ``rank``, 1 the most detailed), ``land`` (no feature when the chart has none) and
    ``navigable_water`` (for the draught and UKC), so that an analyst can check in QGIS the
    water a verdict used; and the charted ``channels`` (areas and lines, with their
    attributes and their water navigable for the draught) and their ``channel_axes``
    (``_channel_layers``; no feature when the chart has none)."""

    def geometries(values: Any) -> np.ndarray:
        shapes = chart.frame.shapes_to_wgs84(_multipolygons(values))
        return np.asarray(shapely.to_wkb(_multipolygons(shapes)), dtype=object)

    water = chart.navigable_water(draught_m, ukc_m)
    names = [p.name for p in chart.detail_order]
    depth_chart = (
        np.asarray([names[i] for i in chart.depth_chart], dtype=object)
        if len(chart.depth_chart) == len(chart.depth_areas)
        else np.full(len(chart.depth_areas), "", dtype=object)
    )
    if chart.coverage_by_chart:
        coverage_geometries = list(chart.coverage_by_chart)
        coverage_fields = {
            "chart": np.asarray(names, dtype=object),
            "rank": np.arange(1, len(names) + 1, dtype=np.int32),
        }
    else:
        coverage_geometries, coverage_fields = [chart.coverage], {}
    land = [] if shapely.is_empty(chart.land) else [chart.land]
    layers = {
        "depth_areas": (
            geometries(chart.depth_areas),
            {
                "DRVAL1": np.asarray(chart.drval1_m, dtype=float),
                "DRVAL2": np.asarray(chart.drval2_m, dtype=float),
                "kind": np.asarray([str(k) for k in chart.kinds], dtype=object),
                "chart": depth_chart,
            },
        ),
        "coverage": (geometries(np.asarray(coverage_geometries, dtype=object)), coverage_fields),
        "land": (geometries(np.asarray(land, dtype=object)), {}),
        "navigable_water": (
            geometries(water),
            {"draught_m": np.array([draught_m]), "ukc_m": np.array([ukc_m])},
        ),
    }
    kinds = dict.fromkeys(layers, "MultiPolygon")
    if channels is not None and len(navigable) != len(channels):
        navigable = navigable_widths(channels, draught_m, ukc_m)
    channel_layers = _channel_layers(channels, navigable, draught_m)
    for layer, (kind, shapes, fields) in channel_layers.items():
        layers[layer] = (_wkb(chart.frame.shapes_to_wgs84(shapes)), fields)
        kinds[layer] = kind
    with atomic_path(path, suffix=".gpkg") as tmp:
        tmp.unlink()  # GDAL creates the GeoPackage itself
        for index, (layer, (wkb, fields)) in enumerate(layers.items()):
            pyogrio.raw.write(
                tmp,
                wkb,
                list(fields.values()),
                list(fields.keys()),
                layer=layer,
                driver="GPKG",
                geometry_type=kinds[layer],
                crs="EPSG:4326",
                promote_to_multi=True,
                append=index > 0,
            )


def _wkb(shapes: Any) -> np.ndarray:
    return np.asarray(shapely.to_wkb(np.asarray(shapes, dtype=object)), dtype=object)


def _channel_layers(
    channels: Channels | None, navigable: Sequence[NavigableWidth | None], draught_m: float
) -> dict[str, tuple[str, np.ndarray, dict[str, np.ndarray]]]:
    """The ``channels`` layer (areas and lines in one layer of any geometry type) and the
    ``channel_axes`` layer (MultiLineString), each as (geometry type, shapes in the chart's
    frame, fields)."""
    items = list(channels or ())

    def column(values: list[Any], dtype: Any = object) -> np.ndarray:
        return np.asarray(values, dtype=dtype)

    def number(values: list[float | None]) -> np.ndarray:
        return np.asarray([np.nan if v is None else v for v in values], dtype=float)

    shared = {
        "kind": column([str(c.kind) for c in items]),
        "label": column([c.label for c in items]),
        "record_id": column([c.record_id for c in items]),
        "axis_source": column([str(c.axis_source) for c in items]),
        "axis_deg": number([c.axis_deg for c in items]),
    }
    fields = {
        **shared,
        "class": column([c.object_class for c in items]),
        "name": column([c.name for c in items]),
        "chart": column([c.chart for c in items]),
        "orient_deg": number([c.orient_deg for c in items]),
        "traffic": column([None if c.traffic is None else str(c.traffic) for c in items]),
        "depth_m": number([c.depth_m for c in items]),
        "depth_max_m": number([c.depth_max_m for c in items]),
        "category": number([c.category for c in items]),
        "length_m": number([c.length_m for c in items]),
        "width_m": number([c.width_m for c in items]),
        "tracks": column([", ".join(c.tracks) for c in items]),
        "navigable_share": number([None if n is None else n.share for n in navigable]),
        "narrowest_navigable_m": number([None if n is None else n.narrowest_m for n in navigable]),
        "draught_m": np.full(len(items), draught_m),
    }
    return {
        "channels": ("Unknown", column([c.geometry for c in items]), fields),
        "channel_axes": ("MultiLineString", column([c.axis for c in items]), shared),
    }


@dataclass(frozen=True)
class ChartSummary:
    chart: Chart
    navigable_area_km2: float | None
    plot_path: Path | None  # the plot or the GeoPackage written, if any
    text: str
    channels: Channels | None = None

    @property
    def written(self) -> str:
        """The line naming what was written (the CLI's notice on stderr); empty if nothing."""
        if self.plot_path is None:
            return ""
        if self.plot_path.suffix.lower() == GEOPACKAGE_SUFFIX:
            return f"GeoPackage: {self.plot_path} (layers {', '.join(GEOPACKAGE_LAYERS)})"
        return f"Plot: {self.plot_path}"


# The deepest draught of any ship (the largest tankers draw about 25 m; AIS encodes at most
# 25.5 m), and the largest under-keel clearance a chart check could ask for.
MAX_DRAUGHT_M = 30.0
MAX_UKC_M = 30.0


def _check_depth(name: str, value: float | None, limit_m: float) -> None:
    if value is None:
        return
    if not math.isfinite(value):
        raise ParameterError(f"--{name} {value} m is not a number; give metres in [0, {limit_m:g}]")
    if value < 0.0:
        raise ParameterError(f"--{name} {value:g} m is negative; give a value >= 0")
    if value > limit_m:
        raise ParameterError(
            f"--{name} {value:g} m is more than any ship needs ({limit_m:g} m at the most); "
            f"give metres in [0, {limit_m:g}]"
        )


def format_cell(cell: CellInfo) -> str:
    """One S-57 cell's identity: edition, update number, issue date, navigational purpose,
    compilation scale, accepted gaps."""
    edition = "?" if cell.edition is None else str(cell.edition)
    update = "?" if cell.update_number is None else str(cell.update_number)
    issued = "" if cell.issue_date is None else f", issued {cell.issue_date}"
    purpose = (
        f", purpose {cell.purpose} ({PURPOSES[cell.purpose]})" if cell.purpose in PURPOSES else ""
    )
    scale = "" if cell.scale is None else f", scale 1:{cell.scale}"
    files = f"{len(cell.update_files)} update file(s)"
    gap = (
        f"; GAP ACCEPTED, missing {', '.join(cell.missing_updates)}" if cell.missing_updates else ""
    )
    return (
        f"  {cell.name}: edition {edition}, update {update}{issued}{purpose}{scale} ({files}{gap})"
    )


def format_chart_summary(chart: Chart) -> str:
    lat_min, lat_max, lon_min, lon_max = chart.bounds_wgs84()
    depth_min, depth_max = chart.depth_range_m()
    lines = ["Charts: " + ", ".join(str(p) for p in chart.sources)]
    if chart.cells:
        lines += ["S-57 cells:", *(format_cell(cell) for cell in chart.cells)]
    if len(chart.detail_order) > 1:
        lines += [
            "Where they overlap, the first decides: "
            + " > ".join(p.name for p in chart.detail_order)
        ]
    lines += ["Layers (features):"]
    lines += [f"  {name:<7} {count:>6}" for name, count in chart.layer_counts.items()]
    lines += [
        f"Depth areas: {len(chart.depth_areas)}, DRVAL1 {depth_min:g} .. {depth_max:g} m",
        f"Extent: lat {lat_min:.5f} .. {lat_max:.5f}, lon {lon_min:.5f} .. {lon_max:.5f}",
        f"Charted area: {chart.coverage.area / 1e6:.3f} km²",
    ]
    return "\n".join(lines) + "\n"


def format_channels(
    channels: Channels,
    navigable: Sequence[NavigableWidth | None] = (),
    draught_m: float | None = None,
) -> str:
    """The charted channels, one line each: kind, name (else class and record id), axis
    (ORIENT as charted, else the derived centreline's direction from end to end, true),
    traffic, least depth, length × mean width, the tracks along it and, for a draught, how
    much of its axis has water navigable for it and how wide that is at the narrowest."""
    if len(channels) == 0:
        return "Channels: none charted\n"
    areas = sum(c.is_area for c in channels)
    labels = {c.record_id: c.label for c in channels}
    lines = [
        f"Channels: {areas} area(s), {len(channels) - areas} line(s) (axis true; least depth; "
        "length × mean width)"
    ]
    for i, channel in enumerate(channels):
        axis = "ORIENT" if channel.axis_source is AxisSource.ORIENT else str(channel.axis_source)
        parts = [f"{axis} {channel.axis_deg:05.1f}°"]
        if channel.traffic is not None:
            parts.append(str(channel.traffic))
        if channel.depth_m is not None:
            parts.append(f"{channel.depth_m:g} m deep")
        size = f"{channel.length_m:.0f} m"
        parts.append(size if channel.width_m is None else f"{size} × {channel.width_m:.0f} m")
        if channel.tracks:
            parts.append("along it " + ", ".join(labels.get(t, t) for t in channel.tracks))
        width = navigable[i] if i < len(navigable) else None
        if draught_m is not None and width is not None:
            parts.append(f"navigable for {draught_m:g} m along {width.share:.0%} of its axis")
            if width.narrowest_m is not None:
                parts[-1] += f", {width.narrowest_m:.0f} m wide there at the narrowest"
        lines.append(f"  {channel.kind:<17} {channel.label}: " + ", ".join(parts))
    return "\n".join(lines) + "\n"


def check_chart_out(out: Path | None, draught_m: float | None) -> None:
    """Refuse, before any chart is read, an ``--out`` the command would not write: one
    without ``--draught`` (the plot and the GeoPackage show the water for a draught) or of
    another kind than a plot or a GeoPackage, or a path that is not a regular file
    (``check_out_file``). Paths that cannot be written are refused when writing
    (``atomic_path``)."""
    if out is None:
        return
    if draught_m is None:
        raise ParameterError(
            f"--out {out} needs --draught M: the plot and the GeoPackage show the navigable "
            "water for a draught; add --draught"
        )
    suffix = out.suffix.lower()
    if out.is_dir():
        raise OutputError(
            f"{out}: --out is a directory; give a file in it, FILE.gpkg for a GeoPackage or "
            f"FILE.png ({', '.join(PLOT_SUFFIXES)}) for a plot"
        )
    if suffix != GEOPACKAGE_SUFFIX and suffix not in PLOT_SUFFIXES:
        raise OutputError(
            f"{out}: --out ends in {suffix or '(no suffix)'!r}, which the chart command does not "
            f"write; give FILE.gpkg for a GeoPackage or FILE.png ({', '.join(PLOT_SUFFIXES)}) "
            "for a plot"
        )
    check_out_file(out)


def summarise_chart(
    paths: Sequence[Path],
    draught_m: float | None = None,
    ukc_m: float = 0.0,
    out: Path | None = None,
    quiet: bool = False,
    accept_gaps: bool = False,
) -> ChartSummary:
    """Load the charts and summarise them; with a draught, add its navigable area and a plot.

    The plot goes to ``out`` (default ``reports/chart-<first chart's stem>.png``).
    """
    _check_depth("draught", draught_m, MAX_DRAUGHT_M)
    _check_depth("ukc", ukc_m, MAX_UKC_M)
    if draught_m is None and ukc_m:
        raise ParameterError(
            f"--ukc {ukc_m:g} needs --draught M: the clearance is added to a draught; add --draught"
        )
    check_chart_out(out, draught_m)
    with progress_bar("Reading charts", 2, progress_enabled(quiet)) as bar:
        chart = load_chart(paths, accept_gaps=accept_gaps)
        bar.advance()
        channels = load_channels(chart)
        bar.advance()
    if draught_m is None:
        text = format_chart_summary(chart) + format_channels(channels)
        return ChartSummary(chart, None, None, text, channels)
    navigable = navigable_widths(channels, draught_m, ukc_m)
    text = format_chart_summary(chart) + format_channels(channels, navigable, draught_m)
    area_km2 = chart.navigable_area_km2(draught_m, ukc_m)
    out_path = DEFAULT_REPORTS_DIR / f"chart-{Path(paths[0]).stem}.png" if out is None else out
    if out_path.suffix.lower() == GEOPACKAGE_SUFFIX:
        write_chart_geopackage(out_path, chart, draught_m, ukc_m, channels, navigable)
        text += (
            f"Navigable water for draught {draught_m:g} m + UKC {ukc_m:g} m: {area_km2:.3f} km²\n"
        )
        return ChartSummary(chart, area_km2, out_path, text, channels)
    plot_path = out_path
    # A bare Figure, not pyplot's: no backend to choose, no figure left open (Agg on save).
    figure = Figure(figsize=(8, 8), layout="constrained")
    ax = figure.subplots()
    depths = draw_chart(ax, chart, draught_m, ukc_m, coverage=True)
    figure.colorbar(depths, ax=ax, label="DRVAL1, shallowest depth (m)", shrink=0.7)
    geographic_axes(ax, chart.frame)
    ax.set_title(
        f"{Path(paths[0]).name}: navigable water for draught {draught_m:g} m "
        f"+ UKC {ukc_m:g} m ({area_km2:.3f} km²)",
        fontsize="medium",
    )
    ax.legend(loc="lower right", fontsize="small")
    save_figure(plot_path, figure, dpi=150)
    text += f"Navigable water for draught {draught_m:g} m + UKC {ukc_m:g} m: {area_km2:.3f} km²\n"
    return ChartSummary(chart, area_km2, plot_path, text, channels)
