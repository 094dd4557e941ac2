"""Charts: depth areas, land and hazards in the run's local frame, and the navigable water.

Geometry convention: every shapely geometry of a ``Chart`` is in the local frame of
``colregs9_cli.geo.LocalFrame`` with **x = east_m and y = north_m**. Functions that take
positions take them as ``(north_m, east_m)``, like the rest of the package.

A hazard (OBSTRN, WRECKS, UWTROC: ``s57_classes``), and a land area charted as a point or
line, is buffered by ``HAZARD_RADIUS_M``. A hazard blocks a vessel when its sounding
``VALSOU`` is shallower than draught + UKC, or when it has no sounding (unknown depth is
treated as dangerous, as ECDIS does).

Navigable water for draught T is the union of depth areas with ``DRVAL1 >= T + UKC``, minus
land and structures, with gaps narrower than ``SLIVER_TOLERANCE_M`` closed (see there), minus
the blocking hazards.

A position outside the coverage (the charted extent: ``sources``) is "unknown", never "deep",
and so is a ship domain that is not wholly inside it (``Chart.covers_shapes``).

The charts are read (``read``, ``cells``) and ranked by detail (``sources``) before
``project_charts`` merges them into one ``Chart`` in one frame; ``load_chart`` does it all.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from ..errors import ChartError, ParameterError
from ..geo import FRAME_REACH_M, LocalFrame
from .cells import CellInfo
from .s57_classes import OBJECT_CLASSES, POLYGONAL, ChartLayer
from .sources import ChartSource, by_detail, claimed_by_detail, read_charts

HAZARD_RADIUS_M = 10.0
# Depth areas that should meet often leave slivers of gap between them (or of land filling the
# gap) once a chart has been converted between coordinate systems or rounded: an edge that is
# one segment in one area and two in its neighbour does not stay straight under a projection.
# Millimetres to centimetres wide, they would punch spurious holes into the navigable water and
# make any ellipse over them "restricted". Gaps narrower than this are closed; nothing a vessel
# could be stopped by is that narrow.
SLIVER_TOLERANCE_M = 0.1


@dataclass(frozen=True)
class WaterIndex:
    """Navigable water for one (draught, UKC), prepared, with its prepared boundary."""

    water: Any
    boundary: Any


@dataclass(frozen=True)
class Chart:
    """Depth areas, land and hazards of one or more charts, in the local frame (x east, y north).

    ``hazard_areas``/``hazard_depth_m`` hold each buffered hazard and its sounding (NaN when
    unknown); ``hazards`` is their union. A chart built without the per-hazard arrays treats
    every hazard as blocking. ``detail_order`` lists the chart files most detailed first: where
    they overlap, the first one covering a place decides its depths; ``coverage_by_chart`` is
    the part of the coverage each of them decides, and ``depth_chart`` the index (into
    ``detail_order``) of the file each depth area comes from.
    """

    frame: LocalFrame
    depth_areas: NDArray[np.object_]
    drval1_m: NDArray[np.float64]
    drval2_m: NDArray[np.float64]
    kinds: NDArray[np.object_]
    land: Any
    hazards: Any
    coverage: Any
    sources: tuple[Path, ...] = ()
    cells: tuple[CellInfo, ...] = ()
    detail_order: tuple[Path, ...] = ()
    coverage_by_chart: tuple[Any, ...] = ()
    depth_chart: NDArray[np.int64] = field(default_factory=lambda: np.empty(0, dtype=np.int64))
    layer_counts: Mapping[str, int] = field(default_factory=dict)
    hazard_areas: NDArray[np.object_] = field(default_factory=lambda: np.empty(0, dtype=object))
    hazard_depth_m: NDArray[np.float64] = field(default_factory=lambda: np.empty(0))
    _water: dict[tuple[float, float], WaterIndex] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )
    _coverage_boundary: Any = field(default=None, init=False, repr=False, compare=False)
    # The charted channels (``channels.load_channels``), read once and carried with the
    # chart to the workers that draw its figures.
    _channels: Any = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        shapely.prepare(self.coverage)
        coverage_boundary = shapely.boundary(self.coverage)
        shapely.prepare(coverage_boundary)
        object.__setattr__(self, "_coverage_boundary", coverage_boundary)

    def water_index(self, draught_m: float, ukc_m: float = 0.0) -> WaterIndex:
        """The prepared navigable water and its boundary, built once per (draught, UKC)."""
        if not (np.isfinite(draught_m) and draught_m >= 0.0):
            raise ParameterError(f"draught {draught_m} m is negative; give a draught >= 0")
        if not (np.isfinite(ukc_m) and ukc_m >= 0.0):
            raise ParameterError(f"under-keel clearance {ukc_m} m is negative; give a UKC >= 0")
        key = (float(draught_m), float(ukc_m))
        if key not in self._water:
            # To the micrometre: 8.8 + 0.3 is 9.100000000000001 in binary, which left out
            # the areas charted exactly 9.1 m deep.
            required_m = round(draught_m + ukc_m, 6)
            deep = shapely.union_all(self.depth_areas[self.drval1_m >= required_m])
            # Depth areas outside a cell's stated coverage (M_COVR) are not charted water;
            # the seams the coverage may share with them are closed after.
            charted = shapely.intersection(shapely.difference(deep, self.land), self.coverage)
            water = _close_slivers(charted)
            blocking = self._blocking_hazards(required_m)
            if not shapely.is_empty(blocking):
                water = shapely.difference(water, blocking)
            boundary = shapely.boundary(water)
            shapely.prepare(water)
            shapely.prepare(boundary)
            self._water[key] = WaterIndex(water, boundary)
        return self._water[key]

    def navigable_water(self, draught_m: float, ukc_m: float = 0.0) -> Any:
        """Water at least ``draught_m + ukc_m`` deep, minus land and blocking hazards (prepared)."""
        return self.water_index(draught_m, ukc_m).water

    def covers(self, north_m: ArrayLike, east_m: ArrayLike) -> NDArray[np.bool_]:
        """True where a local-frame position lies inside the charted extent (boundary included)."""
        return np.atleast_1d(
            np.asarray(
                shapely.intersects_xy(
                    self.coverage,
                    np.asarray(east_m, dtype=float),
                    np.asarray(north_m, dtype=float),
                ),
                dtype=bool,
            )
        )

    def covers_shapes(
        self, north_m: NDArray[np.float64], east_m: NDArray[np.float64], shapes: Any, reach_m: float
    ) -> NDArray[np.bool_]:
        """True where a shape lies wholly inside the charted extent, not touching its edge: the
        edge of a chart is not the edge of the water, so a shape that touches or crosses it is
        neither red nor blue. ``shapes`` is called with the indices of the positions within
        ``reach_m`` (the shapes' largest extent from their position) of the extent's boundary
        and returns their polygons; the others are decided by their position alone."""
        covered = self.covers(north_m, east_m)
        near = np.flatnonzero(
            covered
            & np.asarray(
                shapely.dwithin(
                    self._coverage_boundary,
                    shapely.points(np.column_stack([east_m, north_m])),
                    reach_m,
                ),
                dtype=bool,
            )
        )
        if len(near):
            covered[near] = shapely.contains_properly(self.coverage, shapes(near))
        return covered

    def covers_disk(self, north_m: float, east_m: float, radius_m: float) -> bool:
        """Whether every point within ``radius_m`` of the position lies inside the extent."""
        return bool(self.covers(north_m, east_m)[0]) and not bool(
            shapely.dwithin(self._coverage_boundary, shapely.Point(east_m, north_m), radius_m)
        )

    @property
    def update_gaps(self) -> dict[str, tuple[str, ...]]:
        """The update files missing from each cell read with a gap accepted, by cell name."""
        return {cell.name: cell.missing_updates for cell in self.cells if cell.missing_updates}

    def navigable_area_km2(self, draught_m: float, ukc_m: float = 0.0) -> float:
        return float(shapely.area(self.navigable_water(draught_m, ukc_m))) / 1e6

    def depth_range_m(self) -> tuple[float, float]:
        """The smallest and largest DRVAL1 over the depth areas."""
        return float(np.nanmin(self.drval1_m)), float(np.nanmax(self.drval1_m))

    def bounds_wgs84(self) -> tuple[float, float, float, float]:
        """(lat_min, lat_max, lon_min, lon_max) of the charted extent."""

        def east_north_to_lonlat(xy: NDArray[np.float64]) -> NDArray[np.float64]:
            lat_deg, lon_deg = self.frame.to_geodetic(xy[:, 1], xy[:, 0])
            return np.column_stack([lon_deg, lat_deg])

        lon_min, lat_min, lon_max, lat_max = shapely.bounds(
            shapely.transform(self.coverage, east_north_to_lonlat)
        )
        return float(lat_min), float(lat_max), float(lon_min), float(lon_max)

    def _blocking_hazards(self, required_m: float) -> Any:
        if len(self.hazard_areas) == 0:
            return self.hazards
        blocking = np.isnan(self.hazard_depth_m) | (self.hazard_depth_m < required_m)
        return shapely.union_all(self.hazard_areas[blocking])


def _close_slivers(water: Any) -> Any:
    """``water`` with gaps and holes narrower than ``SLIVER_TOLERANCE_M`` closed.

    A morphological closing (grow by half the tolerance, shrink back) with mitred joins, so
    corners stay sharp and the rest of the outline does not move.
    """
    half_m = SLIVER_TOLERANCE_M / 2.0
    grown = shapely.buffer(water, half_m, join_style="mitre", mitre_limit=10.0)
    return shapely.buffer(grown, -half_m, join_style="mitre", mitre_limit=10.0)


def load_chart(
    paths: Sequence[Path], frame: LocalFrame | None = None, accept_gaps: bool = False
) -> Chart:
    """Read and merge charts, project them into ``frame`` (default: centred on their extent)."""
    return project_charts(read_charts(paths, accept_gaps), frame)


def _check_within_reach(source: ChartSource, frame: LocalFrame) -> None:
    """Charts are projected into one transverse Mercator frame, true to 0.2 % within
    ``FRAME_REACH_M`` of its centre; beyond, areas and ship domains would be stretched.
    Every vertex is checked, so that charts on both sides of 180° are judged as the frame
    (centred the short way round) sees them."""
    lon_lat = shapely.get_coordinates(np.concatenate([f.shapes() for f in source.features]))
    if frame.within_reach(lon_lat[:, 1], lon_lat[:, 0]).all():
        return
    lat_min, lat_max, lon_min, lon_max = source.bounds_wgs84()
    names = ", ".join(str(p) for p in source.paths)
    raise ChartError(
        f"{names}: the charts span lat {lat_min:.2f} .. {lat_max:.2f}, lon {lon_min:.2f} .. "
        f"{lon_max:.2f}, beyond {FRAME_REACH_M / 1000:.0f} km of the centre of the one map "
        "frame they are projected into, which would stretch their areas and the ship domains; "
        "give charts that lie within that of their centre (the cells of one area at a time: "
        "replay leaves out charts away from the AIS)"
    )


def project_charts(source: ChartSource, frame: LocalFrame | None = None) -> Chart:
    """Merge charts already read and project them into ``frame`` (default: their extent).

    Where charts overlap, the most detailed one decides (``by_detail``): a union of the
    deep areas of two cells would take the deeper of two disagreeing soundings.
    """
    features = by_detail(source.features)
    if frame is None:
        frame = LocalFrame.centred_on(*source.bounds_wgs84())
    _check_within_reach(source, frame)
    per_file, coverages = claimed_by_detail(features, frame)
    geometries = np.concatenate(per_file)
    object_class = np.concatenate([f.object_class for f in features])
    drval1 = np.concatenate([f.drval1_m for f in features])
    drval2 = np.concatenate([f.drval2_m for f in features])
    valsou = np.concatenate([f.valsou_m for f in features])
    chart_index = np.concatenate(
        [np.full(len(g), i, dtype=np.int64) for i, g in enumerate(per_file)]
    )
    present = ~shapely.is_empty(geometries)
    geometries, object_class = geometries[present], object_class[present]
    drval1, drval2, valsou = drval1[present], drval2[present], valsou[present]
    chart_index = chart_index[present]
    role = np.asarray([OBJECT_CLASSES[c][1] for c in object_class], dtype=object)
    polygonal = np.isin(shapely.get_type_id(geometries), POLYGONAL)

    depth = np.isin(role, [ChartLayer.DEPARE, ChartLayer.DRGARE]) & polygonal
    if not depth.any():
        names = ", ".join(str(f.path) for f in features)
        raise ChartError(
            f"{names}: no depth area is left where each chart decides (a more detailed chart's "
            "coverage holds none); give charts with depth areas inside their coverage"
        )
    land_areas = (role == ChartLayer.LNDARE) & polygonal
    # Land charted as a point or line (an islet, a pier) is a hazard at any depth.
    small_land = (role == ChartLayer.LNDARE) & ~polygonal
    hazard = (role == ChartLayer.HAZARD) | small_land
    hazard_depth = np.where(small_land, -np.inf, valsou)[hazard]
    hazard_areas = shapely.buffer(geometries[hazard], HAZARD_RADIUS_M)

    land = shapely.union_all(geometries[land_areas])
    coverage = shapely.union_all(np.asarray(coverages, dtype=object))
    counts: dict[str, int] = {}
    for name in object_class:
        counts[str(name)] = counts.get(str(name), 0) + 1
    return Chart(
        frame=frame,
        depth_areas=geometries[depth],
        drval1_m=drval1[depth],
        drval2_m=drval2[depth],
        kinds=role[depth],
        land=land,
        hazards=shapely.union_all(hazard_areas),
        coverage=coverage,
        sources=source.paths,
        cells=source.cells,
        detail_order=tuple(f.path for f in features),
        coverage_by_chart=tuple(coverages),
        depth_chart=chart_index[depth],
        layer_counts={name: counts[name] for name in OBJECT_CLASSES if name in counts},
        hazard_areas=hazard_areas,
        hazard_depth_m=hazard_depth,
    )
