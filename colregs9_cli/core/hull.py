"""Hull outlines from the AIS antenna offsets, and the least distance between two hulls.

Investigators quote the distance between hulls, not between AIS antennas. AIS gives each
vessel's reference point (her GNSS antenna) and its offsets (ITU-R M.1371, "dimension /
reference for position"): A to the bow, B to the stern, C to port, D to starboard, in metres.

The outline is the AIS rectangle: A + B long, C + D wide, aligned with the heading, the
antenna at (A aft of the bow, C in from the port side). No pointed bow is drawn. The AIS
offsets are the hull's extreme dimensions, so the real hull lies inside the rectangle and
the rectangle-to-rectangle distance is a lower bound of the hull-to-hull distance (for
exact positions, heading and offsets): the side of caution for an audit of how close two
vessels came. A pointed bow would add a shape guessed from nothing AIS says, and could only
raise the figure, by at most a few metres at a bow shoulder.

Positions are metres ``north_m, east_m`` in one plane, with the headings measured from that
plane's north: grid headings (``heading_grid_deg``) in the run's ``geo.LocalFrame``.
``least_hull_distance_geodetic_m`` takes WGS84 positions and true headings instead and works
in the tangent plane at the pair's midpoint (the between-vessels geometry of docs/design.md
§4: Earth-centred vectors, no map projection; exact to a few parts in 10⁷ at 2 nm, and
the same whichever vessel is named first). The heading is the vessel's true heading, her COG
where the heading is not available (``core/tracks.py`` already fills a track's null heading
with its COG).

Where A/B/C/D are not known, ``centred_offsets`` places the antenna on the centre line,
amidships by default (``DEFAULT_ANTENNA_FROM_BOW_FRAC``), and marks the offsets defaulted.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from ..errors import ParameterError
from ..geo import (
    course_in_tangent_plane,
    ecef_m,
    in_tangent_plane,
    normal_to_lat_lon,
    surface_normal,
)
from ..vessels import MAX_BREADTH_M, MAX_LENGTH_M

# Where the antenna is assumed along the hull when only length and breadth are known, as a
# fraction of the length from the bow. Amidships: wherever the antenna really is, the drawn
# hull is then at most L/2 out along the ship, the least worst case. (In the DMA NMEA fixture
# the antenna is 0.70 L from the bow at the median, 0.83 L for ships of 50-200 m: bridge aft.)
DEFAULT_ANTENNA_FROM_BOW_FRAC = 0.5

# Closed ring of the rectangle in body coordinates, as multipliers of the offsets:
# forward = to_bow·F1 − to_stern·F2, starboard = to_starboard·S1 − to_port·S2.
# Corners: bow-port, bow-starboard, stern-starboard, stern-port, bow-port.
_FORWARD_BOW = np.array([1.0, 1.0, 0.0, 0.0, 1.0])
_FORWARD_STERN = 1.0 - _FORWARD_BOW
_STARBOARD = np.array([0.0, 1.0, 1.0, 0.0, 0.0])
_PORT = 1.0 - _STARBOARD


@dataclass(frozen=True)
class HullOffsets:
    """A vessel's antenna offsets in metres: AIS A (``to_bow_m``), B (``to_stern_m``),
    C (``to_port_m``), D (``to_starboard_m``). NaN: not known (the hull is then unknown).

    ``defaulted``: some of the four are not AIS A/B/C/D but assumed (``centred_offsets``).
    """

    to_bow_m: float
    to_stern_m: float
    to_port_m: float
    to_starboard_m: float
    defaulted: bool = False

    def __post_init__(self) -> None:
        parts = (self.to_bow_m, self.to_stern_m, self.to_port_m, self.to_starboard_m)
        if any(not (math.isnan(p) or (math.isfinite(p) and p >= 0.0)) for p in parts):
            raise ParameterError(
                f"antenna offsets A {self.to_bow_m}, B {self.to_stern_m}, C {self.to_port_m}, "
                f"D {self.to_starboard_m} m: each must be >= 0 and finite (NaN: not known)"
            )
        if self.known and not (self.length_m > 0.0 and self.breadth_m > 0.0):
            raise ParameterError(
                f"antenna offsets A {self.to_bow_m}, B {self.to_stern_m}, C {self.to_port_m}, "
                f"D {self.to_starboard_m} m give no hull: A + B and C + D must be > 0"
            )

    @property
    def known(self) -> bool:
        """All four offsets are known, so the hull can be drawn."""
        return not any(
            math.isnan(p)
            for p in (self.to_bow_m, self.to_stern_m, self.to_port_m, self.to_starboard_m)
        )

    @property
    def length_m(self) -> float:
        return self.to_bow_m + self.to_stern_m

    @property
    def breadth_m(self) -> float:
        return self.to_port_m + self.to_starboard_m


UNKNOWN_OFFSETS = HullOffsets(math.nan, math.nan, math.nan, math.nan)


def centred_offsets(
    length_m: float,
    breadth_m: float,
    antenna_from_bow_frac: float = DEFAULT_ANTENNA_FROM_BOW_FRAC,
) -> HullOffsets:
    """Offsets for a vessel of known length and breadth whose antenna position is not known:
    on the centre line, ``antenna_from_bow_frac`` of the length aft of the bow (default
    amidships); marked ``defaulted``. A length or breadth that is not a positive number
    gives ``UNKNOWN_OFFSETS``."""
    if not (math.isfinite(antenna_from_bow_frac) and 0.0 <= antenna_from_bow_frac <= 1.0):
        raise ParameterError(
            f"antenna_from_bow_frac {antenna_from_bow_frac} is outside [0, 1]; give the "
            "antenna's distance from the bow as a fraction of the length (0.5: amidships)"
        )
    if not (_positive(length_m) and _positive(breadth_m)):
        return UNKNOWN_OFFSETS
    return HullOffsets(
        antenna_from_bow_frac * length_m,
        (1.0 - antenna_from_bow_frac) * length_m,
        breadth_m / 2.0,
        breadth_m / 2.0,
        defaulted=True,
    )


def offsets_from_ais(
    to_bow_m: float | None,
    to_stern_m: float | None,
    to_port_m: float | None,
    to_starboard_m: float | None,
    length_m: float | None = None,
    breadth_m: float | None = None,
    antenna_from_bow_frac: float = DEFAULT_ANTENNA_FROM_BOW_FRAC,
) -> HullOffsets:
    """A vessel's offsets from her AIS A, B, C, D as reported (None, NaN or 0: not
    available), else from her length and breadth (``centred_offsets``).

    - A, B, C, D all > 0, with A + B and C + D within what ships have
      (``vessels.MAX_LENGTH_M``, ``MAX_BREADTH_M``, the readers' limits): as reported.
    - A = C = 0 with B, D > 0 is ITU-R M.1371's "reference point not available, dimensions
      available": the vessel is B long and D wide (within the same limits), and her antenna
      is placed as in ``centred_offsets``.
    - Otherwise ``length_m``/``breadth_m`` (e.g. ``VesselDimensions``), centred; without
      them the offsets are unknown.

    Along and across the ship are decided apart, as the readers decide length (A + B) and
    breadth (C + D): a vessel that reports A and B but not D keeps her A and B and is
    centred across her breadth. Any part not from A/B/C/D makes the offsets ``defaulted``.
    """
    a, b, c, d = (_part(v) for v in (to_bow_m, to_stern_m, to_port_m, to_starboard_m))
    if a == 0.0 and c == 0.0 and b > 0.0 and d > 0.0:
        if b <= MAX_LENGTH_M and d <= MAX_BREADTH_M:
            length_m, breadth_m = b, d
        a = b = c = d = math.nan
    centred = centred_offsets(_part(length_m), _part(breadth_m), antenna_from_bow_frac)
    along_reported = a > 0.0 and b > 0.0 and a + b <= MAX_LENGTH_M
    across_reported = c > 0.0 and d > 0.0 and c + d <= MAX_BREADTH_M
    if along_reported and across_reported:
        return HullOffsets(a, b, c, d)
    if along_reported:
        # Centred across: C = D = breadth/2 of ``centred``.
        return _mixed(HullOffsets(a, b, centred.to_port_m, centred.to_starboard_m, True))
    if across_reported:
        return _mixed(HullOffsets(centred.to_bow_m, centred.to_stern_m, c, d, True))
    return centred


def _mixed(offsets: HullOffsets) -> HullOffsets:
    return offsets if offsets.known else UNKNOWN_OFFSETS


def _part(value: float | None) -> float:
    """An AIS offset or dimension as a number; None and NaN as 0 (not available)."""
    if value is None:
        return 0.0
    number = float(value)
    return number if math.isfinite(number) else 0.0


def _positive(value: float) -> bool:
    return math.isfinite(value) and value > 0.0


def hull_outlines(
    north_m: ArrayLike, east_m: ArrayLike, heading_deg: ArrayLike, offsets: HullOffsets
) -> NDArray[np.object_]:
    """The hull rectangles at antenna positions (metres, x east, y north) and headings
    (degrees from the plane's north), as shapely polygons, one per position; ``None`` where
    the position or heading is not finite or the offsets are unknown.

    Built with numpy and turned into polygons in one ``shapely.from_ragged_array`` call, as
    ``manoeuvrability.ellipse_polygons`` does.
    """
    north, east, heading = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(v, dtype=float)) for v in (north_m, east_m, heading_deg))
    )
    outlines = np.full(north.shape, None, dtype=object)
    valid = np.isfinite(north) & np.isfinite(east) & np.isfinite(heading)
    if not offsets.known or not valid.any():
        return outlines
    forward_m = offsets.to_bow_m * _FORWARD_BOW - offsets.to_stern_m * _FORWARD_STERN
    starboard_m = offsets.to_starboard_m * _STARBOARD - offsets.to_port_m * _PORT
    heading_rad = np.radians(heading[valid])
    cos_h, sin_h = np.cos(heading_rad), np.sin(heading_rad)
    count, ring = len(heading_rad), len(forward_m)
    coords = np.empty((count, ring, 2))
    coords[:, :, 0] = (
        np.multiply.outer(sin_h, forward_m)
        + np.multiply.outer(cos_h, starboard_m)
        + east[valid][:, None]
    )
    coords[:, :, 1] = (
        np.multiply.outer(cos_h, forward_m)
        - np.multiply.outer(sin_h, starboard_m)
        + north[valid][:, None]
    )
    outlines[valid] = shapely.from_ragged_array(
        shapely.GeometryType.POLYGON,
        coords.reshape(-1, 2),
        (np.arange(0, count * ring + 1, ring), np.arange(count + 1)),
    )
    return outlines


def least_hull_distance_m(
    a_north_m: ArrayLike,
    a_east_m: ArrayLike,
    a_heading_deg: ArrayLike,
    a_offsets: HullOffsets,
    b_north_m: ArrayLike,
    b_east_m: ArrayLike,
    b_heading_deg: ArrayLike,
    b_offsets: HullOffsets,
) -> NDArray[np.float64]:
    """The least distance (metres) between the hulls of vessels a and b at each step, in one
    plane (module docstring): 0 where the hulls touch or overlap, NaN where a position or
    heading is NaN or either vessel's offsets are unknown. Arrays broadcast together."""
    a_north, a_east, a_heading, b_north, b_east, b_heading = np.broadcast_arrays(
        *(
            np.atleast_1d(np.asarray(v, dtype=float))
            for v in (a_north_m, a_east_m, a_heading_deg, b_north_m, b_east_m, b_heading_deg)
        )
    )
    a_hulls = hull_outlines(a_north, a_east, a_heading, a_offsets)
    b_hulls = hull_outlines(b_north, b_east, b_heading, b_offsets)
    # shapely gives NaN for a missing (None) geometry.
    return np.asarray(shapely.distance(a_hulls, b_hulls), dtype=float)


def least_hull_distance_geodetic_m(
    a_lat_deg: ArrayLike,
    a_lon_deg: ArrayLike,
    a_heading_deg: ArrayLike,
    a_offsets: HullOffsets,
    b_lat_deg: ArrayLike,
    b_lon_deg: ArrayLike,
    b_heading_deg: ArrayLike,
    b_offsets: HullOffsets,
) -> NDArray[np.float64]:
    """``least_hull_distance_m`` from WGS84 antenna positions and true headings, in the
    tangent plane at the pair's midpoint at each step (module docstring)."""
    a_lat, a_lon, a_heading, b_lat, b_lon, b_heading = np.broadcast_arrays(
        *(
            np.atleast_1d(np.asarray(v, dtype=float))
            for v in (a_lat_deg, a_lon_deg, a_heading_deg, b_lat_deg, b_lon_deg, b_heading_deg)
        )
    )
    mid_lat, mid_lon = normal_to_lat_lon(
        *np.moveaxis(surface_normal(a_lat, a_lon) + surface_normal(b_lat, b_lon), -1, 0)
    )
    middle = ecef_m(mid_lat, mid_lon)
    a_north, a_east = in_tangent_plane(ecef_m(a_lat, a_lon) - middle, mid_lat, mid_lon)
    b_north, b_east = in_tangent_plane(ecef_m(b_lat, b_lon) - middle, mid_lat, mid_lon)
    return least_hull_distance_m(
        a_north,
        a_east,
        course_in_tangent_plane(a_heading, a_lat, a_lon, mid_lat, mid_lon),
        a_offsets,
        b_north,
        b_east,
        course_in_tangent_plane(b_heading, b_lat, b_lon, mid_lat, mid_lon),
        b_offsets,
    )
