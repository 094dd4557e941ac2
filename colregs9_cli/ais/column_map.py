"""Column maps: what the columns of a CSV mean, for layouts other than DMA's.

A map names, for each source column, the canonical column it fills (docs/design.md §4), and says how
its values are written: the time format, the units, the values that mean "not available".
The MarineCadastre layouts and exactEarth/Spire's are built-in maps (``BUILTIN_MAPS``, made
from their entries in layouts.py); any other CSV is read with a map from a TOML file
(``--columns MAP.toml``, ``load_column_map``)::

    name = "aishub"                 # the layout's name in run.json; default: the file's stem
    delimiter = ","                 # one character; default ","
    [columns]                       # source column (any case) -> canonical column
    MMSI = "mmsi"
    TIME = "timestamp"
    LATITUDE = "lat_deg"
    A = "to_bow"                    # length = to_bow + to_stern, breadth = to_port + to_starboard
    [time]
    format = "%Y-%m-%d %H:%M:%S"    # strftime (UTC), or "unix" (seconds), or "unix_ms"
    [units]
    sog_kn = "m/s"                  # see UNITS
    [sentinels]
    draught_m = [0, 25.5]           # values (as written, before units) meaning not available

Targets besides the canonical columns: ``to_bow``, ``to_stern``, ``to_port``,
``to_starboard`` (the AIS A, B, C, D, which fill ``to_bow_m`` ... ``to_starboard_m``),
``message_type`` (the AIS message number, which tells the mobile type: 1-3, 5, 27 Class A;
18, 19, 24 Class B; 4, 9, 11, 21 not a vessel; other types are ``unsupported_message_type``)
and ``millisecond`` (added to the time). Values:
``ship_type`` and ``nav_status`` may be ITU codes or text; ``mobile_type`` ``A``/``B`` or
``Class A``/``Class B`` (other text: not a vessel). A map with neither ``mobile_type`` nor
``message_type`` reads every row as a vessel of unknown class (``mobile_type`` null): such
files (MarineCadastre 2015-2017) hold vessel reports only.

Required: ``mmsi``, ``lat_deg``, ``lon_deg`` and ``timestamp``. A light module (no
``pyarrow.compute``): ``colregs9 stats`` resolves the layout before it imports those.
"""

from __future__ import annotations

import functools
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..config import TOO_DEEP
from ..errors import ParameterError
from .layouts import LAYOUTS, MAP_PREFIX, Layout
from .schema import ANTENNA_OFFSETS, CANONICAL_COLUMNS

TIME_UNIX = "unix"
TIME_UNIX_MS = "unix_ms"

# A map names AIS's A, B, C, D ``to_bow`` ... (``PART_TARGETS``), as written before the
# canonical schema had them; they fill ``to_bow_m`` ... (``schema.ANTENNA_OFFSETS``).
CANONICAL_TARGETS = tuple(c for c in CANONICAL_COLUMNS if c not in ANTENNA_OFFSETS)
PART_TARGETS = ("to_bow", "to_stern", "to_port", "to_starboard")
EXTRA_TARGETS = (*PART_TARGETS, "message_type", "millisecond")
TARGETS = (*CANONICAL_TARGETS, *EXTRA_TARGETS)
REQUIRED_TARGETS = ("mmsi", "lat_deg", "lon_deg", "timestamp")
TEXT_TARGETS = frozenset({"timestamp", "ship_type", "mobile_type", "name", "callsign", "imo"})
# Targets read as numbers (the chunk reader parses them as such where it can).
NUMERIC_TARGETS = tuple(t for t in TARGETS if t not in TEXT_TARGETS and t != "nav_status")
DIMENSION_TARGETS = ("length_m", "breadth_m", "draught_m", *PART_TARGETS)

_KNOT_M_S = 1852.0 / 3600.0
# Unit names -> factor to the canonical unit, per target.
_METRES = {"m": 1.0, "dm": 0.1, "cm": 0.01, "ft": 0.3048}
UNITS: dict[str, dict[str, float]] = {
    "sog_kn": {"kn": 1.0, "0.1 kn": 0.1, "m/s": 1.0 / _KNOT_M_S, "km/h": 1.0 / 1.852},
    "lat_deg": {"deg": 1.0, "1/10000 min": 1.0 / 600000.0},
    "lon_deg": {"deg": 1.0, "1/10000 min": 1.0 / 600000.0},
    "cog_deg": {"deg": 1.0, "0.1 deg": 0.1},
    "heading_deg": {"deg": 1.0},
    "rot_deg_per_min": {"deg/min": 1.0, "ais": 1.0},
    "length_m": _METRES,
    "breadth_m": _METRES,
    "draught_m": _METRES,
    **{part: _METRES for part in PART_TARGETS},
}


