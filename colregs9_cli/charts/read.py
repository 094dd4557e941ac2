"""Reading chart files into features in WGS84: S-57 cells with their updates, GeoJSON, GeoPackage.

Sources
-------
- S-57 ENC cells (``.000``) through pyogrio and GDAL's S57 driver. The driver is opened with
  ``UPDATES=APPLY`` (update files ``.001``, ``.002``, … lying beside the base cell are applied in
  order), ``SPLIT_MULTIPOINT=ON`` and ``ADD_SOUNDG_DEPTH=ON``; these are passed as dataset open
  options, so no global ``OGR_S57_OPTIONS`` is needed.
- GeoJSON (``.geojson``, ``.json``) and GeoPackage (``.gpkg``) files with the S-57 attribute
  names: the object class in a column ``OBJL`` (the acronym such as ``"DEPARE"`` or its numeric
  S-57 code such as 42), ``DRVAL1`` and optionally ``DRVAL2`` and ``VALSOU``. Features of the
  routeing classes (``FAIRWY``, ``TSSLPT`` …, ``s57_classes.CHANNEL_CLASSES``) are not part of
  the water; ``channels`` reads them from the same files.

Each file is read on its own into ``Features``: its geometries in WGS84 longitude/latitude
with their object class and depths, its coverage and its level of detail, or a ``ChartError``
naming the file. Nothing here knows of the other charts or of the run's frame (``sources``).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray
from pyproj import CRS, Transformer
from pyproj.exceptions import CRSError

from ..errors import ChartError
from .cells import cell_purpose, check_depth_unit, dsid_fields, whole_number
from .gdal_layers import S57_OPEN_OPTIONS, list_layers, read_layer
from .s57_classes import (
    ACRONYM_BY_CODE,
    BLOCKING_CLASSES,
    CHANNEL_CLASSES,
    OBJECT_CLASSES,
    POLYGONAL,
)

S57_SUFFIXES = (".000",)
VECTOR_SUFFIXES = (".geojson", ".json", ".gpkg")


@dataclass(frozen=True)
class Features:
    """One file's features in WGS84 (x lon, y lat), before projection."""

    path: Path
    geometries: NDArray[np.object_]
    object_class: NDArray[np.object_]
    drval1_m: NDArray[np.float64]
    drval2_m: NDArray[np.float64]
    valsou_m: NDArray[np.float64]
    coverage: Any = None  # M_COVR (CATCOV 1 less CATCOV 2) in WGS84; None: not given
    purpose: int = 0  # navigational purpose, 1 overview … 6 berthing (DSID INTU); 0 unknown
    scale: float = math.inf  # compilation scale denominator (DSPM CSCL); inf unknown

    def shapes(self) -> NDArray[np.object_]:
        """Every geometry of the file, its coverage included: where it reaches."""
        if self.coverage is None:
            return self.geometries
        return np.concatenate([self.geometries, np.asarray([self.coverage], dtype=object)])


def _numeric(values: Any, path: Path, column: str) -> NDArray[np.float64]:
    try:
        return np.asarray(
            [np.nan if v is None or v == "" else float(v) for v in values], dtype=float
        )
    except (TypeError, ValueError):
        bad = next(v for v in values if not _is_number(v))
        raise ChartError(
            f"{path}: column {column} has the value {bad!r}, which is not a depth in metres; "
            "fix the file"
        ) from None


def _is_number(value: Any) -> bool:
    try:
        float(value)
    except (TypeError, ValueError):
        return value is None or value == ""
    return True


def _object_class(value: Any, path: Path) -> str | None:
    """The acronym for an OBJL value (acronym or numeric code); None for classes not used."""
    if value is None:
        return None
    text = str(value).strip().upper()
    if text.isdigit():
        return ACRONYM_BY_CODE.get(int(text))
    return text if text in OBJECT_CLASSES else None


def _read_s57(path: Path) -> Features:
    layers = set(list_layers(path))
    parts: list[tuple[NDArray[np.object_], str, Mapping[str, Any]]] = []
    for name in OBJECT_CLASSES:
        if name in layers:
            meta, geometries = read_layer(path, name, **S57_OPEN_OPTIONS)
            parts.append((geometries, name, meta["columns"]))
    features = _assemble(path, parts)
    coverage = None
    if "M_COVR" in layers:
        meta, geometries = read_layer(path, "M_COVR", **S57_OPEN_OPTIONS)
        coverage = _coverage_of(geometries, meta["columns"].get("CATCOV"))
    dsid = dsid_fields(path)
    scale = whole_number(dsid.get("DSPM_CSCL"))
    return dataclasses.replace(
        features,
        coverage=coverage,
        purpose=cell_purpose(dsid.get("DSID_INTU"), path),
        scale=float(scale) if scale else math.inf,
    )


