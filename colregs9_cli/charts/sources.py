"""Charts read but not yet projected, and which of them decides where they overlap.

Coverage (the charted extent) is what a chart says it covers: its M_COVR areas with CATCOV 1
less those with CATCOV 2 (an S-57 cell's ``M_COVR`` layer, or features of class M_COVR in a
GeoJSON/GeoPackage); a chart without them covers the union of its depth areas, land and
structures.

Several charts are ranked most detailed first (``by_detail``): the higher navigational
purpose (DSID INTU, else the digit in an S-57 cell name's third character; for GeoJSON/
GeoPackage an ``INTU`` property on its M_COVR features or a DSID table), then the larger
compilation scale (DSPM CSCL; ``CSCL`` on M_COVR), then the order given. Each chart decides
only where no more detailed one covers: its features are clipped to its coverage less theirs.

Here the files are read (``read``, ``cells``) into a ``ChartSource``, and each file's features
are projected into the run's frame and clipped to the part of the coverage it decides
(``claimed_by_detail``); ``water`` merges what is left into one ``Chart``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from ..errors import ChartError
from ..geo import LocalFrame
from .cells import CellInfo, s57_cell_info
from .gdal_layers import first_line
from .read import S57_SUFFIXES, Features, read_features
from .s57_classes import OBJECT_CLASSES, POLYGONAL, ChartLayer


@dataclass(frozen=True)
class ChartSource:
    """Charts read from their files in WGS84, not yet projected: read once, project once.
    ``cells`` describes the S-57 cells among them."""

    paths: tuple[Path, ...]
    features: tuple[Features, ...]
    cells: tuple[CellInfo, ...] = ()

    @property
    def update_gaps(self) -> dict[str, tuple[str, ...]]:
        """The update files missing from each cell read with a gap accepted, by cell name;
        empty when every update sequence is whole."""
        return {cell.name: cell.missing_updates for cell in self.cells if cell.missing_updates}

    def near(self, lat_deg: ArrayLike, lon_deg: ArrayLike, margin_deg: float) -> ChartSource:
        """The charts whose box, widened by ``margin_deg``, holds one of the positions: those
        that can judge a ship domain there. The rest would only stretch the run's one frame
        (centred on the charts) away from the vessels."""
        lat = np.asarray(lat_deg, dtype=float)
        lon = np.asarray(lon_deg, dtype=float)
        kept = []
        for features in self.features:
            west, south, east, north = shapely.total_bounds(features.shapes())
            width = east - west + 2.0 * margin_deg
            # Eastwards from the widened west edge, round 180° if need be.
            along = np.mod(lon - (west - margin_deg), 360.0) <= width if width < 360.0 else True
            if ((lat >= south - margin_deg) & (lat <= north + margin_deg) & along).any():
                kept.append(features)
        paths = tuple(f.path for f in kept)
        return ChartSource(paths, tuple(kept), tuple(c for c in self.cells if c.path in paths))

    def bounds_wgs84(self) -> tuple[float, float, float, float]:
        """(lat_min, lat_max, lon_min, lon_max) of the charts' features and coverage."""
        lon_min, lat_min, lon_max, lat_max = shapely.total_bounds(
            np.concatenate([f.shapes() for f in self.features])
        )
        return float(lat_min), float(lat_max), float(lon_min), float(lon_max)


def read_charts(paths: Sequence[Path], accept_gaps: bool = False) -> ChartSource:
    """Read every chart file (S-57, GeoJSON, GeoPackage); errors name the file. An S-57
    cell's update sequence is checked first (``s57_cell_info``)."""
    if not paths:
        raise ChartError("no chart given; give at least one chart file")
    files = tuple(Path(p) for p in paths)
    cells = tuple(
        s57_cell_info(p, accept_gaps)
        for p in files
        if p.suffix.lower() in S57_SUFFIXES and p.is_file()
    )
    return ChartSource(paths=files, features=tuple(read_features(p) for p in files), cells=cells)


