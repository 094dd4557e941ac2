"""Charts: depth areas, land and hazards in the run's local frame, and the navigable water.

Geometry convention: every shapely geometry of a ``Chart`` is in the local frame of
``colregs9_cli.geo.LocalFrame`` with **x = east_m and y = north_m**. Functions that take
positions take them as ``(north_m, east_m)``, like the rest of the package.

Sources
-------
- S-57 ENC cells (``.000``) through pyogrio and GDAL's S57 driver. The driver is opened with
  ``UPDATES=APPLY`` (update files ``.001``, ``.002``, … lying beside the base cell are applied in
  order), ``SPLIT_MULTIPOINT=ON`` and ``ADD_SOUNDG_DEPTH=ON``; these are passed as dataset open
  options, so no global ``OGR_S57_OPTIONS`` is needed.
- GeoJSON (``.geojson``, ``.json``) and GeoPackage (``.gpkg``) files with the S-57 attribute
  names: the object class in a column ``OBJL`` (the acronym such as ``"DEPARE"`` or its numeric
  S-57 code such as 42), ``DRVAL1`` and optionally ``DRVAL2`` and ``VALSOU``.

Object classes used: DEPARE and DRGARE (dredged areas count as depth areas), LNDARE (land),
PONTON, HULKES, FLODOC and DRYDOC areas (structures that cut holes in the depth areas; they
are treated like land), and OBSTRN, WRECKS and UWTROC as point hazards. A hazard, and a land
area charted as a point or line, is buffered by ``HAZARD_RADIUS_M``. A hazard blocks a
vessel when its sounding ``VALSOU`` is shallower than draught + UKC, or when it has no
sounding (unknown depth is treated as dangerous, as ECDIS does).

Navigable water for draught T is the union of depth areas with ``DRVAL1 >= T + UKC``, minus
land and structures, with gaps narrower than ``SLIVER_TOLERANCE_M`` closed (see there), minus
the blocking hazards.

Coverage (the charted extent) is what a chart says it covers: its M_COVR areas with CATCOV 1
less those with CATCOV 2 (an S-57 cell's ``M_COVR`` layer, or features of class M_COVR in a
GeoJSON/GeoPackage); a chart without them covers the union of its depth areas, land and
structures. A position outside it is "unknown", never "deep", and so is a ship domain that
is not wholly inside it (``Chart.covers_shapes``).

Several charts are ranked most detailed first (``_by_detail``): the higher navigational
purpose (DSID INTU, else the digit in an S-57 cell name's third character; for GeoJSON/
GeoPackage an ``INTU`` property on its M_COVR features or a DSID table), then the larger
compilation scale (DSPM CSCL; ``CSCL`` on M_COVR), then the order given. Each chart decides
only where no more detailed one covers: its features are clipped to its coverage less theirs.

An S-57 cell's update files are checked before it is read (``s57_cell_info``): a gap in their
sequence is a ``ChartError`` unless accepted, and each cell's edition, update number, issue
date, purpose and scale are kept in ``CellInfo``.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path
from typing import Any

import numpy as np
import pyogrio
import shapely
from numpy.typing import ArrayLike, NDArray
from pyogrio.errors import DataLayerError, DataSourceError, FieldError, GeometryError
from pyproj import CRS, Transformer
from pyproj.exceptions import CRSError

from ..errors import ChartError, ParameterError
from ..geo import FRAME_REACH_M, LocalFrame
from .s57_records import record_count
from .s57_updates import applied_updates, update_files_beside

HAZARD_RADIUS_M = 10.0
# Depth areas that should meet often leave slivers of gap between them (or of land filling the
# gap) once a chart has been converted between coordinate systems or rounded: an edge that is
# one segment in one area and two in its neighbour does not stay straight under a projection.
# Millimetres to centimetres wide, they would punch spurious holes into the navigable water and
# make any ellipse over them "restricted". Gaps narrower than this are closed; nothing a vessel
# could be stopped by is that narrow.
SLIVER_TOLERANCE_M = 0.1
S57_OPEN_OPTIONS = {"UPDATES": "APPLY", "SPLIT_MULTIPOINT": "ON", "ADD_SOUNDG_DEPTH": "ON"}
S57_SUFFIXES = (".000",)
VECTOR_SUFFIXES = (".geojson", ".json", ".gpkg")


class ChartLayer(StrEnum):
    """The role a chart feature plays."""

    DEPARE = "DEPARE"
    DRGARE = "DRGARE"
    LNDARE = "LNDARE"
    HAZARD = "HAZARD"


# S-57 object class acronym → (numeric code, role).
_OBJECT_CLASSES: dict[str, tuple[int, ChartLayer]] = {
    "DEPARE": (42, ChartLayer.DEPARE),
    "DRGARE": (46, ChartLayer.DRGARE),
    "LNDARE": (71, ChartLayer.LNDARE),
    "PONTON": (95, ChartLayer.LNDARE),
    "HULKES": (65, ChartLayer.LNDARE),
    "FLODOC": (57, ChartLayer.LNDARE),
    "DRYDOC": (47, ChartLayer.LNDARE),
    "OBSTRN": (86, ChartLayer.HAZARD),
    "WRECKS": (159, ChartLayer.HAZARD),
    "UWTROC": (153, ChartLayer.HAZARD),
}
_ACRONYM_BY_CODE = {code: name for name, (code, _) in _OBJECT_CLASSES.items()}
_BLOCKING_CLASSES = [
    name
    for name, (_, role) in _OBJECT_CLASSES.items()
    if role in (ChartLayer.LNDARE, ChartLayer.HAZARD)
]
_POLYGONAL = (shapely.GeometryType.POLYGON, shapely.GeometryType.MULTIPOLYGON)


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


@dataclass(frozen=True)
class _Features:
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
        return _ACRONYM_BY_CODE.get(int(text))
    return text if text in _OBJECT_CLASSES else None


@contextmanager
def _gdal_quiet() -> Iterator[None]:
    """GDAL's warnings (pyogrio passes them on as ``RuntimeWarning``) kept off stderr: a file
    GDAL cannot read is one ``ChartError``, and what it can read needs no remark."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


