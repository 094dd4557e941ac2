"""Charted channels: fairways, dredged areas, deep-water routes, traffic separation schemes
and recommended tracks, with an axis each, in the run's frame.

What is read: every object of ``s57_classes.CHANNEL_CLASSES`` in the chart's files
(``channel_read``), with its name (``OBJNAM``), record id (``LNAM``, the S-57 feature object
identifier) and attributes. Geometry convention as ``water``: shapely geometries in the
chart's ``LocalFrame`` with **x = east_m and y = north_m**; functions take positions as
``(north_m, east_m)``. Directions along the axis are *grid* directions of that frame
(``true − γ``, as the tracks' ``cog_grid_deg``); the listed ``axis_deg`` and ``orient_deg``
are true, as charted.

Precedence: where charts overlap, a channel object of a file counts only inside the part of
the coverage that file decides for the depth areas (``Chart.coverage_by_chart``, ranked by
``sources.by_detail``: navigational purpose, then compilation scale, then the order
given); the same object charted in a coarser cell is cut away there. Within that, a position
lying in several channel areas is in the first of them by kind — TSS lane, separation zone,
deep-water route, fairway, dredged area (the dredged quarters of a fairway lie inside it) —
then by the smaller area (the more particular), then by the order read.

The axis (``channel_axis``): a charted ``ORIENT`` where the area has one, else a centreline
derived from the polygon. A line object (track, navigation line, separation line, scheme
boundary) is its own axis. A recommended track does not replace an area's axis: it need not
run down the middle (it may lead past a shoal or mark one half of a one-way pair), and rule
9(a) measures from the channel's own limits. The tracks that run along an area (inside it
for at least half its or their length, within ``TRACK_ALONG_DEG`` of its local axis) are
listed with it (``Channel.tracks``) for a stage that wants a charted direction.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from ..errors import ParameterError
from ..geo import LocalFrame
from ..units import wrap_deg
from .channel_axis import centreline, orient_axis
from .channel_read import ChannelFeatures, read_channel_features
from .s57_classes import AREA_CHANNEL_KINDS, CHANNEL_CLASSES, POLYGONAL, ChannelKind
from .sources import project_file, same_dimension
from .water import Chart

# A track runs along an area channel when its direction stays within this of the area's
# local axis (the median over points a width apart).
TRACK_ALONG_DEG = 15.0
# Which area a position is in where several overlap: first kind first (module docstring).
KIND_PRECEDENCE = (
    ChannelKind.TSS_LANE,
    ChannelKind.TSS_ZONE,
    ChannelKind.DEEP_WATER_ROUTE,
    ChannelKind.FAIRWAY,
    ChannelKind.DREDGED_AREA,
)
# The local axis direction is the chord over this fraction of the channel's mean width either
# side of the nearest axis point (at least _MIN_WINDOW_M): it follows a bend, not a step.
_WINDOW_OF_WIDTH = 0.5
_MIN_WINDOW_M = 10.0
_LINE_TYPES = (shapely.GeometryType.LINESTRING, shapely.GeometryType.MULTILINESTRING)
# Channel areas whose sections end within this of each other share an edge: one channel.
_TOUCHING_M = 1e-3


class Traffic(StrEnum):
    """S-57 ``TRAFIC``: the traffic flow charted."""

    INBOUND = "inbound"
    OUTBOUND = "outbound"
    ONE_WAY = "one-way"
    TWO_WAY = "two-way"


_TRAFFIC_BY_CODE = {1: Traffic.INBOUND, 2: Traffic.OUTBOUND, 3: Traffic.ONE_WAY, 4: Traffic.TWO_WAY}


class AxisSource(StrEnum):
    """Where a channel's axis comes from."""

    ORIENT = "ORIENT"  # the charted orientation
    CENTRELINE = "centreline"  # derived from the area (channel_axis)
    LINE = "line"  # a line object is its own axis


