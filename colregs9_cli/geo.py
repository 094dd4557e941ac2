"""The run's local metric frame: a transverse Mercator projection centred on the region.

Positions in the frame are ``north_m, east_m`` (the paper's NED frame, down omitted).
The frame is chosen once per run and carried with the data; nothing falls back to a default.

Grid north (the frame's ``north_m`` axis) differs from true north by the meridian convergence
γ, about Δlon·sin(lat) from the central meridian (≈ 2° at the edges of Denmark for a frame
centred on the country). Directions compared with frame positions or turned into frame
velocities must be grid directions: ``grid = true − γ``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from pyproj import CRS, Geod, Proj, Transformer

from .errors import ParameterError
from .units import wrap_deg

# Where the series for the meridian convergence holds to 1.6e-5° (``grid_convergence_deg``).
_SERIES_REACH_DEG = 10.0
# How far from its origin a frame places positions: a transverse Mercator scale is about
# 1 + d²/2R², 0.2 % at 400 km. Beyond, positions have no frame coordinates.
FRAME_REACH_M = 400_000.0
MEAN_EARTH_RADIUS_M = 6_371_008.8


@dataclass(frozen=True)
class LocalFrame:
    """A transverse Mercator frame with its origin at (``lat0_deg``, ``lon0_deg``)."""

    lat0_deg: float
    lon0_deg: float
    crs: CRS = field(init=False, repr=False, compare=False)
    _forward: Transformer = field(init=False, repr=False, compare=False)
    _inverse: Transformer = field(init=False, repr=False, compare=False)
    _proj: Proj = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not (-90.0 < self.lat0_deg < 90.0 and -180.0 <= self.lon0_deg <= 180.0):
            raise ParameterError(
                f"frame origin lat {self.lat0_deg}, lon {self.lon0_deg} is not a position on "
                "Earth; give a latitude in (-90, 90) and a longitude in [-180, 180]"
            )
        crs = CRS.from_proj4(
            f"+proj=tmerc +lat_0={self.lat0_deg} +lon_0={self.lon0_deg} +k=1 "
            "+x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs"
        )
        object.__setattr__(self, "crs", crs)
        object.__setattr__(self, "_forward", Transformer.from_crs("EPSG:4326", crs, always_xy=True))
        object.__setattr__(self, "_inverse", Transformer.from_crs(crs, "EPSG:4326", always_xy=True))
        object.__setattr__(self, "_proj", Proj(crs))

    def within_reach(self, lat_deg: ArrayLike, lon_deg: ArrayLike) -> NDArray[np.bool_]:
        """Whether positions lie within ``FRAME_REACH_M`` of the origin (great circle on the
        mean sphere), where the frame's scale is within 0.2 % of true."""
        lat = np.radians(np.asarray(lat_deg, dtype=float))
        dlon = np.radians(np.asarray(lon_deg, dtype=float) - self.lon0_deg)
        lat0 = math.radians(self.lat0_deg)
        half_chord_sq = (
            np.sin((lat - lat0) / 2.0) ** 2 + math.cos(lat0) * np.cos(lat) * np.sin(dlon / 2.0) ** 2
        )
        with np.errstate(invalid="ignore"):
            angle = 2.0 * np.arcsin(np.sqrt(np.clip(half_chord_sq, 0.0, 1.0)))
            return np.asarray(angle * MEAN_EARTH_RADIUS_M <= FRAME_REACH_M)

    @classmethod
    def centred_on(
        cls, lat_min: float, lat_max: float, lon_min: float, lon_max: float
    ) -> LocalFrame:
        """The frame at the middle of a box; its longitudes are taken the short way round,
        so that a box split at the antimeridian (-180 … 180) is centred on 180°, not 0°."""
        if lon_min <= lon_max and lon_max - lon_min <= 180.0:
            return cls((lat_min + lat_max) / 2.0, (lon_min + lon_max) / 2.0)
        span = (lon_max - lon_min) % 360.0
        if span > 180.0:
            span -= 360.0
        centre = (lon_min + span / 2.0 + 180.0) % 360.0 - 180.0
        return cls((lat_min + lat_max) / 2.0, centre)

    def to_local(
        self, lat_deg: ArrayLike, lon_deg: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """WGS84 lat/lon (degrees) to (north_m, east_m)."""
        east_m, north_m = self._forward.transform(
            np.asarray(lon_deg, dtype=float), np.asarray(lat_deg, dtype=float)
        )
        return np.asarray(north_m, dtype=float), np.asarray(east_m, dtype=float)

    def to_geodetic(
        self, north_m: ArrayLike, east_m: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(north_m, east_m) to WGS84 (lat_deg, lon_deg)."""
        lon_deg, lat_deg = self._inverse.transform(
            np.asarray(east_m, dtype=float), np.asarray(north_m, dtype=float)
        )
        return np.asarray(lat_deg, dtype=float), np.asarray(lon_deg, dtype=float)

    def shapes_to_wgs84(self, shapes: ArrayLike) -> NDArray[np.object_]:
        """Shapely geometries in this frame as (lon, lat) geometries in WGS84; those that
        cross the antimeridian are cut there (as RFC 7946 asks), not drawn round the globe."""

        def convert(xy: NDArray[np.float64]) -> NDArray[np.float64]:
            lat_deg, lon_deg = self.to_geodetic(xy[:, 1], xy[:, 0])
            # Continuous across 180°: within half a turn of the central meridian.
            # A whole number of turns added: exact where nothing is added.
            turns = np.round((self.lon0_deg - lon_deg) / 360.0)
            return np.column_stack([lon_deg + 360.0 * turns, lat_deg])

        unwrapped = np.asarray(
            shapely.transform(np.asarray(shapes, dtype=object), convert), dtype=object
        )
        bounds = shapely.bounds(unwrapped)
        crossing = (bounds[..., 0] < -180.0) | (bounds[..., 2] > 180.0)
        if not crossing.any():
            return unwrapped
        across = shapely.make_valid(unwrapped[crossing])
        parts = shapely.intersection(across, shapely.box(-180.0, -90.0, 180.0, 90.0))
        for shift, beyond in (
            (-360.0, shapely.box(180.0, -90.0, 540.0, 90.0)),
            (360.0, shapely.box(-540.0, -90.0, -180.0, 90.0)),
        ):
            moved = shapely.transform(
                shapely.intersection(across, beyond), lambda xy, s=shift: xy + np.array([s, 0.0])
            )
            parts = shapely.union(parts, moved)
        unwrapped[crossing] = parts
        return unwrapped

    def grid_convergence_deg(self, lat_deg: ArrayLike, lon_deg: ArrayLike) -> NDArray[np.float64]:
        """Meridian convergence γ (degrees) at WGS84 positions: ``grid bearing = true − γ``.

        γ is 0 on the central meridian and, in the northern hemisphere, positive east of it
        (grid north lies east of true north there). NaN positions give NaN.

        Within ``_SERIES_REACH_DEG`` of the central meridian γ comes from its series in the
        longitude difference (Redfearn's, to the fifth power): within 1.6e-5° of PROJ there,
        at any latitude, and faster than PROJ's ``get_factors``, which computes twelve factors
        to give this one (figures: tests/benchmarks/README.md). Farther out PROJ computes it.
        """
        lat, lon = np.broadcast_arrays(
            np.asarray(lat_deg, dtype=float), np.asarray(lon_deg, dtype=float)
        )
        delta_deg = (lon - self.lon0_deg + 180.0) % 360.0 - 180.0
        phi = np.radians(lat)
        dl = np.radians(delta_deg)
        cos_phi, sin_phi, tan_phi = np.cos(phi), np.sin(phi), np.tan(phi)
        eta2 = _SECOND_ECCENTRICITY_SQ * cos_phi * cos_phi
        dl2_cos2 = dl * dl * cos_phi * cos_phi
        gamma = np.degrees(
            dl
            * sin_phi
            * (
                1.0
                + dl2_cos2 / 3.0 * (1.0 + 3.0 * eta2 + 2.0 * eta2 * eta2)
                + dl2_cos2 * dl2_cos2 / 15.0 * (2.0 - tan_phi * tan_phi)
            )
        )
        far = np.isfinite(lat) & np.isfinite(lon) & (np.abs(delta_deg) > _SERIES_REACH_DEG)
        if far.any():
            # PROJ reports an unknown position as inf, not NaN: only known ones go in.
            factors = self._proj.get_factors(lon[far], lat[far])
            far_gamma = np.asarray(factors.meridian_convergence, dtype=float)
            # Beyond the projection's reach PROJ answers inf: no grid direction there.
            gamma[far] = np.where(np.isfinite(far_gamma), far_gamma, np.nan)
        return np.asarray(gamma, dtype=float)

    def true_to_grid_deg(
        self, bearing_deg: ArrayLike, lat_deg: ArrayLike, lon_deg: ArrayLike
    ) -> NDArray[np.float64]:
        """True bearings at the given positions as grid bearings of the frame, in [0, 360)."""
        gamma = self.grid_convergence_deg(lat_deg, lon_deg)
        return wrap_deg(np.asarray(bearing_deg, dtype=float) - gamma)

    def grid_to_true_deg(
        self, bearing_deg: ArrayLike, lat_deg: ArrayLike, lon_deg: ArrayLike
    ) -> NDArray[np.float64]:
        """Grid bearings of the frame at the given positions as true bearings, in [0, 360)."""
        gamma = self.grid_convergence_deg(lat_deg, lon_deg)
        return wrap_deg(np.asarray(bearing_deg, dtype=float) + gamma)


# -- geometry between vessels, free of any map frame -------------------------------------------
#
# Ranges, CPAs and bearings between two vessels are computed from their WGS84 positions,
# true courses and speeds, never in the run's map frame: a transverse Mercator frame for a
# whole country is 2–3 % long a few hundred kilometres from its centre, and undefined
# across the antimeridian. Positions become Earth-centred Cartesian vectors (ECEF, on the
# ellipsoid), velocities the vectors of their local east/north; the relative motion of two
# vessels within a few kilometres is then a straight line in 3-D, exact to (range/R)², i.e.
# to a few parts in 10⁷ at 2 nm. Bearings are measured in each vessel's own tangent plane.

WGS84_A_M = 6_378_137.0
WGS84_F = 1.0 / 298.257223563
WGS84_E2 = WGS84_F * (2.0 - WGS84_F)
_SECOND_ECCENTRICITY_SQ = WGS84_E2 / (1.0 - WGS84_E2)


def ecef_m(lat_deg: ArrayLike, lon_deg: ArrayLike) -> NDArray[np.float64]:
    """Earth-centred Cartesian positions (metres, shape ``(..., 3)``) at height 0."""
    lat = np.radians(np.asarray(lat_deg, dtype=float))
    lon = np.radians(np.asarray(lon_deg, dtype=float))
    sin_lat = np.sin(lat)
    prime_vertical_m = WGS84_A_M / np.sqrt(1.0 - WGS84_E2 * sin_lat * sin_lat)
    return np.stack(
        [
            prime_vertical_m * np.cos(lat) * np.cos(lon),
            prime_vertical_m * np.cos(lat) * np.sin(lon),
            prime_vertical_m * (1.0 - WGS84_E2) * sin_lat,
        ],
        axis=-1,
    )


def surface_normal(lat_deg: ArrayLike, lon_deg: ArrayLike) -> NDArray[np.float64]:
    """The unit normal to the ellipsoid (the "n-vector", shape ``(..., 3)``) at WGS84 positions.

    Interpolating normals between two reports and normalising gives positions on the Earth
    with no map frame, across the antimeridian and at the poles too (``normal_to_lat_lon``).
    """
    lat = np.radians(np.asarray(lat_deg, dtype=float))
    lon = np.radians(np.asarray(lon_deg, dtype=float))
    return np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)


def normal_to_lat_lon(
    x: ArrayLike, y: ArrayLike, z: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """WGS84 (lat_deg, lon_deg) of (not necessarily unit) surface normals."""
    x, y, z = (np.asarray(v, dtype=float) for v in (x, y, z))
    lat_deg = np.degrees(np.arctan2(z, np.hypot(x, y)))
    lon_deg = np.degrees(np.arctan2(y, x))
    return lat_deg, lon_deg


def north_east_units(
    lat_deg: ArrayLike, lon_deg: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The unit vectors of local (geodetic) north and east, shape ``(..., 3)`` each."""
    lat = np.radians(np.asarray(lat_deg, dtype=float))
    lon = np.radians(np.asarray(lon_deg, dtype=float))
    north = np.stack([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)], axis=-1)
    east = np.stack([-np.sin(lon), np.cos(lon), np.zeros_like(lon)], axis=-1)
    return north, east


def velocity_ecef_mps(
    lat_deg: ArrayLike, lon_deg: ArrayLike, speed_mps: ArrayLike, course_deg: ArrayLike
) -> NDArray[np.float64]:
    """A speed along a true course as an Earth-centred velocity vector (m/s). A vessel at
    rest has no velocity whatever her course: AIS gives a stopped vessel's COG as "not
    available" (null), which must not make her motion unknown."""
    north, east = north_east_units(lat_deg, lon_deg)
    course = np.radians(np.asarray(course_deg, dtype=float))
    speed = np.asarray(speed_mps, dtype=float)
    at_rest = speed == 0.0
    north_mps = np.where(at_rest, 0.0, speed * np.cos(course))
    east_mps = np.where(at_rest, 0.0, speed * np.sin(course))
    return north_mps[..., None] * north + east_mps[..., None] * east


def velocity_mps(
    speed_mps: ArrayLike, course_deg: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(north, east) velocity components of a speed along a course.

    The components are along the axes the course is measured from: give a grid course
    (``cog_grid_deg``) for a velocity in the ``LocalFrame``.
    """
    course_rad = np.radians(np.asarray(course_deg, dtype=float))
    speed = np.asarray(speed_mps, dtype=float)
    at_rest = speed == 0.0  # no velocity whatever her course, known or not (velocity_ecef_mps)
    return (
        np.where(at_rest, 0.0, speed * np.cos(course_rad)),
        np.where(at_rest, 0.0, speed * np.sin(course_rad)),
    )


def in_tangent_plane(
    vectors: NDArray[np.float64], lat_deg: ArrayLike, lon_deg: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(north, east) components of 3-D vectors in the tangent plane at (lat, lon)."""
    north, east = north_east_units(lat_deg, lon_deg)
    return np.sum(vectors * north, axis=-1), np.sum(vectors * east, axis=-1)


def true_bearing_deg(
    from_lat_deg: ArrayLike, from_lon_deg: ArrayLike, to_lat_deg: ArrayLike, to_lon_deg: ArrayLike
) -> NDArray[np.float64]:
    """The true bearing of "to" seen from "from", in [0, 360), in the observer's tangent plane
    (equal to the geodesic's azimuth to within (range/R) radians: < 0.04° at 2 nm)."""
    offset = ecef_m(to_lat_deg, to_lon_deg) - ecef_m(from_lat_deg, from_lon_deg)
    d_north, d_east = in_tangent_plane(offset, from_lat_deg, from_lon_deg)
    return wrap_deg(np.degrees(np.arctan2(d_east, d_north)))


def course_in_tangent_plane(
    course_deg: ArrayLike,
    lat_deg: ArrayLike,
    lon_deg: ArrayLike,
    plane_lat_deg: ArrayLike,
    plane_lon_deg: ArrayLike,
) -> NDArray[np.float64]:
    """A true course at (lat, lon) as a direction in the tangent plane at another point
    (turned by the convergence of the meridians between them), in [0, 360)."""
    direction = velocity_ecef_mps(lat_deg, lon_deg, 1.0, course_deg)
    d_north, d_east = in_tangent_plane(direction, plane_lat_deg, plane_lon_deg)
    return wrap_deg(np.degrees(np.arctan2(d_east, d_north)))


_GEOD = Geod(ellps="WGS84")


def sail(
    lat_deg: ArrayLike, lon_deg: ArrayLike, course_deg: ArrayLike, distance_m: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Where a vessel is after ``distance_m`` along the geodesic starting on a true course
    (NaN course or distance: NaN)."""
    lat, lon, course, distance = np.broadcast_arrays(
        *(np.asarray(v, dtype=float) for v in (lat_deg, lon_deg, course_deg, distance_m))
    )
    known = np.isfinite(lat) & np.isfinite(lon) & np.isfinite(course) & np.isfinite(distance)
    out_lat = np.full(lat.shape, np.nan)
    out_lon = np.full(lat.shape, np.nan)
    if known.any():
        lons, lats, _ = _GEOD.fwd(lon[known], lat[known], course[known], distance[known])
        out_lat[known], out_lon[known] = lats, lons
    return out_lat, out_lon
