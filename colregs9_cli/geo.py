"""The run's local metric frame: a transverse Mercator projection centred on the region.

Positions in the frame are ``north_m, east_m`` (the paper's NED frame, down omitted).
The frame is chosen once per run and carried with the data; nothing falls back to a default.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pyproj import CRS, Transformer

from .errors import ParameterError


@dataclass(frozen=True)
class LocalFrame:
    """A transverse Mercator frame with its origin at (``lat0_deg``, ``lon0_deg``)."""

    lat0_deg: float
    lon0_deg: float
    crs: CRS = field(init=False, repr=False, compare=False)
    _forward: Transformer = field(init=False, repr=False, compare=False)
    _inverse: Transformer = field(init=False, repr=False, compare=False)

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

    @classmethod
    def centred_on(
        cls, lat_min: float, lat_max: float, lon_min: float, lon_max: float
    ) -> LocalFrame:
        return cls((lat_min + lat_max) / 2.0, (lon_min + lon_max) / 2.0)

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