@dataclass(frozen=True)
class ColumnMap:
    """A CSV layout described column by column (module docstring).

    ``columns``: canonical target -> source column (lower case, as ``layouts.normalise_column``
    gives). ``units``: target -> factor to the canonical unit (1 where not given).
    ``sentinels``: target -> values, as written, that mean "not available".
    """

    name: str
    columns: Mapping[str, str]
    time_format: str
    delimiter: str = ","
    units: Mapping[str, float] = field(default_factory=dict)
    rot_ais: bool = False
    sentinels: Mapping[str, tuple[float | str, ...]] = field(default_factory=dict)
    source: Path | None = None
    # target -> other names its column goes by (built-in maps): used where the first is absent
    aliases: Mapping[str, tuple[str, ...]] = field(default_factory=dict)

    def for_header(self, names: tuple[str, ...]) -> ColumnMap:
        """The map with each column the header lacks replaced by an alias the header has."""
        present = set(names)
        columns = dict(self.columns)
        for target, alternatives in self.aliases.items():
            if target in columns and columns[target] not in present:
                found = [a for a in alternatives if a in present]
                if found:
                    columns[target] = found[0]
        return replace(self, columns=columns, aliases={})

    def has(self, target: str) -> bool:
        return target in self.columns

    def column(self, target: str) -> str:
        return self.columns[target]

    @property
    def read_columns(self) -> tuple[str, ...]:
        """The source columns the map reads, in target order."""
        return tuple(dict.fromkeys(self.columns[t] for t in TARGETS if t in self.columns))

    @property
    def row_columns(self) -> tuple[str, ...]:
        """The source columns every row needs: identity, position, class, dimensions."""
        wanted = ("mmsi", "lat_deg", "lon_deg", "mobile_type", "message_type", *DIMENSION_TARGETS)
        return tuple(dict.fromkeys(self.columns[t] for t in wanted if t in self.columns))

    @property
    def numeric_columns(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(self.columns[t] for t in NUMERIC_TARGETS if t in self.columns))

    @property
    def whole_columns(self) -> tuple[str, ...]:
        return (self.columns["mmsi"],)

    @property
    def dimension_columns(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(self.columns[t] for t in DIMENSION_TARGETS if t in self.columns))


# -- built-in maps ------------------------------------------------------------------------------


def _builtin(layout: Layout) -> ColumnMap:
    """The ``ColumnMap`` of a layout read through a built-in map (layouts.py)."""
    assert layout.column_map is not None, "a layout with a built-in map"
    spec = layout.column_map
    columns = {target: source for source, target in spec.targets.items()}
    return ColumnMap(layout.name, columns, spec.time_format, aliases=spec.aliases)


BUILTIN_MAPS: dict[str, ColumnMap] = {
    layout.name: _builtin(layout) for layout in LAYOUTS.values() if layout.column_map is not None
}


# -- maps from TOML -----------------------------------------------------------------------------


def column_map(layout: Layout) -> ColumnMap | None:
    """The map of a layout: built-in, or a ``--columns`` map (read from its TOML); None for
    the layouts read otherwise (DMA, NMEA, Parquet)."""
    if layout.map_file is not None:
        return load_column_map(layout.map_file)
    return BUILTIN_MAPS.get(layout.name)


def map_layout(path: Path) -> str:
    """The layout name that stands for the map file ``path`` (``--columns``)."""
    load_column_map(Path(path))  # checked now: an error in the map before any reading
    return MAP_PREFIX + str(Path(path))


@functools.lru_cache(maxsize=16)
def load_column_map(path: Path) -> ColumnMap:
    """Read and check a map file; ``ParameterError`` naming the file and the key."""
    if path.exists() and not (path.is_file() or path.is_dir()):  # a pipe's read would block
        raise ParameterError(
            f"--columns {path}: a pipe or a device, not a file; give the map's TOML file"
        )
    try:
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise ParameterError(f"--columns {path}: no such file; check the path") from None
    except IsADirectoryError:
        raise ParameterError(f"--columns {path}: a directory; give the map's TOML file") from None
    except OSError as exc:
        raise ParameterError(f"--columns {path}: cannot read the map ({exc.strerror})") from None
    except UnicodeDecodeError as exc:
        raise ParameterError(
            f"{path}: byte {exc.start} is not UTF-8; save the map as UTF-8"
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc}); fix the map") from None
    except RecursionError:
        raise ParameterError(f"{path}: {TOO_DEEP}; fix the map") from None
    except ValueError:  # an integer of more digits than Python converts
        raise ParameterError(
            f"{path}: a number of more than 4300 digits; give numbers of a sensible size"
        ) from None
    return _parse_map(path, data)