def _coverage_of(geometries: NDArray[np.object_], catcov: Any) -> Any:
    """The union of the CATCOV 1 ("coverage available") areas less the CATCOV 2 ones; None
    when there are none."""
    polygonal = np.isin(shapely.get_type_id(geometries), POLYGONAL)
    codes = np.ones(len(geometries)) if catcov is None else _numeric(catcov, Path(), "CATCOV")
    codes = np.where(np.isnan(codes), 1.0, codes)
    covered = geometries[polygonal & (codes == 1.0)]
    if len(covered) == 0:
        return None
    uncovered = geometries[polygonal & (codes == 2.0)]
    return shapely.difference(shapely.union_all(covered), shapely.union_all(uncovered))


def _read_vector(path: Path) -> Features:
    """A GeoJSON/GeoPackage chart with S-57 attribute names. Features of class M_COVR (with
    CATCOV) give its coverage, and their INTU (navigational purpose) and CSCL (compilation
    scale) its level of detail, as a cell's DSID would.

    A layer without an OBJL column takes its class from its name (``DEPARE``, ``M_COVR`` …),
    and a table named DSID with DSID_INTU and DSPM_CSCL gives the level of detail: the layout
    ``ogr2ogr -f GPKG out.gpkg CELL.000`` writes. DRVAL1 is needed where there are depth areas.
    """
    parts: list[tuple[NDArray[np.object_], str | NDArray[np.object_], Mapping[str, Any]]] = []
    coverage_parts: list[Any] = []
    detail: dict[str, float] = {}
    for layer in list_layers(path):
        meta, geometries = read_layer(path, layer)
        columns = meta["columns"]
        if layer.upper() == "DSID":
            _dsid_detail(columns, detail)
            duni = columns.get("DSPM_DUNI")
            check_depth_unit(path, duni[0] if duni is not None and len(duni) else None)
            continue
        if len(geometries) == 0:
            continue
        objl = columns.get("OBJL")
        if objl is None:
            if not _is_class_name(layer):
                raise ChartError(
                    f"{path}: layer {layer} has no column OBJL; a GeoJSON/GeoPackage chart needs "
                    "OBJL (S-57 object class, e.g. DEPARE) and DRVAL1 (shallowest depth, m), or "
                    "layers named after their S-57 object class"
                )
            objl = np.full(len(geometries), layer.upper(), dtype=object)
        classes = np.asarray([_object_class(v, path) for v in objl], dtype=object)
        if "DRVAL1" not in columns and np.isin(classes, ["DEPARE", "DRGARE"]).any():
            raise ChartError(
                f"{path}: layer {layer} has depth areas but no column DRVAL1; a GeoJSON/"
                "GeoPackage chart needs OBJL (S-57 object class, e.g. DEPARE) and DRVAL1 "
                "(shallowest depth, m)"
            )
        geometries = to_wgs84(geometries, meta["crs"], path)
        parts.append((geometries, classes, columns))
        is_coverage = np.asarray(
            [str(v).strip().upper() in ("M_COVR", "302") for v in objl], dtype=bool
        )
        if is_coverage.any():
            catcov = columns.get("CATCOV")
            coverage_parts.append(
                _coverage_of(
                    geometries[is_coverage], None if catcov is None else catcov[is_coverage]
                )
            )
            for name, column in (("INTU", "purpose"), ("CSCL", "scale")):
                if name in columns:
                    values = _numeric(columns[name][is_coverage], path, name)
                    if np.isfinite(values).any():
                        detail[column] = float(
                            np.nanmax(values) if column == "purpose" else np.nanmin(values)
                        )
    features = _assemble(path, parts)
    known = [c for c in coverage_parts if c is not None]
    return dataclasses.replace(
        features,
        coverage=shapely.union_all(known) if known else None,
        purpose=int(detail.get("purpose", 0)),
        scale=detail.get("scale", math.inf),
    )


def _is_class_name(layer: str) -> bool:
    """A layer named after an S-57 object class the charts are read for (its features take
    that class); routeing layers (FAIRWY …) are left to ``channels``."""
    name = layer.upper()
    return name in OBJECT_CLASSES or name in CHANNEL_CLASSES or name == "M_COVR"


def _dsid_detail(columns: Mapping[str, Any], detail: dict[str, float]) -> None:
    """Navigational purpose and compilation scale from a DSID table (S-57 field names)."""
    for name, key in (("DSID_INTU", "purpose"), ("DSPM_CSCL", "scale")):
        values = columns.get(name)
        number = whole_number(values[0]) if values is not None and len(values) else None
        if number:
            detail[key] = float(number)


def to_wgs84(geometries: NDArray[np.object_], crs: str | None, path: Path) -> Any:
    """The geometries in WGS84 longitude/latitude; coordinates off the Earth are an error
    naming the file (a projected chart without its CRS, say)."""
    return _on_earth(_transformed(geometries, crs, path), path)


