"""Drawing charts and manoeuvrability assessments on matplotlib axes, in local-frame metres.

x is east (m), y is north (m), like the chart's geometry. The functions draw onto a given
``Axes`` so that the chart command and the replay report share them. Each collection gets a
``gid`` (``depth-areas``, ``land``, ``navigable-water``, ``not-charted``,
``restricted-ellipses``, ``clear-ellipses``, ``unknown-ellipses``) so that tests and callers
can find what was drawn.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.collections import PatchCollection
from matplotlib.colors import BoundaryNorm, ListedColormap
from matplotlib.patches import PathPatch
from matplotlib.path import Path as MplPath
from matplotlib.ticker import FuncFormatter, MaxNLocator
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

if TYPE_CHECKING:
    from ..charts.channels import Channels
    from ..charts.water import Chart
    from ..core.manoeuvrability import ManoeuvrabilityAssessment
    from ..geo import LocalFrame

LAND_COLOUR = "#d9c7a0"
WATER_EDGE_COLOUR = "#00c853"
RESTRICTED_COLOUR = "tab:red"
CLEAR_COLOUR = "tab:blue"
UNKNOWN_COLOUR = "0.5"
# The pale half of "Blues": deep water stays light enough for the blue (clear) ellipses.
DEPTH_CMAP = ListedColormap(colormaps["Blues"](np.linspace(0.0, 0.45, 256)), name="depth")
DEPTH_LABEL = "DRVAL1, shallowest depth (m)"
# Drawing order: the chart at the bottom (0-2), then the ellipses, the restricted ones above
# the clear ones, then the tracks drawn by callers (a band of ellipses must not hide them),
# and the arcs on top.
ELLIPSE_ZORDER = 3.0
RESTRICTED_ZORDER = 3.2
TRACK_ZORDER = 3.5
ARC_ZORDER = 4.0
ELLIPSE_LINEWIDTH = 0.5
# Ellipses are half transparent, so that the chart under them stays readable.
ELLIPSE_ALPHA = 0.45
# Outside the chart's coverage: grey and hatched, unlike any depth or land colour, so that
# it does not read as water too shallow to navigate.
NOT_CHARTED_COLOUR = "#e6e6e6"
NOT_CHARTED_HATCH_COLOUR = "0.55"
NOT_CHARTED_LABEL = "not charted"
# A view box: (min east, min north, max east, max north), in metres of the frame.
Bounds = tuple[float, float, float, float]


def _ring_path(coords: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    codes = np.full(len(coords), MplPath.LINETO, dtype=np.uint8)
    codes[0] = MplPath.MOVETO
    codes[-1] = MplPath.CLOSEPOLY
    return coords, codes


def polygon_path(geometry: Any) -> MplPath | None:
    """A matplotlib path (holes included) for a polygonal geometry; None when it has no area."""
    vertices: list[np.ndarray] = []
    codes: list[np.ndarray] = []
    for part in shapely.get_parts(geometry):
        if shapely.get_type_id(part) != shapely.GeometryType.POLYGON or part.is_empty:
            continue
        rings = [part.exterior, *part.interiors]
        for ring in rings:
            ring_vertices, ring_codes = _ring_path(np.asarray(ring.coords)[:, :2])
            vertices.append(ring_vertices)
            codes.append(ring_codes)
    if not vertices:
        return None
    return MplPath(np.concatenate(vertices), np.concatenate(codes))


def _patches(geometries: Iterable[Any]) -> tuple[list[PathPatch], list[int]]:
    patches, kept = [], []
    for i, geometry in enumerate(geometries):
        path = polygon_path(geometry)
        if path is not None:
            patches.append(PathPatch(path))
            kept.append(i)
    return patches, kept


# Bands shallower than the draught (+ UKC) in warm colours, deeper ones in pale blues, so that
# the water that matters stands out and the blue (clear) ellipses stay visible on it.
SHALLOW_COLOURS = ("#d6604d", "#f4a582", "#fddbc7")
DEEP_COLOURS = ("#f2f7fc", "#deebf7", "#c6dbef", "#a8cce4")
# Band edges, as multiples of the draught + UKC, from drying to deep.
BAND_MULTIPLES = (0.0, 0.5, 1.0, 1.5, 2.0, 4.0)


def depth_bands(need_m: float, drval1_m: np.ndarray) -> tuple[list[float], list[str]]:
    """Band edges (m) and colours for depth areas around ``need_m`` (draught + UKC): drying,
    below half of it, below it, then up to 1.5, 2 and 4 times it, and deeper."""
    finite = drval1_m[np.isfinite(drval1_m)]
    low = min(float(finite.min()) if finite.size else 0.0, 0.0) - 1.0
    high = max(float(finite.max()) if finite.size else 0.0, 4.0 * need_m) + 1.0
    edges = [low, *(m * need_m for m in BAND_MULTIPLES), high]
    colours = [*SHALLOW_COLOURS, *DEEP_COLOURS]
    if need_m <= 0.0:  # no draught: only drying and not drying
        return [low, 0.0, high], [SHALLOW_COLOURS[0], DEEP_COLOURS[0]]
    return edges, colours


def _in_view(geometries: Any, view: Bounds | None) -> Any:
    """The geometries cut to the view box (all at once): a figure of a harbour then draws a
    few of the chart's polygons, not every one of them."""
    return geometries if view is None else shapely.clip_by_rect(geometries, *view)