def _fail(path: Path, key: str, why: str) -> ParameterError:
    return ParameterError(f"{path}: {key}: {why}")


def _parse_map(path: Path, data: dict[str, Any]) -> ColumnMap:
    known = {"name", "delimiter", "columns", "time", "units", "sentinels"}
    for key in data:
        if key not in known:
            raise _fail(path, key, f"unknown key; a map has {', '.join(sorted(known))}")
    name = data.get("name", path.stem)
    if not isinstance(name, str) or not name.strip() or len(name) > 80 or "\n" in name:
        raise _fail(path, "name", f"{name!r}: give a short one-line text")
    delimiter = data.get("delimiter", ",")
    if not isinstance(delimiter, str) or len(delimiter) != 1 or delimiter in '"\r\n':
        raise _fail(path, "delimiter", f'{delimiter!r}: give one character, such as "," or ";"')
    columns = _table(path, data, "columns", required=True)
    targets: dict[str, str] = {}
    for source, target in columns.items():
        key = f"[columns] {source!r}"
        if not isinstance(target, str) or target not in TARGETS:
            raise _fail(
                path,
                key,
                f"{target!r} is not a column colregs9 reads; use one of {', '.join(TARGETS)}",
            )
        if target in targets:
            raise _fail(path, key, f"{target!r} is already the column {targets[target]!r}")
        normalised = source.strip().lstrip("#").strip().lower()
        if not normalised:
            raise _fail(path, key, "an empty column name")
        targets[target] = normalised
    missing = [t for t in REQUIRED_TARGETS if t not in targets]
    if missing:
        raise _fail(
            path,
            "[columns]",
            f"no column is {missing[0]!r}; colregs9 needs {', '.join(REQUIRED_TARGETS)}",
        )
    time_format = _time_format(path, _table(path, data, "time", required=True))
    units, rot_ais = _units(path, _table(path, data, "units"))
    sentinels: dict[str, tuple[float | str, ...]] = {}
    for target, values in _table(path, data, "sentinels").items():
        key = f"[sentinels] {target}"
        if target not in TARGETS:
            raise _fail(path, key, f"not a column colregs9 reads; use one of {', '.join(TARGETS)}")
        if not isinstance(values, list) or not all(
            isinstance(v, int | float | str) and not isinstance(v, bool) for v in values
        ):
            raise _fail(path, key, f"{values!r}: give a list of numbers or texts")
        sentinels[target] = tuple(values)
    return ColumnMap(
        name=name.strip(),
        columns=targets,
        time_format=time_format,
        delimiter=delimiter,
        units=units,
        rot_ais=rot_ais,
        sentinels=sentinels,
        source=path,
    )


def _table(path: Path, data: dict[str, Any], key: str, required: bool = False) -> dict[str, Any]:
    if key not in data:
        if required:
            raise _fail(path, f"[{key}]", "missing; see the README's section 'Column maps'")
        return {}
    value = data[key]
    if not isinstance(value, dict):
        raise _fail(path, key, f"{value!r}: give a table ([{key}])")
    return value


def _time_format(path: Path, table: dict[str, Any]) -> str:
    for key in table:
        if key != "format":
            raise _fail(path, f"[time] {key}", "unknown key; [time] has format")
    value = table.get("format")
    if not isinstance(value, str) or not value.strip():
        raise _fail(
            path,
            "[time] format",
            f'{value!r}: give a strftime format ("%Y-%m-%d %H:%M:%S"), "unix" or "unix_ms"',
        )
    if value not in (TIME_UNIX, TIME_UNIX_MS) and "%" not in value:
        raise _fail(
            path,
            "[time] format",
            f'{value!r} has no % field; give a strftime format, "unix" or "unix_ms"',
        )
    return value


def _units(path: Path, table: dict[str, Any]) -> tuple[dict[str, float], bool]:
    units: dict[str, float] = {}
    rot_ais = False
    for target, unit in table.items():
        key = f"[units] {target}"
        if target not in UNITS:
            raise _fail(path, key, f"no units to give for it; units apply to {', '.join(UNITS)}")
        allowed = UNITS[target]
        if not isinstance(unit, str) or unit not in allowed:
            raise _fail(path, key, f"{unit!r}: use one of {', '.join(map(repr, allowed))}")
        units[target] = allowed[unit]
        rot_ais = rot_ais or (target == "rot_deg_per_min" and unit == "ais")
    return units, rot_ais
