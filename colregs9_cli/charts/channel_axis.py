"""The axis of a charted channel area, in the run's frame (x east, y north, metres).

Two ways, in this order (``channels`` picks):

- **Charted** (``orient_axis``): the area's ``ORIENT`` is the direction of its axis. Each
  polygonal part gets a straight line in that direction through the part's centroid, running
  the part's whole extent along it. ENCs chart an ``ORIENT`` on straight reaches.
- **Derived** (``centreline``): an approximate medial axis, the chordal axis of a constrained
  Delaunay triangulation (Prasad, "Morphological analysis of shapes", 1997): the boundary is
  densified to a third of the area's mean width (``2 · area / perimeter``, the width of a
  long strip), triangulated inside the polygon (GEOS, ``shapely.constrained_delaunay_
  triangles``), and the midpoints of the triangles' interior edges are joined within each
  triangle. In a strip of parallel sides every such midpoint lies on the centre line, so the
  graph follows the middle of the channel through its bends; side branches, basins and the
  loops round an island are spurs and cycles of the graph. The axis is the graph's longest
  path (two sweeps of Dijkstra's algorithm: from any node to the farthest, and from there to
  the farthest again; exact on the tree a polygon without holes gives), straightened where
  it strays by less than a hundredth of the width, its last width at each end cut off (there
  the triangles fan out from a corner of the channel's end and the path runs into that
  corner), and extended at both ends straight on, in the direction of the width before, to
  the polygon's boundary.
  A part too small to triangulate into a path takes the long axis of its minimum rotated
  rectangle. An area about as wide as long (a turning basin) gets its longest diagonal,
  which says little of a direction: its length over its mean width tells.

The axis has no direction of its own; ``channels`` gives each point the local direction of
the axis nearest to it, so that a bend gives the direction of the bend.
"""

from __future__ import annotations

import heapq
import math
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray
from shapely.ops import substring

# Boundary densified to this fraction of the mean width: enough triangles across a strip for
# their edge midpoints to trace its middle, few enough for a channel 20 km long.
_SPACING_OF_WIDTH = 1.0 / 3.0
_MAX_BOUNDARY_POINTS = 4000
# Axis vertices closer than this fraction of the mean width to the line through their
# neighbours are dropped: the chordal axis's points along a straight reach, not its bends
# (a twentieth cut the chords of a bend of radius 5 widths 5 % of the half-width inside).
_SIMPLIFY_OF_WIDTH = 1.0 / 100.0


def _mean_width_m(polygon: Any) -> float:
    """``2 · area / perimeter``: the width of a long strip of that area and boundary."""
    perimeter = float(shapely.length(shapely.boundary(polygon)))
    return 2.0 * float(shapely.area(polygon)) / perimeter if perimeter > 0.0 else 0.0


def orient_axis(polygon: Any, orient_grid_deg: float) -> Any:
    """The straight axis of each polygonal part in direction ``orient_grid_deg`` (grid
    degrees), through the part's centroid, over its extent along that direction."""
    direction = _unit(orient_grid_deg)
    lines = []
    for part in _polygons(polygon):
        centre = np.asarray(shapely.centroid(part).coords[0])
        along = (shapely.get_coordinates(part) - centre) @ direction
        lines.append(
            shapely.LineString([centre + along.min() * direction, centre + along.max() * direction])
        )
    return _one_or_multi(lines)


def centreline(polygon: Any) -> Any:
    """The derived axis (module docstring) of each polygonal part: a LineString, or a
    MultiLineString for several parts."""
    return _one_or_multi([_part_centreline(part) for part in _polygons(polygon)])


def _polygons(geometry: Any) -> list[Any]:
    parts = shapely.get_parts(geometry)
    keep = (shapely.get_type_id(parts) == shapely.GeometryType.POLYGON) & ~shapely.is_empty(parts)
    return list(parts[keep])


def _one_or_multi(lines: list[Any]) -> Any:
    if len(lines) == 1:
        return lines[0]
    return shapely.MultiLineString(lines)


def _unit(bearing_deg: float) -> NDArray[np.float64]:
    """The unit vector (east, north) of a grid bearing."""
    bearing_rad = math.radians(bearing_deg)
    return np.array([math.sin(bearing_rad), math.cos(bearing_rad)])


def _part_centreline(part: Any) -> Any:
    width_m = _mean_width_m(part)
    perimeter_m = float(shapely.length(shapely.boundary(part)))
    spacing_m = max(width_m * _SPACING_OF_WIDTH, perimeter_m / _MAX_BOUNDARY_POINTS, 1e-3)
    midpoints, a, b = _chordal_graph(shapely.segmentize(part, spacing_m))
    if len(midpoints) < 2 or len(a) == 0:
        return _rectangle_axis(part)
    path = midpoints[_longest_path(midpoints, a, b)]
    if len(path) < 2:
        return _rectangle_axis(part)
    line = shapely.simplify(shapely.LineString(path), width_m * _SIMPLIFY_OF_WIDTH)
    if line.length > 3.0 * width_m:
        # The last width of each end fans out to a corner of the channel's end.
        line = substring(line, width_m, line.length - width_m)
    return _extended_to_boundary(line, part, width_m)