def draw_chart(
    ax: Axes,
    chart: Chart,
    draught_m: float | None,
    ukc_m: float = 0.0,
    coverage: bool = False,
    view: Bounds | None = None,
) -> Any:
    """Depth areas shaded by DRVAL1, land, and (with a draught) the navigable water outlined;
    with ``coverage``, the chart's edge (its coverage) dashed. With a draught the shading is
    in discrete bands around it (``depth_bands``), else continuous.

    With a ``view`` box, only what lies in it is drawn, the axes show exactly it, and the
    part of it outside the chart's coverage is hatched grey ("not charted"); without one,
    the axes show the whole coverage.

    Returns the depth-area collection (a ScalarMappable, for a colour bar).
    """
    patches, kept = _patches(_in_view(chart.depth_areas, view))
    drval1 = np.asarray(chart.drval1_m, dtype=float)[kept]
    if draught_m is None:
        depths = PatchCollection(patches, cmap=DEPTH_CMAP, edgecolor="none", zorder=0)
    else:
        bands, colours = depth_bands(draught_m + ukc_m, drval1)
        depths = PatchCollection(
            patches,
            cmap=ListedColormap(colours, name="depth-bands"),
            norm=BoundaryNorm(bands, len(colours)),
            edgecolor="none",
            zorder=0,
        )
    depths.set_array(drval1)
    depths.set_gid("depth-areas")
    ax.add_collection(depths)
    land_patches, _ = _patches([_in_view(chart.land, view)])
    land = PatchCollection(
        land_patches, facecolor=LAND_COLOUR, edgecolor="0.4", linewidth=0.3, zorder=1
    )
    land.set_gid("land")
    ax.add_collection(land)
    if draught_m is not None:
        water_patches, _ = _patches([_in_view(chart.navigable_water(draught_m, ukc_m), view)])
        water = PatchCollection(
            water_patches,
            # Outlined, not filled: a tint would shift the depth colours off the colour bar.
            facecolor="none",
            edgecolor=WATER_EDGE_COLOUR,
            linewidth=1.8,
            zorder=2,
        )
        water.set_gid("navigable-water")
        water.set_label(f"navigable for draught {draught_m:g} m + UKC {ukc_m:g} m")
        ax.add_collection(water)
    if coverage:
        edge_patches, _ = _patches([chart.coverage])
        edge = PatchCollection(
            edge_patches,
            facecolor="none",
            edgecolor="0.15",
            linestyle="--",
            linewidth=1.0,
            zorder=2,
        )
        edge.set_gid("coverage")
        edge.set_label("chart edge (coverage): beyond it unknown")
        ax.add_collection(edge)
    if view is None:
        min_east, min_north, max_east, max_north = shapely.bounds(chart.coverage)
        ax.update_datalim([(min_east, min_north), (max_east, max_north)])
        ax.autoscale_view()
        ax.set_aspect("equal", adjustable="datalim")
        return depths
    _draw_not_charted(ax, shapely.difference(shapely.box(*view), chart.coverage))
    show_view(ax, view)
    return depths


def _draw_not_charted(ax: Axes, outside: Any) -> None:
    patches, _ = _patches([outside])
    if not patches:
        return
    not_charted = PatchCollection(
        patches,
        facecolor=NOT_CHARTED_COLOUR,
        edgecolor=NOT_CHARTED_HATCH_COLOUR,
        hatch="///",
        linewidth=0.0,
        zorder=1.5,
    )
    not_charted.set_gid("not-charted")
    not_charted.set_label(NOT_CHARTED_LABEL)
    ax.add_collection(not_charted)


def show_view(ax: Axes, view: Bounds) -> None:
    """Show exactly the view box, at one scale in east and north."""
    min_east, min_north, max_east, max_north = view
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlim(min_east, max_east)
    ax.set_ylim(min_north, max_north)