def _read_layer(path: Path, layer: str | int, **options: str) -> tuple[dict[str, Any], Any]:
    try:
        with _gdal_quiet():  # and shapely's about NaN vertices: _check_finite names them
            meta, _, wkb, field_data = pyogrio.raw.read(path, layer=layer, **options)
            geometries = shapely.from_wkb(wkb) if wkb is not None else np.empty(0, dtype=object)
    except (
        DataSourceError,
        DataLayerError,
        FieldError,
        GeometryError,
        RuntimeError,
        shapely.errors.GEOSException,
    ) as exc:
        raise ChartError(
            f"{path}: cannot read layer {layer} ({_first_line(exc)}); give an S-57 .000, "
            "GeoJSON or GeoPackage chart"
        ) from None
    columns = dict(zip(meta["fields"], field_data, strict=True))
    _check_finite(geometries, path, layer, columns)
    return {"crs": meta.get("crs"), "columns": columns}, geometries


def _check_finite(
    geometries: NDArray[np.object_], path: Path, layer: str | int, columns: Mapping[str, Any]
) -> None:
    """A vertex that is not a finite number (NaN, inf) is an error naming the feature: GEOS
    cannot build or repair such a geometry."""
    if len(geometries) == 0:
        return
    coordinates, owner = shapely.get_coordinates(geometries, return_index=True)
    bad = ~np.isfinite(coordinates).all(axis=1)
    if not bad.any():
        return
    feature = int(owner[bad][0])
    objl = columns.get("OBJL")
    kind = f" ({objl[feature]})" if objl is not None and objl[feature] is not None else ""
    x, y = coordinates[bad][0]
    raise ChartError(
        f"{path}: layer {layer}, feature {feature + 1}{kind}: the vertex ({x}, {y}) is not a "
        "finite number; fix or remove that feature"
    )


def _first_line(exc: BaseException) -> str:
    return str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__


def _list_layers(path: Path) -> list[str]:
    try:
        with _gdal_quiet():
            return [str(name) for name, _ in pyogrio.list_layers(path)]
    except (DataSourceError, DataLayerError, RuntimeError) as exc:
        raise ChartError(
            f"{path}: not a chart GDAL can open ({_first_line(exc)}); give an S-57 .000, "
            "GeoJSON or GeoPackage chart"
        ) from None


