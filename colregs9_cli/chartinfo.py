"""``colregs9 chart``: a chart's summary and, for a draught, its navigable water and a plot."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pyogrio
import shapely

from .chart import CellInfo, Chart, load_chart
from .errors import ParameterError
from .progress import progress_bar, progress_enabled
from .report.atomic import atomic_path, save_figure
from .report.chart_plot import draw_chart

DEFAULT_REPORTS_DIR = Path("reports")
GEOPACKAGE_LAYERS = ("depth_areas", "coverage", "land", "navigable_water")


def write_chart_geopackage(path: Path, chart: Chart, draught_m: float, ukc_m: float) -> None:
    """The chart as a GeoPackage in WGS84 (EPSG:4326), written with GDAL through pyogrio,
    whole or not at all: ``depth_areas`` (with DRVAL1, DRVAL2 and the S-57 class),
    ``coverage``, ``land`` and ``navigable_water`` (for the draught and UKC), so that an
    analyst can check in QGIS the water a verdict used."""

    def to_wgs84(xy: np.ndarray) -> np.ndarray:
        lat_deg, lon_deg = chart.frame.to_geodetic(xy[:, 1], xy[:, 0])
        return np.column_stack([lon_deg, lat_deg])

    def geometries(values: Any) -> np.ndarray:
        projected = shapely.transform(np.atleast_1d(np.asarray(values, dtype=object)), to_wgs84)
        return np.asarray(shapely.to_wkb(projected), dtype=object)

    water = chart.navigable_water(draught_m, ukc_m)
    layers = {
        "depth_areas": (
            geometries(chart.depth_areas),
            {
                "DRVAL1": np.asarray(chart.drval1_m, dtype=float),
                "DRVAL2": np.asarray(chart.drval2_m, dtype=float),
                "kind": np.asarray([str(k) for k in chart.kinds], dtype=object),
            },
        ),
        "coverage": (geometries(chart.coverage), {}),
        "land": (geometries(chart.land), {}),
        "navigable_water": (
            geometries(water),
            {"draught_m": np.array([draught_m]), "ukc_m": np.array([ukc_m])},
        ),
    }
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
                geometry_type="MultiPolygon",
                crs="EPSG:4326",
                promote_to_multi=True,
                append=index > 0,
            )


@dataclass(frozen=True)
class ChartSummary:
    chart: Chart
    navigable_area_km2: float | None
    plot_path: Path | None
    text: str


def _check_depth(name: str, value: float | None) -> None:
    if value is not None and not value >= 0.0:
        raise ParameterError(f"--{name} {value} m is negative; give a value >= 0")


def format_cell(cell: CellInfo) -> str:
    """One S-57 cell's identity: edition, update number, issue date, accepted gaps."""
    edition = "?" if cell.edition is None else str(cell.edition)
    update = "?" if cell.update_number is None else str(cell.update_number)
    issued = "" if cell.issue_date is None else f", issued {cell.issue_date}"
    files = f"{len(cell.update_files)} update file(s)"
    gap = (
        f"; GAP ACCEPTED, missing {', '.join(cell.missing_updates)}" if cell.missing_updates else ""
    )
    return f"  {cell.name}: edition {edition}, update {update}{issued} ({files}{gap})"


def format_chart_summary(chart: Chart) -> str:
    lat_min, lat_max, lon_min, lon_max = chart.bounds_wgs84()
    depth_min, depth_max = chart.depth_range_m()
    lines = ["Charts: " + ", ".join(str(p) for p in chart.sources)]
    if chart.cells:
        lines += ["S-57 cells:", *(format_cell(cell) for cell in chart.cells)]
    lines += ["Layers (features):"]
    lines += [f"  {name:<7} {count:>6}" for name, count in chart.layer_counts.items()]
    lines += [
        f"Depth areas: {len(chart.depth_areas)}, DRVAL1 {depth_min:g} .. {depth_max:g} m",
        f"Extent: lat {lat_min:.5f} .. {lat_max:.5f}, lon {lon_min:.5f} .. {lon_max:.5f}",
        f"Charted area: {chart.coverage.area / 1e6:.3f} km²",
    ]
    return "\n".join(lines) + "\n"


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
    _check_depth("draught", draught_m)
    _check_depth("ukc", ukc_m)
    with progress_bar("Reading charts", 1, progress_enabled(quiet)) as bar:
        chart = load_chart(paths, accept_gaps=accept_gaps)
        bar.advance()
    text = format_chart_summary(chart)
    if draught_m is None:
        return ChartSummary(chart, None, None, text)
    area_km2 = chart.navigable_area_km2(draught_m, ukc_m)
    out_path = DEFAULT_REPORTS_DIR / f"chart-{Path(paths[0]).stem}.png" if out is None else out
    if out_path.suffix.lower() == ".gpkg":
        write_chart_geopackage(out_path, chart, draught_m, ukc_m)
        text += (
            f"Navigable water for draught {draught_m:g} m + UKC {ukc_m:g} m: {area_km2:.3f} km²\n"
        )
        text += f"GeoPackage: {out_path} (layers {', '.join(GEOPACKAGE_LAYERS)})\n"
        return ChartSummary(chart, area_km2, out_path, text)
    plot_path = out_path
    figure, ax = plt.subplots(figsize=(8, 8), layout="constrained")
    try:
        depths = draw_chart(ax, chart, draught_m, ukc_m)
        figure.colorbar(depths, ax=ax, label="DRVAL1, shallowest depth (m)", shrink=0.7)
        ax.set_xlabel("east (m)")
        ax.set_ylabel("north (m)")
        ax.set_title(
            f"{Path(paths[0]).name}: navigable water for draught {draught_m:g} m "
            f"+ UKC {ukc_m:g} m ({area_km2:.3f} km²)",
            fontsize="medium",
        )
        ax.legend(loc="lower right", fontsize="small")
        save_figure(plot_path, figure, dpi=150)
    finally:
        plt.close(figure)
    text += f"Navigable water for draught {draught_m:g} m + UKC {ukc_m:g} m: {area_km2:.3f} km²\n"
    text += f"Plot: {plot_path}\n"
    return ChartSummary(chart, area_km2, plot_path, text)