def by_detail(features: Sequence[Features]) -> list[Features]:
    """Most detailed first: higher navigational purpose, then larger compilation scale
    (smaller denominator), then the order given."""
    order = sorted(range(len(features)), key=lambda i: (-features[i].purpose, features[i].scale, i))
    return [features[i] for i in order]


def project(geometries: NDArray[np.object_], frame: LocalFrame) -> Any:
    """WGS84 geometries in ``frame`` (east, north in metres), invalid ones repaired."""

    def lonlat_to_east_north(xy: NDArray[np.float64]) -> NDArray[np.float64]:
        north_m, east_m = frame.to_local(xy[:, 1], xy[:, 0])
        return np.column_stack([east_m, north_m])

    projected = shapely.transform(geometries, lonlat_to_east_north)
    invalid = ~shapely.is_valid(projected)
    if invalid.any():
        # A ring with a spike is repaired into its area and a line: keep the area.
        projected[invalid] = same_dimension(
            shapely.make_valid(projected[invalid]), projected[invalid]
        )
    return projected


def project_file(
    path: Path,
    geometries: Any,
    frame: LocalFrame,
    what: str = "feature",
    fix: str = "its rings (closed, at least three distinct vertices, lon/lat in degrees)",
) -> Any:
    """A file's geometries in the frame; one GEOS cannot repair names the file, what it is
    and what to fix."""
    try:
        return project(geometries, frame)
    except shapely.errors.GEOSException as exc:
        raise ChartError(
            f"{path}: a {what}'s geometry cannot be used ({first_line(exc)}); fix {fix}"
        ) from None


def _file_coverage(features: Features, geometries: NDArray[np.object_], frame: LocalFrame) -> Any:
    """A file's coverage in the frame: its M_COVR, else the union of its areas
    (``geometries``: its features in the frame)."""
    if features.coverage is not None:
        return project(np.array([features.coverage], dtype=object), frame)[0]
    role = np.asarray([OBJECT_CLASSES[c][1] for c in features.object_class], dtype=object)
    areal = np.isin(role, [ChartLayer.DEPARE, ChartLayer.DRGARE, ChartLayer.LNDARE]) & np.isin(
        shapely.get_type_id(geometries), POLYGONAL
    )
    return shapely.union_all(geometries[areal])


def claimed_by_detail(
    features: Sequence[Features], frame: LocalFrame
) -> tuple[list[NDArray[np.object_]], list[Any]]:
    """Each file's projected geometries, cut to where no more detailed file has coverage (a
    coarse cell decides only outside the detailed one), and each file's coverage left."""
    projected = [project_file(f.path, f.geometries, frame) for f in features]
    coverages = [_file_coverage(f, g, frame) for f, g in zip(features, projected, strict=True)]
    if len(features) == 1:
        return projected, coverages
    claimed = shapely.Polygon()
    kept_geometries, kept_coverages = [], []
    for geometries, coverage in zip(projected, coverages, strict=True):
        own = shapely.difference(coverage, claimed)
        clipped = same_dimension(shapely.intersection(geometries, own), geometries)
        kept_geometries.append(clipped)
        kept_coverages.append(own)
        claimed = shapely.union(claimed, coverage)
    return kept_geometries, kept_coverages


def same_dimension(clipped: NDArray[np.object_], original: NDArray[np.object_]) -> Any:
    """``clipped`` with the parts of a lower dimension than the feature's dropped.

    GEOS may return a polygon clipped along an edge of the clip as a geometry collection (the
    area and a line where they touch): it would no longer count as a depth area at all.
    """
    clipped = np.array(clipped, dtype=object)
    mixed = np.flatnonzero(shapely.get_type_id(clipped) == shapely.GeometryType.GEOMETRYCOLLECTION)
    for i in mixed:
        dimension = shapely.get_dimensions(original[i])
        parts = shapely.get_parts(clipped[i])
        parts = parts[shapely.get_dimensions(parts) == dimension]
        clipped[i] = shapely.union_all(parts) if len(parts) else shapely.Polygon()
    return clipped