def _read_s57(path: Path) -> _Features:
    layers = set(_list_layers(path))
    parts: list[tuple[NDArray[np.object_], str, Mapping[str, Any]]] = []
    for name in _OBJECT_CLASSES:
        if name in layers:
            meta, geometries = _read_layer(path, name, **S57_OPEN_OPTIONS)
            parts.append((geometries, name, meta["columns"]))
    features = _assemble(path, parts)
    coverage = None
    if "M_COVR" in layers:
        meta, geometries = _read_layer(path, "M_COVR", **S57_OPEN_OPTIONS)
        coverage = _coverage_of(geometries, meta["columns"].get("CATCOV"))
    dsid = _dsid_fields(path)
    scale = _whole_number(dsid.get("DSPM_CSCL"))
    return dataclasses.replace(
        features,
        coverage=coverage,
        purpose=cell_purpose(dsid.get("DSID_INTU"), path),
        scale=float(scale) if scale else math.inf,
    )


def cell_purpose(intu: Any, path: Path) -> int:
    """A cell's navigational purpose, 1 (overview) … 6 (berthing): DSID INTU, else the digit
    in the third character of its name (``US5CA72M``: 5, harbour), else 0 (unknown)."""
    purpose = _whole_number(intu)
    if purpose is not None and 1 <= purpose <= 6:
        return purpose
    digit = Path(path).name[2:3]
    return int(digit) if digit.isdigit() and 1 <= int(digit) <= 6 else 0


def _coverage_of(geometries: NDArray[np.object_], catcov: Any) -> Any:
    """The union of the CATCOV 1 ("coverage available") areas less the CATCOV 2 ones; None
    when there are none."""
    polygonal = np.isin(shapely.get_type_id(geometries), _POLYGONAL)
    codes = np.ones(len(geometries)) if catcov is None else _numeric(catcov, Path(), "CATCOV")
    codes = np.where(np.isnan(codes), 1.0, codes)
    covered = geometries[polygonal & (codes == 1.0)]
    if len(covered) == 0:
        return None
    uncovered = geometries[polygonal & (codes == 2.0)]
    return shapely.difference(shapely.union_all(covered), shapely.union_all(uncovered))


def _whole_number(value: Any) -> int | None:
    return int(value) if value is not None and str(value).strip().isdigit() else None


def _dsid_fields(path: Path, apply_updates: bool = True) -> dict[str, Any]:
    """The DSID record of an S-57 cell (after its updates, unless not ``apply_updates``: the
    file's own; an update file's own too), or nothing when GDAL has none."""
    options = {**S57_OPEN_OPTIONS, "UPDATES": "APPLY" if apply_updates else "IGNORE"}
    try:
        with _gdal_quiet():
            meta, _, _, values = pyogrio.raw.read(
                path, layer="DSID", read_geometry=False, **options
            )
    except (DataSourceError, DataLayerError, FieldError, RuntimeError):
        return {}
    return {
        name: column[0] for name, column in zip(meta["fields"], values, strict=True) if len(column)
    }


def _read_vector(path: Path) -> _Features:
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
    for layer in _list_layers(path):
        meta, geometries = _read_layer(path, layer)
        columns = meta["columns"]
        if layer.upper() == "DSID":
            _dsid_detail(columns, detail)
            duni = columns.get("DSPM_DUNI")
            _check_depth_unit(path, duni[0] if duni is not None and len(duni) else None)
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
        geometries = _to_wgs84(geometries, meta["crs"], path)
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
    return layer.upper() in _OBJECT_CLASSES or layer.upper() == "M_COVR"


def _dsid_detail(columns: Mapping[str, Any], detail: dict[str, float]) -> None:
    """Navigational purpose and compilation scale from a DSID table (S-57 field names)."""
    for name, key in (("DSID_INTU", "purpose"), ("DSPM_CSCL", "scale")):
        values = columns.get(name)
        number = _whole_number(values[0]) if values is not None and len(values) else None
        if number:
            detail[key] = float(number)