@dataclass(frozen=True)
class Channel:
    """One charted routeing object in the run's frame (x east, y north).

    ``axis_deg`` is true: the charted ``ORIENT`` where there is one, else the direction from
    one end of the axis to the other, in [0, 180) (an axis without a charted direction runs
    both ways). ``length_m`` is the axis's length and ``width_m`` an area's mean width (its
    area over that length; None for lines). ``category`` is ``CATTRK`` for a recommended
    track and ``CATNAV`` for a navigation line (3: a leading line bearing a track).
    """

    kind: ChannelKind
    object_class: str
    name: str | None
    record_id: str
    chart: str
    geometry: Any
    axis: Any
    axis_source: AxisSource
    axis_deg: float
    length_m: float
    width_m: float | None = None
    orient_deg: float | None = None
    traffic: Traffic | None = None
    depth_m: float | None = None  # DRVAL1, the least depth
    depth_max_m: float | None = None  # DRVAL2
    category: int | None = None
    tracks: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        """The name, else the class and the record id."""
        return self.name or f"{self.object_class} {self.record_id}"

    @property
    def is_area(self) -> bool:
        return self.kind in AREA_CHANNEL_KINDS

    @property
    def one_way(self) -> bool:
        """For traffic one way, in the direction of its ``ORIENT``: a traffic separation lane
        (rule 10(b)(i)), or an object whose ``TRAFIC`` says so."""
        if self.orient_deg is None:
            return False
        return self.kind is ChannelKind.TSS_LANE or self.traffic in (
            Traffic.INBOUND,
            Traffic.OUTBOUND,
            Traffic.ONE_WAY,
        )

    @property
    def bears_track(self) -> bool:
        """A recommended track, or a navigation line that is a leading line bearing one."""
        return self.kind is ChannelKind.RECOMMENDED_TRACK or (
            self.kind is ChannelKind.NAVIGATION_LINE and self.category == 3
        )


def make_channel(
    frame: LocalFrame,
    kind: ChannelKind,
    geometry: Any,
    *,
    record_id: str,
    name: str | None = None,
    chart: str = "",
    orient_deg: float | None = None,
    traffic: Traffic | None = None,
    depth_m: float | None = None,
    depth_max_m: float | None = None,
    category: int | None = None,
) -> Channel | None:
    """A channel from its geometry in the frame, with its axis; None when the geometry has
    no part of the kind's dimension (an area reduced to a line by clipping, say)."""
    object_class = next(c for c, (_, k) in CHANNEL_CLASSES.items() if k is kind)
    area = kind in AREA_CHANNEL_KINDS
    parts = shapely.get_parts(geometry)
    parts = parts[
        np.isin(shapely.get_type_id(parts), POLYGONAL if area else _LINE_TYPES)
        & ~shapely.is_empty(parts)
    ]
    if len(parts) == 0:
        return None
    geometry = shapely.union_all(parts) if area else shapely.line_merge(shapely.union_all(parts))
    east_m, north_m = shapely.centroid(geometry).coords[0]
    lat_deg, lon_deg = frame.to_geodetic(north_m, east_m)
    if not area:
        axis, source = geometry, AxisSource.LINE
    elif orient_deg is not None:
        grid_deg = float(frame.true_to_grid_deg(orient_deg, lat_deg, lon_deg))
        axis, source = orient_axis(geometry, grid_deg), AxisSource.ORIENT
    else:
        axis, source = centreline(geometry), AxisSource.CENTRELINE
    length_m = float(shapely.length(axis))
    if orient_deg is not None:
        axis_deg = float(wrap_deg(orient_deg))
    else:
        axis_deg = float(frame.grid_to_true_deg(_end_to_end_grid_deg(axis), lat_deg, lon_deg)) % 180
    return Channel(
        kind=kind,
        object_class=object_class,
        name=name,
        record_id=record_id,
        chart=chart,
        geometry=geometry,
        axis=axis,
        axis_source=source,
        axis_deg=axis_deg,
        length_m=length_m,
        width_m=float(shapely.area(geometry)) / length_m if area and length_m > 0 else None,
        orient_deg=None if orient_deg is None else float(orient_deg),
        traffic=traffic,
        depth_m=depth_m,
        depth_max_m=depth_max_m,
        category=category,
    )