def _on_earth(geometries: NDArray[np.object_], path: Path) -> NDArray[np.object_]:
    present = geometries[~shapely.is_empty(geometries)] if len(geometries) else geometries
    if len(present) == 0:
        return geometries
    lon_min, lat_min, lon_max, lat_max = shapely.total_bounds(present)
    if not (-90.0 <= lat_min <= lat_max <= 90.0 and -180.0 <= lon_min <= lon_max <= 180.0):
        raise ChartError(
            f"{path}: coordinates off the Earth (longitude {lon_min:g} to {lon_max:g}, latitude "
            f"{lat_min:g} to {lat_max:g}); give the chart in WGS84 longitude/latitude, or with "
            "its coordinate reference system"
        )
    return geometries


def _transformed(geometries: NDArray[np.object_], crs: str | None, path: Path) -> Any:
    if crs is None:
        return geometries
    try:
        source = CRS.from_user_input(crs)
    except CRSError:
        raise ChartError(f"{path}: unknown coordinate reference system {crs!r}") from None
    if source.equals(CRS.from_epsg(4326), ignore_axis_order=True):
        return geometries
    transformer = Transformer.from_crs(source, "EPSG:4326", always_xy=True)
    return shapely.transform(
        geometries, lambda xy: np.column_stack(transformer.transform(xy[:, 0], xy[:, 1]))
    )


def _assemble(
    path: Path,
    parts: Sequence[tuple[NDArray[np.object_], str | NDArray[np.object_], Mapping[str, Any]]],
) -> Features:
    geometries: list[NDArray[np.object_]] = []
    classes: list[NDArray[np.object_]] = []
    drval1: list[NDArray[np.float64]] = []
    drval2: list[NDArray[np.float64]] = []
    valsou: list[NDArray[np.float64]] = []
    for part_geometries, part_class, columns in parts:
        n = len(part_geometries)
        geometries.append(part_geometries)
        classes.append(
            np.full(n, part_class, dtype=object) if isinstance(part_class, str) else part_class
        )
        for out, column in ((drval1, "DRVAL1"), (drval2, "DRVAL2"), (valsou, "VALSOU")):
            values = columns.get(column)
            out.append(np.full(n, np.nan) if values is None else _numeric(values, path, column))
    if not geometries:
        return Features(path, *(np.empty(0, dtype=object),) * 2, *(np.empty(0),) * 3)
    features = Features(
        path,
        np.concatenate(geometries),
        np.concatenate(classes),
        np.concatenate(drval1),
        np.concatenate(drval2),
        np.concatenate(valsou),
    )
    missing = shapely.is_missing(features.geometries)
    # Land or a hazard without a geometry would leave water where there is none.
    blocking = missing & np.isin(features.object_class, BLOCKING_CLASSES)
    if blocking.any():
        first = features.object_class[blocking][0]
        raise ChartError(
            f"{path}: {int(blocking.sum())} land or hazard feature(s) ({first} first) have no "
            "geometry GDAL could read; give each its geometry (a Polygon, LineString or Point "
            "in the file's coordinates), or leave the feature out"
        )
    keep = ~missing & (features.object_class != None)  # noqa: E711
    return Features(
        path,
        features.geometries[keep],
        features.object_class[keep],
        features.drval1_m[keep],
        features.drval2_m[keep],
        features.valsou_m[keep],
    )


def read_features(path: Path) -> Features:
    """One chart file's features in WGS84; a ``ChartError`` where it is no usable chart."""
    path = Path(path)
    if path.is_dir():
        raise ChartError(f"{path}: a directory, not a chart file; give the chart file itself")
    if not path.is_file():
        raise ChartError(f"{path}: no such chart file; check the path")
    suffix = path.suffix.lower()
    if suffix in S57_SUFFIXES:
        features = _read_s57(path)
    elif suffix in VECTOR_SUFFIXES:
        features = _read_vector(path)
    elif len(suffix) == 4 and suffix[1:].isdigit():
        raise ChartError(
            f"{path}: an S-57 update file ({suffix}); give its base cell "
            f"({path.with_suffix('.000').name}), whose update files beside it are applied"
        )
    else:
        raise ChartError(
            f"{path}: unknown chart type {suffix or '(no suffix)'!r}; give an S-57 base cell "
            "(.000), a GeoJSON (.geojson) or a GeoPackage (.gpkg)"
        )
    depth = np.isin(features.object_class, ["DEPARE", "DRGARE"])
    polygonal = np.isin(shapely.get_type_id(features.geometries), POLYGONAL)
    if not (depth & polygonal).any():
        raise ChartError(
            f"{path}: the chart has no depth areas (DEPARE or DRGARE polygons); give a chart "
            "with depth information"
        )
    unknown = depth & polygonal & np.isnan(features.drval1_m)
    if unknown.any():
        # A depth area of unknown depth would be read as too shallow for every vessel.
        raise ChartError(
            f"{path}: {int(unknown.sum())} of {int((depth & polygonal).sum())} depth areas have "
            "no DRVAL1 (their least depth); give each depth area its DRVAL1 in metres, or "
            "leave out those of unknown depth"
        )
    return features