def _to_wgs84(geometries: NDArray[np.object_], crs: str | None, path: Path) -> Any:
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
) -> _Features:
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
        return _Features(path, *(np.empty(0, dtype=object),) * 2, *(np.empty(0),) * 3)
    features = _Features(
        path,
        np.concatenate(geometries),
        np.concatenate(classes),
        np.concatenate(drval1),
        np.concatenate(drval2),
        np.concatenate(valsou),
    )
    missing = shapely.is_missing(features.geometries)
    # Land or a hazard without a geometry would leave water where there is none.
    blocking = missing & np.isin(features.object_class, _BLOCKING_CLASSES)
    if blocking.any():
        first = features.object_class[blocking][0]
        raise ChartError(
            f"{path}: {int(blocking.sum())} land or hazard feature(s) ({first} first) have no "
            "geometry GDAL could read; give each its geometry (a Polygon, LineString or Point "
            "in the file's coordinates), or leave the feature out"
        )
    keep = ~missing & (features.object_class != None)  # noqa: E711
    return _Features(
        path,
        features.geometries[keep],
        features.object_class[keep],
        features.drval1_m[keep],
        features.drval2_m[keep],
        features.valsou_m[keep],
    )


def _read_features(path: Path) -> _Features:
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
    else:
        raise ChartError(
            f"{path}: unknown chart type {suffix or '(no suffix)'!r}; give an S-57 base cell "
            "(.000), a GeoJSON (.geojson) or a GeoPackage (.gpkg)"
        )
    depth = np.isin(features.object_class, ["DEPARE", "DRGARE"])
    polygonal = np.isin(shapely.get_type_id(features.geometries), _POLYGONAL)
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


@dataclass(frozen=True)
class CellInfo:
    """An S-57 cell's identity as read from its DSID record after the updates were applied.

    ``update_files`` are the update files beside the base cell, in order; ``missing_updates``
    names the files missing from that sequence, when the user accepted the gap (GDAL then
    applies the updates before the gap and none after it: ``update_number`` tells which).
    ``purpose`` and ``scale`` rank the cell where charts overlap (``project_charts``).
    """

    path: Path
    name: str
    edition: int | None
    update_number: int | None
    issue_date: str | None
    update_files: tuple[Path, ...]
    missing_updates: tuple[str, ...]
    purpose: int = 0  # navigational purpose (``cell_purpose``); 0 unknown
    scale: int | None = None  # compilation scale denominator (DSPM CSCL)


def s57_cell_info(path: Path, accept_gaps: bool = False) -> CellInfo:
    """The cell's edition, update number and issue date; a gap in its update sequence is a
    ``ChartError`` unless ``accept_gaps`` (GDAL would stop at the gap without a word)."""
    updates, missing = update_files_beside(path)
    if missing and not accept_gaps:
        raise ChartError(
            f"{path}: the update sequence has a gap, {', '.join(missing)} missing beside "
            f"{', '.join(u.name for u in updates)}; GDAL would apply the updates before the gap "
            "and silently skip the rest. Put the missing update files beside the cell, or "
            "pass --accept-chart-gaps to use the cell as updated up to the gap"
        )
    records = _whole_records(path, updates)
    _check_update_identities(path, applied_updates(updates, missing))
    fields = _dsid_fields(path)
    _check_all_records(path, records, fields)
    _check_updates_applied(path, updates, missing, _whole_number(fields.get("DSID_UPDN")))
    _check_depth_unit(path, fields.get("DSPM_DUNI"))
    issue = fields.get("DSID_ISDT")
    return CellInfo(
        path=path,
        name=str(fields.get("DSID_DSNM") or path.name),
        edition=_whole_number(fields.get("DSID_EDTN")),
        update_number=_whole_number(fields.get("DSID_UPDN")),
        issue_date=None if not issue else str(issue),
        update_files=tuple(updates),
        missing_updates=tuple(missing),
        purpose=cell_purpose(fields.get("DSID_INTU"), path),
        scale=_whole_number(fields.get("DSPM_CSCL")),
    )


def _whole_records(path: Path, updates: Sequence[Path]) -> int:
    """The number of records of the base cell, once every record of the cell and its updates
    is found to end within its file (GDAL reads a file cut inside a record up to the cut, or
    refuses it with a message about its leaders)."""
    found = _records_of(path)
    for update in updates:
        _records_of(update)
    return found


def _records_of(file: Path) -> int:
    count = record_count(file)
    if count is None:
        raise ChartError(
            f"{file}: cut short or corrupt: a record of the file runs past its end or has "
            "no length in its leader (ISO 8211); download the cell and its updates again"
        )
    return count


