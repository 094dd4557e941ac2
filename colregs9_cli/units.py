"""Unit conversions, applied once at the edges. Internal units: metres, seconds, m/s, degrees."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

METRES_PER_NAUTICAL_MILE = 1852.0
MPS_PER_KNOT = METRES_PER_NAUTICAL_MILE / 3600.0


def knots_to_mps(speed_kn: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(speed_kn, dtype=float) * MPS_PER_KNOT


def mps_to_knots(speed_mps: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(speed_mps, dtype=float) / MPS_PER_KNOT


def nautical_miles_to_metres(distance_nm: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(distance_nm, dtype=float) * METRES_PER_NAUTICAL_MILE


def metres_to_nautical_miles(distance_m: ArrayLike) -> NDArray[np.float64]:
    return np.asarray(distance_m, dtype=float) / METRES_PER_NAUTICAL_MILE


def wrap_deg(angle_deg: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles into [0, 360)."""
    wrapped = np.mod(np.asarray(angle_deg, dtype=float), 360.0)
    # np.mod(-1e-17, 360) rounds to 360.0, which is outside the half-open range
    return np.where(wrapped >= 360.0, 0.0, wrapped)


def signed_angle_deg(angle_deg: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles into [-180, 180)."""
    return wrap_deg(np.asarray(angle_deg, dtype=float) + 180.0) - 180.0