def _chordal_graph(
    polygon: Any,
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """The midpoints of the interior edges of the polygon's constrained Delaunay
    triangulation, and the pairs of them (indices ``a``, ``b``) that share a triangle."""
    triangles = shapely.get_parts(shapely.constrained_delaunay_triangles(polygon))
    triangles = triangles[shapely.get_type_id(triangles) == shapely.GeometryType.POLYGON]
    if len(triangles) == 0:
        return np.empty((0, 2)), np.empty(0, np.int64), np.empty(0, np.int64)
    corners = shapely.get_coordinates(shapely.get_exterior_ring(triangles))
    corners = corners.reshape(len(triangles), 4, 2)[:, :3]
    # Vertices shared by neighbouring triangles are the same coordinates: one id each.
    vertices, vertex_id = np.unique(corners.reshape(-1, 2), axis=0, return_inverse=True)
    vertex_id = vertex_id.reshape(-1, 3)
    sides = np.sort(
        np.stack([vertex_id[:, [0, 1]], vertex_id[:, [1, 2]], vertex_id[:, [2, 0]]], 1), 2
    )
    edges, edge_id, uses = np.unique(
        sides.reshape(-1, 2), axis=0, return_inverse=True, return_counts=True
    )
    edge_id = edge_id.reshape(-1, 3)
    interior = np.flatnonzero(uses == 2)  # an edge of two triangles lies inside the polygon
    node = np.full(len(edges), -1, dtype=np.int64)
    node[interior] = np.arange(len(interior))
    midpoints = vertices[edges[interior]].mean(axis=1)
    a, b = [], []
    for p, q in ((0, 1), (1, 2), (2, 0)):
        both = (uses[edge_id[:, p]] == 2) & (uses[edge_id[:, q]] == 2)
        a.append(node[edge_id[both, p]])
        b.append(node[edge_id[both, q]])
    return midpoints, np.concatenate(a), np.concatenate(b)


def _longest_path(
    points: NDArray[np.float64], a: NDArray[np.int64], b: NDArray[np.int64]
) -> list[int]:
    """The nodes of the graph's longest shortest path, by two sweeps of Dijkstra's algorithm
    (the farthest node from node 0, then the farthest from that one)."""
    lengths = np.hypot(*(points[a] - points[b]).T)
    neighbours: list[list[tuple[int, float]]] = [[] for _ in range(len(points))]
    for i, j, length in zip(a.tolist(), b.tolist(), lengths.tolist(), strict=True):
        neighbours[i].append((j, length))
        neighbours[j].append((i, length))
    distance, _ = _dijkstra(neighbours, 0)
    start = int(np.argmax(np.where(np.isfinite(distance), distance, -1.0)))
    distance, previous = _dijkstra(neighbours, start)
    node = int(np.argmax(np.where(np.isfinite(distance), distance, -1.0)))
    path = [node]
    while previous[node] >= 0:
        node = previous[node]
        path.append(node)
    return path


def _dijkstra(
    neighbours: list[list[tuple[int, float]]], source: int
) -> tuple[NDArray[np.float64], list[int]]:
    distance = np.full(len(neighbours), np.inf)
    previous = [-1] * len(neighbours)
    distance[source] = 0.0
    heap = [(0.0, source)]
    while heap:
        reached, node = heapq.heappop(heap)
        if reached > distance[node]:
            continue
        for other, length in neighbours[node]:
            if reached + length < distance[other]:
                distance[other] = reached + length
                previous[other] = node
                heapq.heappush(heap, (reached + length, other))
    return distance, previous


def _rectangle_axis(part: Any) -> Any:
    """The long centre line of the part's minimum rotated rectangle."""
    corners = shapely.get_coordinates(shapely.minimum_rotated_rectangle(part))[:4]
    if len(corners) < 4:  # a degenerate part: its rectangle is a line or a point
        return shapely.LineString(corners[[0, -1]]) if len(corners) > 1 else shapely.LineString()
    side_a, side_b = corners[1] - corners[0], corners[2] - corners[1]
    if np.hypot(*side_a) >= np.hypot(*side_b):
        return shapely.LineString([(corners[0] + corners[3]) / 2, (corners[1] + corners[2]) / 2])
    return shapely.LineString([(corners[0] + corners[1]) / 2, (corners[2] + corners[3]) / 2])


def _extended_to_boundary(line: Any, part: Any, width_m: float) -> Any:
    """``line`` with each end carried straight on, in the direction of its last width, to
    where it leaves ``part``."""
    xy = shapely.get_coordinates(line)
    reach_m = 2.0 * float(np.hypot(*np.subtract(*np.reshape(shapely.bounds(part), (2, 2)))))
    ends = []
    for points in (xy[::-1], xy):  # the start (walked backwards), then the end
        end = points[-1]
        back = np.hypot(*(points - end).T)
        inner = (
            points[np.flatnonzero(back >= width_m)[-1]] if (back >= width_m).any() else points[0]
        )
        step = end - inner
        norm = float(np.hypot(*step))
        if norm == 0.0:
            ends.append(end)
            continue
        ray = shapely.LineString([end, end + step / norm * reach_m])
        pieces = shapely.get_parts(shapely.intersection(ray, part))
        first = [p for p in pieces if shapely.dwithin(p, shapely.Point(end), 1e-6)]
        ends.append(_far_end(first[0], end) if first else end)
    return shapely.LineString([ends[0], *xy, ends[1]])


def _far_end(piece: Any, near: NDArray[np.float64]) -> NDArray[np.float64]:
    coordinates = shapely.get_coordinates(piece)
    return coordinates[int(np.argmax(np.hypot(*(coordinates - near).T)))]