def _end_to_end_grid_deg(axis: Any) -> float:
    """The grid direction from the first to the last point of the axis's longest part; NaN
    for an axis of no length (a sliver of an area)."""
    parts = shapely.get_parts(axis)
    if len(parts) == 0 or shapely.length(axis) == 0.0:
        return float("nan")
    xy = shapely.get_coordinates(parts[int(np.argmax(shapely.length(parts)))])
    east_m, north_m = xy[-1] - xy[0]
    return float(np.degrees(np.arctan2(east_m, north_m)) % 360.0)


@dataclass(frozen=True)
class AxisPoints:
    """For each queried position, the nearest point of its channel's axis (``foot_*``), the
    axis's local grid direction there (in the sense the axis line runs) and the position's
    signed distance across it, positive to the right of that direction. NaN where the
    position is in no channel."""

    direction_grid_deg: NDArray[np.float64]
    foot_north_m: NDArray[np.float64]
    foot_east_m: NDArray[np.float64]
    across_m: NDArray[np.float64]


@dataclass(frozen=True)
class Sections:
    """The cross-section of the channel through each queried position, square to a given
    direction: the distance to its limit on the left and on the right of that direction,
    and its width. NaN where the position is not in the channel (or not in its navigable
    part, for a draught)."""

    left_m: NDArray[np.float64]
    right_m: NDArray[np.float64]

    @property
    def width_m(self) -> NDArray[np.float64]:
        return self.left_m + self.right_m