def _check_update_identities(path: Path, updates: Sequence[Path]) -> None:
    """Each update file GDAL applies is, by its own DSID, the update of this edition of this
    cell that its name says: GDAL skips a stale, swapped or foreign update and every later
    one without a word, and may take its update number, so that the check after reading
    (``_check_updates_applied``) would blame the wrong file."""
    if not updates:
        return
    base = _dsid_fields(path, apply_updates=False)
    cell = Path(str(base.get("DSID_DSNM") or path.name)).stem
    edition = _whole_number(base.get("DSID_EDTN"))
    for update in updates:
        own = _dsid_fields(update, apply_updates=False)
        if not own:  # not readable as S-57: the check after reading names it
            continue
        name = Path(str(own.get("DSID_DSNM") or update.name)).stem
        its_edition = _whole_number(own.get("DSID_EDTN"))
        number = _whole_number(own.get("DSID_UPDN"))
        expected = int(update.suffix[1:])
        if (name, its_edition, number) != (cell, edition, expected):
            raise ChartError(
                f"{update}: by its DSID, update {number} of edition {its_edition} of cell "
                f"{name}, not update {expected} of edition {edition} of {cell}; put update "
                f"{expected} of this edition in its place, or move it and the later updates "
                "away to use the cell as updated before it"
            )


# DSSI's counts of the records of each kind: meta, cartographic, geo and collection feature
# records, then isolated nodes, connected nodes, edges and faces.
_DSSI_COUNTS = ("NOMR", "NOCR", "NOGR", "NOLR", "NOIN", "NOCN", "NOED", "NOFA")


def _check_all_records(path: Path, found: int, fields: Mapping[str, Any]) -> None:
    """The base cell holds every record its DSSI field lists, besides its data descriptive
    record (GDAL reads a cell cut between two records without a word, the features of the
    missing records gone)."""
    counts = [_whole_number(fields.get(f"DSSI_{name}")) for name in _DSSI_COUNTS]
    if any(count is None for count in counts):
        return
    # The DSID record, and the DSPM record when there is one (its scale is mandatory).
    has_dspm = bool(_whole_number(fields.get("DSPM_CSCL")))
    listed = 1 + int(has_dspm) + sum(count or 0 for count in counts)
    if found - 1 < listed:
        raise ChartError(
            f"{path}: cut short: its DSSI field lists {listed} records and the file holds "
            f"{found - 1} (a download stopped early?); download the cell again"
        )


def _check_updates_applied(
    path: Path, updates: Sequence[Path], missing: Sequence[str], update_number: int | None
) -> None:
    """GDAL skips an update it cannot apply (corrupt, or of another edition) without a word;
    the cell's update number after reading tells."""
    before_gap = applied_updates(updates, missing)
    if not before_gap:
        return
    expected = int(before_gap[-1].suffix[1:])
    if update_number is None or update_number < expected:
        applied = f"up to .{update_number:03d}" if update_number else "none"
        raise ChartError(
            f"{path}: of the update files {before_gap[0].name} to {before_gap[-1].name} beside "
            f"it GDAL applied {applied}: .{(update_number or 0) + 1:03d} could not be applied "
            "(corrupt, or of another edition of the cell). Replace the update files with those "
            "of this edition, or move them away to use the base cell alone"
        )


# S-57 depth units (DSPM DUNI); ENCs must give metres.
_DEPTH_UNITS = {1: "metres", 2: "fathoms and feet", 3: "feet", 4: "fathoms and fractions"}


def _check_depth_unit(path: Path, duni: Any) -> None:
    unit = _whole_number(duni)
    if unit is not None and unit != 1:
        raise ChartError(
            f"{path}: the cell gives its depths in {_DEPTH_UNITS.get(unit, f'unit {unit}')} "
            "(DSPM DUNI), and colregs9 reads depths in metres; give an ENC in metres"
        )


@dataclass(frozen=True)
class ChartSource:
    """Charts read from their files in WGS84, not yet projected: read once, project once.
    ``cells`` describes the S-57 cells among them."""

    paths: tuple[Path, ...]
    features: tuple[_Features, ...]
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
    return ChartSource(paths=files, features=tuple(_read_features(p) for p in files), cells=cells)


