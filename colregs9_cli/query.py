"""Saved queries: a region, a time window, a vessel filter and stage parameters, from TOML.

The format is documented in ``queries/README.md``. In short::

    name = "aalborg_fjord"
    description = "..."
    [region]      # a box, a GeoJSON polygon, or both (then a row must be inside both)
    lat_min = 57.04; lat_max = 57.06; lon_min = 9.90; lon_max = 9.97
    polygon = '{"type": "Polygon", "coordinates": [...]}'   # or polygon_file = "x.geojson"
    [time]        # optional, ISO 8601; start inclusive, end exclusive; no offset means UTC
    start = 2024-09-09T00:00:00Z
    [vessels]     # optional
    mobile_types = ["Class A"]; mmsi_include = [...]; mmsi_exclude = [...]
    ship_types = ["Cargo"]; length_min_m = 20.0; length_max_m = 400.0
    [manoeuvrability] / [colregs] / [replay]   # parameters, validated by their own stages

Unknown keys, at the top level or inside ``[region]``, ``[time]`` and ``[vessels]``, are an
error that names the file and the key.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import UTC, date, datetime, time, timedelta
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray
from shapely.geometry import MultiPolygon, Polygon, shape
from shapely.geometry.base import BaseGeometry

from .config import read_toml
from .errors import InputFileError, QueryError
from .vessels import NINE_DIGIT_MMSI_MAX, NINE_DIGIT_MMSI_MIN, VESSEL_MOBILE_TYPES

if TYPE_CHECKING:
    from .geo import LocalFrame

TOP_LEVEL_KEYS = frozenset(
    {
        "name",
        "description",
        "region",
        "time",
        "vessels",
        "ingest",
        "manoeuvrability",
        "colregs",
        "replay",
    }
)
# The tables of the replay's stages, and the stage tables with ingest's.
REPLAY_STAGE_TABLES = ("manoeuvrability", "colregs", "replay")
STAGE_TABLES = ("ingest", *REPLAY_STAGE_TABLES)
REGION_KEYS = frozenset({"lat_min", "lat_max", "lon_min", "lon_max", "polygon", "polygon_file"})
TIME_KEYS = frozenset({"start", "end"})
VESSEL_KEYS = frozenset(
    {"mobile_types", "mmsi_include", "mmsi_exclude", "ship_types", "length_min_m", "length_max_m"}
)
# Query names become directory names (reports/stats-<name>/).
_NAME_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")


def is_report_name(name: Any) -> bool:
    """True for a name that may name a report directory or file: no path, no control bytes."""
    return isinstance(name, str) and bool(_NAME_PATTERN.fullmatch(name))


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


@dataclass(frozen=True)
class Region:
    """A lat/lon box, optionally narrowed by a polygon (lon/lat, WGS84).

    A point is inside when it is inside the box and, if there is a polygon, inside or on the
    polygon. Boundaries are inclusive. The box does not wrap across the antimeridian.
    """

    lat_min: float
    lat_max: float
    lon_min: float
    lon_max: float
    polygon: Polygon | MultiPolygon | None = None

    def __post_init__(self) -> None:
        for key in ("lat_min", "lat_max", "lon_min", "lon_max"):
            if not _is_number(getattr(self, key)):
                raise QueryError(f"{key} is {getattr(self, key)!r}; give a number in degrees")
        for key, limit in (
            ("lat_min", 90.0),
            ("lat_max", 90.0),
            ("lon_min", 180.0),
            ("lon_max", 180.0),
        ):
            value = getattr(self, key)
            if not -limit <= value <= limit:
                raise QueryError(f"{key} = {value} is outside [-{limit:g}, {limit:g}] degrees")
        if self.lat_min >= self.lat_max:
            raise QueryError(
                f"lat_min = {self.lat_min} is not below lat_max = {self.lat_max}; swap them"
            )
        if self.lon_min >= self.lon_max:
            raise QueryError(
                f"lon_min = {self.lon_min} is not below lon_max = {self.lon_max}; swap them "
                "(boxes across the antimeridian are not supported)"
            )
        if self.polygon is not None:
            if not isinstance(self.polygon, Polygon | MultiPolygon) or self.polygon.is_empty:
                raise QueryError("polygon must be a non-empty GeoJSON Polygon or MultiPolygon")
            if not self.polygon.is_valid:
                raise QueryError(
                    f"polygon is not valid ({shapely.is_valid_reason(self.polygon)}); "
                    "fix its rings (no self-intersections, closed, lon/lat order)"
                )
            shapely.prepare(self.polygon)

    @classmethod
    def from_polygon(cls, polygon: Polygon | MultiPolygon) -> Region:
        """The region of a polygon alone: its bounding box plus the polygon."""
        lon_min, lat_min, lon_max, lat_max = polygon.bounds
        return cls(lat_min, lat_max, lon_min, lon_max, polygon)

    def contains(self, lat_deg: ArrayLike, lon_deg: ArrayLike) -> NDArray[np.bool_]:
        """Which of the points are in the region (NaN positions are not)."""
        lat = np.asarray(lat_deg, dtype=float)
        lon = np.asarray(lon_deg, dtype=float)
        inside = (
            (lat >= self.lat_min)
            & (lat <= self.lat_max)
            & (lon >= self.lon_min)
            & (lon <= self.lon_max)
        )
        if self.polygon is not None and inside.any():
            candidates = np.flatnonzero(inside)
            inside[candidates] = shapely.intersects_xy(
                self.polygon, lon[candidates], lat[candidates]
            )
        return inside


_EPOCH = datetime(1970, 1, 1, tzinfo=UTC)


def ms_at_or_after(moment: datetime) -> int:
    """The first millisecond since the epoch (the schema's unit) at or after ``moment``, in
    integers: a row at ``t`` ms is at or after ``moment`` exactly when ``t`` is at or after it,
    so a bound of ``00:00:01.0001`` keeps no row of ``00:00:01.000``."""
    microseconds = (moment - _EPOCH) // timedelta(microseconds=1)
    return -(-microseconds // 1000)


@dataclass(frozen=True)
class TimeWindow:
    """``start <= timestamp < end`` in UTC; either bound may be absent."""

    start: datetime | None = None
    end: datetime | None = None

    def __post_init__(self) -> None:
        for key in ("start", "end"):
            value = getattr(self, key)
            if value is not None and (not isinstance(value, datetime) or value.tzinfo is None):
                raise QueryError(f"time {key} {value!r} must be a timezone-aware datetime")
        if self.start is not None and self.end is not None and self.start >= self.end:
            raise QueryError(
                f"time start {self.start.isoformat()} is not before end {self.end.isoformat()}"
            )

    @property
    def unbounded(self) -> bool:
        return self.start is None and self.end is None


@dataclass(frozen=True)
class VesselFilter:
    """Which vessels a query keeps; every given criterion must hold (empty: all vessels).

    ``ship_types`` match the ship type text case-insensitively (a row with no ship type does
    not match). The length range is inclusive and applies to each row's ``length_m``; a row
    with no length does not match when a range is set.
    """

    mobile_types: frozenset[str] | None = None
    mmsi_include: frozenset[int] | None = None
    mmsi_exclude: frozenset[int] = frozenset()
    ship_types: frozenset[str] | None = None
    length_min_m: float | None = None
    length_max_m: float | None = None

    def __post_init__(self) -> None:
        if self.mobile_types is not None:
            bad = sorted(set(self.mobile_types) - VESSEL_MOBILE_TYPES)
            if bad:
                raise QueryError(
                    f"mobile_types contains {bad[0]!r}; allowed: "
                    f"{', '.join(sorted(VESSEL_MOBILE_TYPES))}"
                )
        for key in ("mmsi_include", "mmsi_exclude"):
            values = getattr(self, key) or frozenset()
            bad_mmsi = [
                v
                for v in values
                if isinstance(v, bool)
                or not isinstance(v, int)
                or not NINE_DIGIT_MMSI_MIN <= v <= NINE_DIGIT_MMSI_MAX
            ]
            if bad_mmsi:
                raise QueryError(f"{key} contains {bad_mmsi[0]!r}; an MMSI is a 9-digit integer")
        for key in ("length_min_m", "length_max_m"):
            value = getattr(self, key)
            if value is not None and (not _is_number(value) or value < 0):
                raise QueryError(f"{key} = {value!r}; give a length in metres >= 0")
        if (
            self.length_min_m is not None
            and self.length_max_m is not None
            and self.length_min_m > self.length_max_m
        ):
            raise QueryError(
                f"length_min_m = {self.length_min_m} is above length_max_m = {self.length_max_m}"
            )

    @property
    def selects_all(self) -> bool:
        return (
            self.mobile_types is None
            and self.mmsi_include is None
            and not self.mmsi_exclude
            and self.ship_types is None
            and self.length_min_m is None
            and self.length_max_m is None
        )

    def selects(
        self,
        mmsi: ArrayLike,
        mobile_type: ArrayLike,
        ship_type: ArrayLike,
        length_m: ArrayLike,
    ) -> NDArray[np.bool_]:
        """Which rows pass the filter (vectorised; text arrays may hold None)."""
        mmsi_values = np.asarray(mmsi, dtype=np.int64)
        keep = np.ones(mmsi_values.shape, dtype=bool)
        if self.mmsi_include is not None:
            keep &= np.isin(mmsi_values, np.fromiter(self.mmsi_include, dtype=np.int64))
        if self.mmsi_exclude:
            keep &= ~np.isin(mmsi_values, np.fromiter(self.mmsi_exclude, dtype=np.int64))
        if self.mobile_types is not None:
            keep &= np.isin(np.asarray(mobile_type, dtype=object), list(self.mobile_types))
        if self.ship_types is not None:
            wanted = {s.casefold() for s in self.ship_types}
            keep &= np.array(
                [isinstance(s, str) and s.casefold() in wanted for s in np.asarray(ship_type)],
                dtype=bool,
            )
        if self.length_min_m is not None or self.length_max_m is not None:
            length = np.asarray(length_m, dtype=float)
            low = -np.inf if self.length_min_m is None else self.length_min_m
            high = np.inf if self.length_max_m is None else self.length_max_m
            with np.errstate(invalid="ignore"):
                keep &= (length >= low) & (length <= high)
        return keep


@dataclass(frozen=True)
class Query:
    """A saved query. ``tables`` holds the raw stage tables, validated by their owners."""

    name: str
    description: str = ""
    region: Region | None = None
    time: TimeWindow = field(default_factory=TimeWindow)
    vessels: VesselFilter = field(default_factory=VesselFilter)
    tables: Mapping[str, Mapping[str, Any]] = field(default_factory=lambda: MappingProxyType({}))
    source: Path | None = None

    def __reduce__(self) -> tuple[Any, ...]:
        # The tables are read-only views, which pickle cannot copy; a query is sent to Dask
        # workers: its tables travel as dicts and are made read-only again.
        state = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        state["tables"] = {key: dict(table) for key, table in self.tables.items()}
        return (_unpickled_query, (state,))

    @property
    def has_replay_tables(self) -> bool:
        """Whether the query holds a table of the replay's stages, which a command that does
        not use it still checks (``jobs.replay_params.stage_tables``), so that a query one
        command accepts, the others accept."""
        return any(name in self.tables for name in REPLAY_STAGE_TABLES)

    def frame(self) -> LocalFrame | None:
        """The run's local metric frame, centred on the region's box; None without a region."""
        # pyproj is imported here, by the commands that project, not by every read.
        from .geo import LocalFrame

        if self.region is None:
            return None
        r = self.region
        return LocalFrame.centred_on(r.lat_min, r.lat_max, r.lon_min, r.lon_max)


def _unpickled_query(state: dict[str, Any]) -> Query:
    tables = state.pop("tables")
    return Query(
        **state,
        tables=MappingProxyType({key: MappingProxyType(table) for key, table in tables.items()}),
    )


def everything_query() -> Query:
    """The query used without ``--query``: every vessel, everywhere, at any time."""
    return Query(name="all", description="every vessel position in the input")


def load_query(path: Path) -> Query:
    """Read and validate a query TOML file (format: ``queries/README.md``)."""
    path = Path(path)
    document = read_toml(path)
    unknown = sorted(set(document) - TOP_LEVEL_KEYS)
    if unknown:
        raise QueryError(
            f"{path}: unknown key {unknown[0]!r}; allowed top-level keys are "
            f"{', '.join(sorted(TOP_LEVEL_KEYS))}"
        )
    name = document.get("name", path.stem)
    if not is_report_name(name):
        raise QueryError(
            f"{path}: name = {name!r}; use letters, digits, '_', '-' and '.' "
            "(it names the report directory)"
        )
    description = document.get("description", "")
    if not isinstance(description, str):
        raise QueryError(f"{path}: description = {description!r}; give a string")
    region = _region(path, _table(path, document, "region")) if "region" in document else None
    time_window = _time_window(path, _table(path, document, "time"))
    vessels = _vessel_filter(path, _table(path, document, "vessels"))
    tables = MappingProxyType(
        {
            key: MappingProxyType(_table(path, document, key))
            for key in STAGE_TABLES
            if key in document
        }
    )
    return Query(
        name=name,
        description=description,
        region=region,
        time=time_window,
        vessels=vessels,
        tables=tables,
        source=path,
    )


def _table(path: Path, document: dict[str, Any], key: str) -> dict[str, Any]:
    table = document.get(key, {})
    if not isinstance(table, dict):
        raise QueryError(f"{path}: {key} must be a table ([{key}]), got {table!r}")
    return table


def _check_keys(path: Path, section: str, table: dict[str, Any], allowed: frozenset[str]) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise QueryError(
            f"{path}: [{section}] unknown key {unknown[0]!r}; allowed keys are "
            f"{', '.join(sorted(allowed))}"
        )


def _region(path: Path, table: dict[str, Any]) -> Region:
    _check_keys(path, "region", table, REGION_KEYS)
    box_keys = ("lat_min", "lat_max", "lon_min", "lon_max")
    given = [k for k in box_keys if k in table]
    if "polygon" in table and "polygon_file" in table:
        raise QueryError(f"{path}: [region] give either polygon or polygon_file, not both")
    polygon = None
    if "polygon" in table:
        polygon = _polygon_from_text(table["polygon"], f"{path}: [region] polygon")
    elif "polygon_file" in table:
        polygon = _polygon_from_file(path, table["polygon_file"])
    if given and len(given) < len(box_keys):
        missing = next(k for k in box_keys if k not in table)
        raise QueryError(
            f"{path}: [region] has {', '.join(given)} but not {missing}; give all four"
        )
    if not given and polygon is None:
        raise QueryError(
            f"{path}: [region] is empty; give lat_min, lat_max, lon_min, lon_max and/or a polygon"
        )
    try:
        if not given:
            assert polygon is not None
            return Region.from_polygon(polygon)
        return Region(
            table["lat_min"], table["lat_max"], table["lon_min"], table["lon_max"], polygon=polygon
        )
    except QueryError as exc:
        raise QueryError(f"{path}: [region] {exc}") from None


def _polygon_from_text(text: Any, where: str) -> Polygon | MultiPolygon:
    if not isinstance(text, str):
        raise QueryError(f"{where}: expected a GeoJSON string, got {text!r}")
    try:
        geojson = json.loads(text)
    except json.JSONDecodeError as exc:
        raise QueryError(f"{where}: not valid JSON ({exc})") from None
    except ValueError:  # an integer of more digits than Python converts
        raise QueryError(
            f"{where}: a number of more than 4300 digits; give coordinates in degrees"
        ) from None
    except RecursionError:
        raise QueryError(f"{where}: the GeoJSON is nested too deeply to be a polygon") from None
    return _polygon_from_geojson(geojson, where)


def _polygon_from_file(query_path: Path, relative: Any) -> Polygon | MultiPolygon:
    if not isinstance(relative, str) or "\0" in relative:
        raise QueryError(f"{query_path}: [region] polygon_file = {relative!r}; give a path")
    # realpath leaves a symbolic link that loops as it is (Path.resolve raises RuntimeError),
    # so that stat reports it as the OSError below.
    polygon_path = Path(os.path.realpath(query_path.parent / relative))
    try:
        polygon_path.stat()
    except FileNotFoundError:
        pass
    except OSError as exc:
        raise InputFileError(
            f"{query_path}: [region] polygon_file {relative!r}: {exc.strerror}; give a path "
            "to a GeoJSON file"
        ) from None
    if polygon_path.is_dir():
        raise InputFileError(
            f"{query_path}: [region] polygon_file {relative!r} is {polygon_path}, a directory, "
            "not a file; give a GeoJSON file"
        )
    if not polygon_path.exists():
        raise InputFileError(
            f"{query_path}: [region] polygon_file {relative!r}: no such file {polygon_path}"
        )
    if not polygon_path.is_file():  # a pipe's read would wait for a writer
        raise InputFileError(
            f"{query_path}: [region] polygon_file {relative!r} is {polygon_path}, a pipe or a "
            "device, not a file; give a GeoJSON file"
        )
    try:
        text = polygon_path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise QueryError(f"{polygon_path}: not UTF-8 text; save the GeoJSON as UTF-8") from None
    except OSError as exc:
        raise InputFileError(f"{polygon_path}: cannot read it ({exc.strerror})") from None
    return _polygon_from_text(text, f"{polygon_path}")


def _first_bad_coordinate(coordinates: Any) -> Any:
    """The first value in nested coordinate lists that is not a finite number, else None."""
    if isinstance(coordinates, list | tuple):
        for item in coordinates:
            bad = _first_bad_coordinate(item)
            if bad is not None:
                return bad
        return None
    if isinstance(coordinates, bool) or not isinstance(coordinates, int | float):
        return coordinates
    if isinstance(coordinates, int) and abs(coordinates) > 360:  # no degree, and too big a float
        return coordinates
    return None if math.isfinite(coordinates) else coordinates


def _polygon_from_geojson(geojson: Any, where: str) -> Polygon | MultiPolygon:
    """A Polygon/MultiPolygon geometry, or a Feature/FeatureCollection of them (their union)."""
    if not isinstance(geojson, dict) or "type" not in geojson:
        raise QueryError(f"{where}: expected a GeoJSON object with a 'type'")
    kind = geojson["type"]
    if kind == "FeatureCollection":
        features = geojson.get("features")
        if not isinstance(features, list):
            raise QueryError(
                f"{where}: the FeatureCollection's features = {features!r}; give a list"
            )
        parts = [_polygon_from_geojson(feature, where) for feature in features]
        if not parts:
            raise QueryError(f"{where}: the FeatureCollection has no features")
        merged: BaseGeometry = shapely.union_all(parts)
        if not isinstance(merged, Polygon | MultiPolygon):
            raise QueryError(f"{where}: the features do not form a polygon")
        return merged
    if kind == "Feature":
        return _polygon_from_geojson(geojson.get("geometry"), where)
    if kind not in ("Polygon", "MultiPolygon"):
        raise QueryError(f"{where}: geometry type {kind!r}; give a Polygon or MultiPolygon")
    bad = _first_bad_coordinate(geojson.get("coordinates"))
    if bad is not None:
        raise QueryError(
            f"{where}: the coordinate {bad!r} is not a finite number; give longitude and "
            "latitude in degrees"
        )
    try:
        geometry = shape(geojson)
    except (ValueError, TypeError, AttributeError, IndexError, KeyError) as exc:
        raise QueryError(f"{where}: cannot build the {kind} ({exc})") from None
    assert isinstance(geometry, Polygon | MultiPolygon)
    if geometry.is_empty:
        raise QueryError(
            f"{where}: the {kind} has no coordinates; give at least one closed ring of "
            "[longitude, latitude] pairs"
        )
    return geometry


def _utc(value: Any, where: str) -> datetime:
    """A TOML datetime or ISO 8601 string as aware UTC; no offset means UTC, a date midnight."""
    if isinstance(value, str):
        try:
            value = datetime.fromisoformat(value.replace("Z", "+00:00"))
        except ValueError:
            raise QueryError(
                f"{where} = {value!r} is not an ISO 8601 time; write e.g. 2024-09-09T12:00:00Z"
            ) from None
    elif isinstance(value, date) and not isinstance(value, datetime):
        value = datetime.combine(value, time(0, 0))
    if not isinstance(value, datetime):
        raise QueryError(f"{where} = {value!r} is not a time; write e.g. 2024-09-09T12:00:00Z")
    try:
        return value.replace(tzinfo=UTC) if value.tzinfo is None else value.astimezone(UTC)
    except OverflowError:
        raise QueryError(
            f"{where} = {value.isoformat()} is beyond the range of times; give a time between "
            "1980 and 2099"
        ) from None


def _time_window(path: Path, table: dict[str, Any]) -> TimeWindow:
    _check_keys(path, "time", table, TIME_KEYS)
    bounds = {key: _utc(table[key], f"{path}: [time] {key}") for key in TIME_KEYS if key in table}
    try:
        return TimeWindow(**bounds)
    except QueryError as exc:
        raise QueryError(f"{path}: [time] {exc}") from None


def _vessel_filter(path: Path, table: dict[str, Any]) -> VesselFilter:
    _check_keys(path, "vessels", table, VESSEL_KEYS)
    where = f"{path}: [vessels]"
    values: dict[str, Any] = {}
    for key in ("mobile_types", "ship_types"):
        if key in table:
            items = table[key]
            if not isinstance(items, list) or not all(isinstance(s, str) for s in items):
                raise QueryError(f"{where} {key} = {items!r}; give a list of strings")
            values[key] = frozenset(items)
    for key in ("mmsi_include", "mmsi_exclude"):
        if key in table:
            items = table[key]
            if not isinstance(items, list) or any(isinstance(v, list | dict) for v in items):
                raise QueryError(f"{where} {key} = {items!r}; give a flat list of MMSIs")
            values[key] = frozenset(items)
    for key in ("length_min_m", "length_max_m"):
        if key in table:
            values[key] = table[key]
    try:
        return VesselFilter(**values)
    except QueryError as exc:
        raise QueryError(f"{where} {exc}") from None