@dataclass(frozen=True)
class Channels:
    """The charted channels of a chart, with a spatial index of the areas.

    ``items`` are the channels; an index into it is how a position's channel is named
    (``channel_at``: -1 for none). ``chart`` is the chart they were read from, whose
    navigable water gives the width for a draught.
    """

    frame: LocalFrame
    items: tuple[Channel, ...]
    chart: Chart | None = field(default=None, repr=False, compare=False)
    _areas: NDArray[np.int64] = field(init=False, repr=False, compare=False)
    _tree: shapely.STRtree = field(init=False, repr=False, compare=False)
    _parts: NDArray[np.object_] = field(init=False, repr=False, compare=False)
    _first_part: NDArray[np.int64] = field(init=False, repr=False, compare=False)
    _part_count: NDArray[np.int64] = field(init=False, repr=False, compare=False)
    _window_m: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    _reach_m: NDArray[np.float64] = field(init=False, repr=False, compare=False)
    _water: dict[tuple[float, float], NDArray[np.object_]] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        rank = {kind: i for i, kind in enumerate(KIND_PRECEDENCE)}
        areas = [i for i, c in enumerate(self.items) if c.is_area]
        areas.sort(key=lambda i: (rank[self.items[i].kind], self.items[i].geometry.area, i))
        geometries = np.asarray([c.geometry for c in self.items], dtype=object)
        object.__setattr__(self, "_areas", np.asarray(areas, dtype=np.int64))
        object.__setattr__(self, "_tree", shapely.STRtree(geometries[areas]))
        parts, owner = shapely.get_parts(
            np.asarray([c.axis for c in self.items], dtype=object), return_index=True
        )
        counts = np.bincount(owner, minlength=len(self.items)).astype(np.int64)
        object.__setattr__(self, "_parts", parts)
        object.__setattr__(self, "_part_count", counts)
        object.__setattr__(self, "_first_part", np.cumsum(counts) - counts)
        widths = np.asarray([c.width_m or 0.0 for c in self.items], dtype=float)
        object.__setattr__(self, "_window_m", np.maximum(widths * _WINDOW_OF_WIDTH, _MIN_WINDOW_M))
        bounds = shapely.bounds(geometries) if len(geometries) else np.empty((0, 4))
        reach = np.hypot(bounds[:, 2] - bounds[:, 0], bounds[:, 3] - bounds[:, 1]) + 1.0
        object.__setattr__(self, "_reach_m", reach)

    def __len__(self) -> int:
        return len(self.items)

    def __iter__(self) -> Iterator[Channel]:
        return iter(self.items)

    def __getitem__(self, index: int) -> Channel:
        return self.items[index]

    def section_limits(
        self, centre_xy: NDArray[np.float64], right_unit: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """For each point (x = east, y = north) and the unit vector to its right, how far to
        its left and to its right the channel areas run along the line square to its
        direction, the areas it meets side by side joined (a cut charted as two one-way
        fairways, a dredged centre between dredged toes: one channel to be confined to).
        NaN where the point is in no channel area."""
        left, right = np.full(len(centre_xy), np.nan), np.full(len(centre_xy), np.nan)
        reach = np.full(len(centre_xy), float(self._reach_m.max(initial=1.0)))
        lines = section_lines(centre_xy, right_unit, (reach, reach))
        line_of_pair, area_rank = self._tree.query(lines, predicate="intersects")
        areas = self._tree.geometries  # the areas, in their rank's order
        pieces, pair = shapely.get_parts(
            shapely.intersection(lines[line_of_pair], areas[area_rank]), return_index=True
        )
        straight = np.isin(shapely.get_type_id(pieces), _LINE_TYPES)
        pieces, line = pieces[straight], line_of_pair[pair[straight]]
        ends = np.stack(
            [
                shapely.get_coordinates(shapely.get_point(pieces, 0)),
                shapely.get_coordinates(shapely.get_point(pieces, -1)),
            ],
            axis=1,
        )
        along = np.einsum("kij,kj->ki", ends - centre_xy[line][:, None, :], right_unit[line])
        starts_m, stops_m = along.min(axis=1), along.max(axis=1)
        for point in np.unique(line).tolist():
            mine = line == point
            span = _span_holding_zero(starts_m[mine], stops_m[mine])
            if span is not None:
                left[point], right[point] = max(-span[0], 0.0), max(span[1], 0.0)
        return left, right

    def labels(self, index: ArrayLike) -> list[str | None]:
        """The label of each indexed channel, None for -1."""
        return [None if i < 0 else self.items[i].label for i in np.asarray(index).tolist()]

    def channel_at(
        self,
        north_m: ArrayLike,
        east_m: ArrayLike,
        kinds: frozenset[ChannelKind] = AREA_CHANNEL_KINDS,
    ) -> NDArray[np.int64]:
        """The index of the channel area each position lies in (boundary included), by the
        precedence of the module docstring; -1 where it is in none of ``kinds``."""
        north, east = _points_xy(north_m, east_m)
        out = np.full(len(north), -1, dtype=np.int64)
        if len(self._areas) == 0 or len(north) == 0:
            return out
        points = shapely.points(np.column_stack([east, north]))
        point_index, area_rank = self._tree.query(points, predicate="intersects")
        wanted = np.asarray([self.items[i].kind in kinds for i in self._areas], dtype=bool)
        keep = wanted[area_rank]
        point_index, area_rank = point_index[keep], area_rank[keep]
        best = np.full(len(north), len(self._areas), dtype=np.int64)
        np.minimum.at(best, point_index, area_rank)
        found = best < len(self._areas)
        out[found] = self._areas[best[found]]
        return out

    def axis_at(self, north_m: ArrayLike, east_m: ArrayLike, index: ArrayLike) -> AxisPoints:
        """The nearest axis point of channel ``index[i]`` to each position, the axis's local
        direction there (the chord over half a mean width either side, so a bend gives the
        bend's direction) and the distance across it (``AxisPoints``)."""
        north, east = _points_xy(north_m, east_m)
        index = np.broadcast_to(np.asarray(index, dtype=np.int64), north.shape)
        n = len(north)
        direction, foot_n, foot_e, across = (np.full(n, np.nan) for _ in range(4))
        part = self._nearest_parts(north, east, index)
        q = np.flatnonzero(part >= 0)
        if len(q) == 0:
            return AxisPoints(direction, foot_n, foot_e, across)
        lines = self._parts[part[q]]
        points = shapely.points(np.column_stack([east[q], north[q]]))
        length = shapely.length(lines)
        at = shapely.line_locate_point(lines, points)
        window = self._window_m[index[q]]
        before = shapely.get_coordinates(
            shapely.line_interpolate_point(lines, np.clip(at - window, 0.0, length))
        )
        after = shapely.get_coordinates(
            shapely.line_interpolate_point(lines, np.clip(at + window, 0.0, length))
        )
        foot = shapely.get_coordinates(shapely.line_interpolate_point(lines, at))
        chord = after - before
        norm = np.hypot(chord[:, 0], chord[:, 1])
        with np.errstate(invalid="ignore", divide="ignore"):
            unit = chord / norm[:, None]
        direction[q] = np.where(
            norm > 0, np.degrees(np.arctan2(unit[:, 0], unit[:, 1])) % 360, np.nan
        )
        foot_e[q], foot_n[q] = foot[:, 0], foot[:, 1]
        # Right of (e, n) is (n, -e): the offset's component along it.
        offset = np.column_stack([east[q], north[q]]) - foot
        across[q] = offset[:, 0] * unit[:, 1] - offset[:, 1] * unit[:, 0]
        return AxisPoints(direction, foot_n, foot_e, across)

    def _nearest_parts(
        self, north: NDArray[np.float64], east: NDArray[np.float64], index: NDArray[np.int64]
    ) -> NDArray[np.int64]:
        """For each position, the nearest axis part of its channel (-1 for index -1)."""
        chosen = np.full(len(north), -1, dtype=np.int64)
        q = np.flatnonzero((index >= 0) & np.isfinite(north) & np.isfinite(east))
        if len(q) == 0:
            return chosen
        counts = self._part_count[index[q]]
        pair_q = np.repeat(q, counts)
        within = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
        pair_part = np.repeat(self._first_part[index[q]], counts) + within
        distance = shapely.distance(
            self._parts[pair_part], shapely.points(np.column_stack([east[pair_q], north[pair_q]]))
        )
        order = np.lexsort((distance, pair_q))
        first = np.r_[True, pair_q[order][1:] != pair_q[order][:-1]]
        chosen[pair_q[order][first]] = pair_part[order][first]
        return chosen

    def sections(
        self,
        north_m: ArrayLike,
        east_m: ArrayLike,
        index: ArrayLike,
        direction_grid_deg: ArrayLike,
        draught_m: float | None = None,
        ukc_m: float = 0.0,
    ) -> Sections:
        """The cross-section of channel ``index[i]`` through each position, square to
        ``direction_grid_deg`` (``Sections``): the straight piece of the section inside the
        channel, or inside its water navigable for ``draught_m + ukc_m``, that holds the
        position."""
        north, east = _points_xy(north_m, east_m)
        index = np.broadcast_to(np.asarray(index, dtype=np.int64), north.shape)
        bearing = np.broadcast_to(np.asarray(direction_grid_deg, dtype=float), north.shape)
        left, right = np.full(len(north), np.nan), np.full(len(north), np.nan)
        q = np.flatnonzero((index >= 0) & np.isfinite(bearing) & np.isfinite(north + east))
        if len(q) == 0:
            return Sections(left, right)
        bearing_rad = np.radians(bearing[q])
        right_unit = np.column_stack([np.cos(bearing_rad), -np.sin(bearing_rad)])
        reach = self._reach_m[index[q]]
        left[q], right[q] = section_extents(
            np.column_stack([east[q], north[q]]),
            right_unit,
            (reach, reach),
            self._area_geometries(draught_m, ukc_m)[index[q]],
        )
        return Sections(left, right)

    def width_m_at(
        self,
        north_m: ArrayLike,
        east_m: ArrayLike,
        index: ArrayLike,
        draught_m: float | None = None,
        ukc_m: float = 0.0,
    ) -> NDArray[np.float64]:
        """The channel's width through each position, square to its local axis; with a
        draught, the width of its water navigable for ``draught_m + ukc_m`` (the channel
        intersected with ``Chart.navigable_water``). NaN outside it."""
        axis = self.axis_at(north_m, east_m, index)
        return self.sections(
            north_m, east_m, index, axis.direction_grid_deg, draught_m, ukc_m
        ).width_m

    def _area_geometries(self, draught_m: float | None, ukc_m: float) -> NDArray[np.object_]:
        """Each channel's geometry; for a draught, its part navigable for it (cached)."""
        geometries = np.asarray([c.geometry for c in self.items], dtype=object)
        if draught_m is None:
            return geometries
        if self.chart is None:
            raise ParameterError(
                "a channel width for a draught needs the chart's navigable water; load the "
                "channels from a chart (load_channels)"
            )
        key = (float(draught_m), float(ukc_m))
        if key not in self._water:
            water = self.chart.navigable_water(draught_m, ukc_m)
            self._water[key] = np.asarray(shapely.intersection(geometries, water), dtype=object)
        return self._water[key]


def section_lines(
    centre_xy: NDArray[np.float64],
    right_unit: NDArray[np.float64],
    reach_m: tuple[NDArray[np.float64], NDArray[np.float64]],
) -> NDArray[np.object_]:
    """For each point, the line square to its direction from ``reach_m[0][i]`` on its left
    to ``reach_m[1][i]`` on its right (``section_extents``)."""
    return np.asarray(
        shapely.linestrings(
            np.stack(
                [
                    centre_xy - reach_m[0][:, None] * right_unit,
                    centre_xy + reach_m[1][:, None] * right_unit,
                ],
                axis=1,
            )
        ),
        dtype=object,
    )


def section_extents(
    centre_xy: NDArray[np.float64],
    right_unit: NDArray[np.float64],
    reach_m: tuple[NDArray[np.float64], NDArray[np.float64]],
    areas: NDArray[np.object_],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """For each point (``centre_xy``: x = east, y = north) and the unit vector to its right
    (``right_unit``), the straight piece of ``areas[i]`` along the line square to the
    direction that holds the point, from ``reach_m[0][i]`` on its left to ``reach_m[1][i]``
    on its right: how far the piece reaches to the left and to the right (each at most the
    reach). NaN where no piece holds the point."""
    left, right = np.full(len(centre_xy), np.nan), np.full(len(centre_xy), np.nan)
    if len(centre_xy) == 0:
        return left, right
    lines = section_lines(centre_xy, right_unit, reach_m)
    pieces, owner = shapely.get_parts(
        shapely.line_merge(shapely.intersection(lines, areas)), return_index=True
    )
    pieces = np.asarray(pieces, dtype=object)
    holds = np.asarray(
        shapely.dwithin(pieces, shapely.points(centre_xy[owner]), 1e-6), dtype=bool
    ) & np.isin(shapely.get_type_id(pieces), _LINE_TYPES)
    pieces, owner = pieces[holds], owner[holds]
    ends = np.stack(
        [
            shapely.get_coordinates(shapely.get_point(pieces, 0)),
            shapely.get_coordinates(shapely.get_point(pieces, -1)),
        ],
        axis=1,
    )
    along = np.einsum("kij,kj->ki", ends - centre_xy[owner][:, None, :], right_unit[owner])
    # Pieces met in order along the section: the first holding the point decides.
    first = np.unique(owner, return_index=True)[1]
    right[owner[first]] = np.maximum(along[first].max(axis=1), 0.0)
    left[owner[first]] = np.maximum(-along[first].min(axis=1), 0.0)
    return left, right


def _span_holding_zero(
    starts_m: NDArray[np.float64], stops_m: NDArray[np.float64]
) -> tuple[float, float] | None:
    """Of the intervals ``starts_m[i]..stops_m[i]`` along a line, joined where they touch
    (areas sharing an edge, to ``_TOUCHING_M``), the span that holds 0; None where none
    does."""
    order = np.argsort(starts_m)
    spans: list[list[float]] = []
    for start_m, stop_m in zip(starts_m[order].tolist(), stops_m[order].tolist(), strict=True):
        if spans and start_m <= spans[-1][1] + _TOUCHING_M:
            spans[-1][1] = max(spans[-1][1], stop_m)
        else:
            spans.append([start_m, stop_m])
    for start_m, stop_m in spans:
        if start_m <= _TOUCHING_M and stop_m >= -_TOUCHING_M:
            return start_m, stop_m
    return None


def _points_xy(
    north_m: ArrayLike, east_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    north, east = np.broadcast_arrays(
        np.atleast_1d(np.asarray(north_m, dtype=float)),
        np.atleast_1d(np.asarray(east_m, dtype=float)),
    )
    return np.ascontiguousarray(north), np.ascontiguousarray(east)


@dataclass(frozen=True)
class NavigableWidth:
    """An area channel's water navigable for a draught, measured across its axis at points
    half a mean width apart inside it: the share of those points where there is any, and
    the least width there (None where there is none)."""

    share: float
    narrowest_m: float | None


def navigable_widths(
    channels: Channels, draught_m: float, ukc_m: float = 0.0
) -> list[NavigableWidth | None]:
    """Each channel's ``NavigableWidth`` for ``draught_m + ukc_m``; None for a line, and for
    an area whose axis lies nowhere inside it."""
    points, owners = [], []
    for index, channel in enumerate(channels):
        if not channel.is_area:
            continue
        step_m = max((channel.width_m or 0.0) / 2.0, 1.0)
        for part in shapely.get_parts(channel.axis):
            at = np.arange(step_m / 2.0, part.length, step_m)
            xy = shapely.get_coordinates(shapely.line_interpolate_point(part, at))
            # An ORIENT axis spans the area's extent: where it leaves the area it has no width.
            xy = xy[shapely.contains_xy(channel.geometry, xy[:, 0], xy[:, 1])]
            points.append(xy)
            owners.append(np.full(len(xy), index, dtype=np.int64))
    out: list[NavigableWidth | None] = [None] * len(channels)
    if not points:
        return out
    xy, owner = np.concatenate(points), np.concatenate(owners)
    widths = channels.width_m_at(xy[:, 1], xy[:, 0], owner, draught_m, ukc_m)
    for index in np.unique(owner).tolist():
        mine = widths[owner == index]
        there = mine[np.isfinite(mine) & (mine > 0.0)]
        out[index] = NavigableWidth(
            share=len(there) / len(mine), narrowest_m=float(there.min()) if len(there) else None
        )
    return out


def load_channels(chart: Chart) -> Channels:
    """The channels charted in ``chart``'s files, in its frame, each file's cut to the part
    of the coverage it decides (module docstring), with the tracks along each area; read
    once per chart (kept with it)."""
    if isinstance(chart._channels, Channels):
        return chart._channels
    channels = _read_channels(chart)
    object.__setattr__(chart, "_channels", channels)
    return channels


def _read_channels(chart: Chart) -> Channels:
    items: list[Channel] = []
    several = len(chart.detail_order) > 1
    for rank, path in enumerate(chart.detail_order):
        features = read_channel_features(path)
        if len(features.geometries) == 0:
            continue
        geometries = project_file(
            features.path,
            features.geometries,
            chart.frame,
            what="channel",
            fix="its rings or lines (lon/lat in degrees)",
        )
        if several:
            own = chart.coverage_by_chart[rank]
            geometries = same_dimension(shapely.intersection(geometries, own), geometries)
        items.extend(_channels_of(features, geometries, chart.frame))
    channels = Channels(chart.frame, tuple(items), chart)
    return Channels(chart.frame, _with_tracks(channels), chart)


def _channels_of(
    features: ChannelFeatures, geometries: NDArray[np.object_], frame: LocalFrame
) -> list[Channel]:
    numbers = features.numbers
    channels = []
    order = list(CHANNEL_CLASSES)
    # Listed as CHANNEL_CLASSES lists the classes (fairways first), each in the file's order.
    for i in sorted(
        range(len(geometries)), key=lambda k: order.index(str(features.object_class[k]))
    ):
        geometry = geometries[i]
        if shapely.is_empty(geometry):
            continue
        kind = CHANNEL_CLASSES[str(features.object_class[i])][1]
        category = numbers["CATTRK" if kind is ChannelKind.RECOMMENDED_TRACK else "CATNAV"][i]
        channel = make_channel(
            frame,
            kind,
            geometry,
            record_id=str(features.record_id[i]),
            name=features.name[i],
            chart=features.path.name,
            orient_deg=_optional(numbers["ORIENT"][i]),
            traffic=_TRAFFIC_BY_CODE.get(int(numbers["TRAFIC"][i]))
            if np.isfinite(numbers["TRAFIC"][i])
            else None,
            depth_m=_optional(numbers["DRVAL1"][i]),
            depth_max_m=_optional(numbers["DRVAL2"][i]),
            category=int(category) if np.isfinite(category) else None,
        )
        if channel is not None:
            channels.append(channel)
    return channels


def _optional(value: float) -> float | None:
    return float(value) if np.isfinite(value) else None


def _with_tracks(channels: Channels) -> tuple[Channel, ...]:
    """Each area with the record ids of the tracks that run along it: inside it for at least
    half the track's length or half the area's axis, and, at points a width apart on the
    part inside, a median angle to the area's local axis within ``TRACK_ALONG_DEG``."""
    tracks = [c for c in channels if c.bears_track]
    if not tracks:
        return channels.items
    items = list(channels.items)
    for i, area in enumerate(items):
        if not area.is_area:
            continue
        along = []
        for track in tracks:
            inside = shapely.intersection(track.axis, area.geometry)
            inside_m = float(shapely.length(inside))
            if inside_m == 0.0 or inside_m < 0.5 * min(track.length_m, area.length_m):
                continue
            if _median_angle_deg(channels, i, inside, area.width_m or 0.0) <= TRACK_ALONG_DEG:
                along.append(track.record_id)
        if along:
            items[i] = dataclasses.replace(area, tracks=tuple(along))
    return tuple(items)


def _median_angle_deg(channels: Channels, index: int, inside: Any, step_m: float) -> float:
    """The median angle (0–90°) between line ``inside`` and channel ``index``'s local axis,
    at points ``step_m`` apart on each of its parts."""
    angles = []
    for part in shapely.get_parts(shapely.line_merge(inside)):
        if shapely.get_type_id(part) != shapely.GeometryType.LINESTRING or part.length == 0:
            continue
        at = np.linspace(0.0, part.length, max(int(part.length / max(step_m, 1.0)), 1) + 2)[1:-1]
        chord = shapely.get_coordinates(
            shapely.line_interpolate_point(part, np.minimum(at + 1.0, part.length))
        ) - shapely.get_coordinates(shapely.line_interpolate_point(part, np.maximum(at - 1.0, 0)))
        line_deg = np.degrees(np.arctan2(chord[:, 0], chord[:, 1]))
        xy = shapely.get_coordinates(shapely.line_interpolate_point(part, at))
        axis_deg = channels.axis_at(xy[:, 1], xy[:, 0], index).direction_grid_deg
        angles.append(line_angle_deg(line_deg, axis_deg))
    return float(np.nanmedian(np.concatenate(angles))) if angles else 90.0


def line_angle_deg(a_deg: ArrayLike, b_deg: ArrayLike) -> NDArray[np.float64]:
    """The angle between two undirected lines of these directions, 0–90°."""
    difference = np.abs(wrap_deg(np.asarray(a_deg, dtype=float) - np.asarray(b_deg, dtype=float)))
    difference = np.minimum(difference, 360.0 - difference)
    return np.minimum(difference, 180.0 - difference)