def _project(geometries: NDArray[np.object_], frame: LocalFrame) -> Any:
    def lonlat_to_east_north(xy: NDArray[np.float64]) -> NDArray[np.float64]:
        north_m, east_m = frame.to_local(xy[:, 1], xy[:, 0])
        return np.column_stack([east_m, north_m])

    projected = shapely.transform(geometries, lonlat_to_east_north)
    invalid = ~shapely.is_valid(projected)
    if invalid.any():
        # A ring with a spike is repaired into its area and a line: keep the area.
        projected[invalid] = _same_dimension(
            shapely.make_valid(projected[invalid]), projected[invalid]
        )
    return projected


def load_chart(
    paths: Sequence[Path], frame: LocalFrame | None = None, accept_gaps: bool = False
) -> Chart:
    """Read and merge charts, project them into ``frame`` (default: centred on their extent)."""
    return project_charts(read_charts(paths, accept_gaps), frame)


def _by_detail(features: Sequence[_Features]) -> list[_Features]:
    """Most detailed first: higher navigational purpose, then larger compilation scale
    (smaller denominator), then the order given."""
    order = sorted(range(len(features)), key=lambda i: (-features[i].purpose, features[i].scale, i))
    return [features[i] for i in order]


def _project_file(features: _Features, frame: LocalFrame) -> Any:
    """A file's features in the frame; a geometry GEOS cannot repair names the file."""
    try:
        return _project(features.geometries, frame)
    except shapely.errors.GEOSException as exc:
        raise ChartError(
            f"{features.path}: a feature's geometry cannot be used ({_first_line(exc)}); fix "
            "its rings (closed, at least three distinct vertices, lon/lat in degrees)"
        ) from None


def _file_coverage(features: _Features, geometries: NDArray[np.object_], frame: LocalFrame) -> Any:
    """A file's coverage in the frame: its M_COVR, else the union of its areas
    (``geometries``: its features in the frame)."""
    if features.coverage is not None:
        return _project(np.array([features.coverage], dtype=object), frame)[0]
    role = np.asarray([_OBJECT_CLASSES[c][1] for c in features.object_class], dtype=object)
    areal = np.isin(role, [ChartLayer.DEPARE, ChartLayer.DRGARE, ChartLayer.LNDARE]) & np.isin(
        shapely.get_type_id(geometries), _POLYGONAL
    )
    return shapely.union_all(geometries[areal])


def _claimed_by_detail(
    features: Sequence[_Features], frame: LocalFrame
) -> tuple[list[NDArray[np.object_]], list[Any]]:
    """Each file's projected geometries, cut to where no more detailed file has coverage (a
    coarse cell decides only outside the detailed one), and each file's coverage left."""
    projected = [_project_file(f, frame) for f in features]
    coverages = [_file_coverage(f, g, frame) for f, g in zip(features, projected, strict=True)]
    if len(features) == 1:
        return projected, coverages
    claimed = shapely.Polygon()
    kept_geometries, kept_coverages = [], []
    for geometries, coverage in zip(projected, coverages, strict=True):
        own = shapely.difference(coverage, claimed)
        clipped = _same_dimension(shapely.intersection(geometries, own), geometries)
        kept_geometries.append(clipped)
        kept_coverages.append(own)
        claimed = shapely.union(claimed, coverage)
    return kept_geometries, kept_coverages


def _same_dimension(clipped: NDArray[np.object_], original: NDArray[np.object_]) -> Any:
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

    Where charts overlap, the most detailed one decides (``_by_detail``): a union of the
    deep areas of two cells would take the deeper of two disagreeing soundings.
    """
    features = _by_detail(source.features)
    if frame is None:
        frame = LocalFrame.centred_on(*source.bounds_wgs84())
    _check_within_reach(source, frame)
    per_file, coverages = _claimed_by_detail(features, frame)
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
    role = np.asarray([_OBJECT_CLASSES[c][1] for c in object_class], dtype=object)
    polygonal = np.isin(shapely.get_type_id(geometries), _POLYGONAL)

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
        layer_counts={name: counts[name] for name in _OBJECT_CLASSES if name in counts},
        hazard_areas=hazard_areas,
        hazard_depth_m=hazard_depth,
    )