def draw_assessment(ax: Axes, assessment: ManoeuvrabilityAssessment, every: int = 1) -> None:
    """Both arcs, and each comfort zone red (restricted), blue (clear) or grey (off the chart).

    With ``every`` > 1, only every ``every``-th clear or grey outline along each arc is drawn
    (every red one is): a hundred overlapping outlines add up to an opaque band.
    """
    for arc, style in (("cw", "-"), ("ccw", "--")):
        on_arc = assessment.arc == arc
        ax.plot(
            assessment.east_m[on_arc],
            assessment.north_m[on_arc],
            style,
            color="black",
            linewidth=0.8,
            zorder=ARC_ZORDER,
            label=f"{arc} arc",
        )
    restricted = assessment.restricted & assessment.covered
    sampled = assessment.step % every == 0
    thinned = f" (1 in {every} drawn)" if every > 1 else ""
    groups = (
        ("restricted", restricted, RESTRICTED_COLOUR, RESTRICTED_ZORDER, ""),
        (
            "clear",
            ~assessment.restricted & assessment.covered & sampled,
            CLEAR_COLOUR,
            ELLIPSE_ZORDER,
            thinned,
        ),
        ("unknown", ~assessment.covered & sampled, UNKNOWN_COLOUR, ELLIPSE_ZORDER, thinned),
    )
    for state, selected, colour, zorder, note in groups:
        if not selected.any():
            continue
        patches, _ = _patches(assessment.ellipses[selected])
        ellipses = PatchCollection(
            patches,
            facecolor="none",
            edgecolor=colour,
            linewidth=ELLIPSE_LINEWIDTH,
            alpha=ELLIPSE_ALPHA,
            zorder=zorder,
        )
        ellipses.set_gid(f"{state}-ellipses")
        ellipses.set_label(f"{state} ellipses{note}")
        ax.add_collection(ellipses)


def geographic_axes(ax: Axes, frame: LocalFrame) -> None:
    """Label the axes of a local-frame plot in latitude and longitude (read at the middle of
    the view: exact there, and within a small fraction of a tick across a harbour-sized
    view) and add a scale bar, so that the metres of the frame never reach the reader."""
    (x_low, x_high), (y_low, y_high) = ax.get_xlim(), ax.get_ylim()
    middle_east, middle_north = (x_low + x_high) / 2.0, (y_low + y_high) / 2.0

    def longitude(east_m: float, _: int) -> str:
        lon = frame.to_geodetic(middle_north, east_m)[1]
        return f"{abs(float(lon)):.4f}°{'E' if lon >= 0 else 'W'}"

    def latitude(north_m: float, _: int) -> str:
        lat = frame.to_geodetic(north_m, middle_east)[0]
        return f"{abs(float(lat)):.4f}°{'N' if lat >= 0 else 'S'}"

    ax.xaxis.set_major_formatter(FuncFormatter(longitude))
    ax.yaxis.set_major_formatter(FuncFormatter(latitude))
    ax.xaxis.set_major_locator(MaxNLocator(nbins=5))
    ax.yaxis.set_major_locator(MaxNLocator(nbins=6))
    ax.tick_params(axis="x", labelrotation=20)
    ax.set_xlabel("longitude")
    ax.set_ylabel("latitude")
    length_m = _round_length(0.25 * (x_high - x_low))
    label = f"{length_m / 1000:g} km" if length_m >= 1000 else f"{length_m:g} m"
    bar = AnchoredSizeBar(
        ax.transData, length_m, label, "lower left", pad=0.4, frameon=True, size_vertical=0
    )
    bar.set_gid("scale-bar")
    ax.add_artist(bar)


def _round_length(length_m: float) -> float:
    """1, 2 or 5 times a power of ten, at most ``length_m``."""
    power = 10.0 ** np.floor(np.log10(max(length_m, 1.0)))
    return float(max(m * power for m in (1.0, 2.0, 5.0) if m * power <= max(length_m, 1.0)))


CHANNEL_COLOUR = "tab:purple"
CHANNEL_LABEL = "charted channel"
CHANNEL_AXIS_LABEL = "channel axis"


def draw_channels(
    ax: Axes, channels: Channels, view: Bounds | None = None, named: Iterable[str] = ()
) -> None:
    """The charted channel areas in the view, outlined, and the axes of those ``named`` (the
    channels the vessels were in), dash-dotted: where rule 9's "narrow channel or fairway"
    lies, and what "along" and "starboard side" are measured against (``charts.channels``)."""
    wanted = set(named)
    areas = [c.geometry for c in channels if c.is_area]
    axes = [c.axis for c in channels if c.is_area and c.label in wanted]
    if not areas:
        return
    clipped = _in_view(np.asarray(areas, dtype=object), view)
    patches, _ = _patches(clipped)
    if patches:
        ax.add_collection(
            PatchCollection(
                patches,
                facecolor="none",
                edgecolor=CHANNEL_COLOUR,
                linewidth=0.8,
                linestyle="--",
                zorder=2.2,
            )
        )
        ax.plot([], [], color=CHANNEL_COLOUR, lw=0.8, ls="--", label=CHANNEL_LABEL)
    shown = False
    if not axes:
        return
    for line in shapely.get_parts(_in_view(np.asarray(axes, dtype=object), view)):
        if shapely.get_type_id(line) != shapely.GeometryType.LINESTRING or line.is_empty:
            continue
        east, north = np.asarray(line.coords)[:, 0], np.asarray(line.coords)[:, 1]
        ax.plot(east, north, color=CHANNEL_COLOUR, lw=0.7, ls="-.", zorder=2.2)
        shown = True
    if shown:
        ax.plot([], [], color=CHANNEL_COLOUR, lw=0.7, ls="-.", label=CHANNEL_AXIS_LABEL)
