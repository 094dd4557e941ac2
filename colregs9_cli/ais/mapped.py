"""Reading a CSV block through a column map (column_map.py) into the canonical schema.

The MarineCadastre layouts, exactEarth/Spire's and any ``--columns`` map are read here, block
by block as DMA's (see load.py): ``mapped_fields`` converts the columns every row needs,
``mapped_canonical`` the rows kept. Conversions, after a map's sentinels and units:

- time: strftime text (UTC; in the ISO format a space may stand for the ``T``), unix seconds
  or unix milliseconds, plus a ``millisecond`` column where mapped (empty: 0; outside 0-999:
  the time does not parse);
- ``ship_type``: an ITU code becomes the DMA category text (30 Fishing, 52 Tug, 60-69
  Passenger, 70-79 Cargo, 80-89 Tanker, ...; 0 is null, codes outside 1-99 "Other"); text is
  kept; ``nav_status``: a code 0-15 is kept, text mapped as DMA's (``clean.nav_status_code``);
- mobile type: ``A``/``B``/``Class A``/``Class B`` become ``Class A``/``Class B``; an AIS message
  number gives it (1-3, 5, 27 Class A; 18, 19, 24 Class B; 4, 11 base station, 9 SAR
  aircraft, 21 AtoN: not vessels); with neither column every row is a vessel of unknown class;
- A, B, C, D (``to_bow`` ... ``to_starboard``, exactEarth's ``dimension_to_*``): the canonical
  ``to_bow_m`` ... ``to_starboard_m`` as ``clean.offset_parts`` cleans them (null for a map
  without them, MarineCadastre's); length and breadth: A+B and C+D where they give them (B
  and D where A = C = 0), else the length and breadth columns; ``IMO9307839`` is read as
  9307839; the AIS sentinels become null as in clean.py.
"""

from __future__ import annotations

import math
from typing import TypeAlias

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from .clean import (
    BoolArray,
    DimensionColumns,
    Dimensions,
    Fields,
    FloatArray,
    OffsetParts,
    clean_angle,
    clean_rot,
    clean_ship_type,
    clean_sog,
    clean_text,
    float_column,
    is_vessel,
    mmsi_column,
    nan_to_null,
    nav_status_code,
    no_offsets,
    null_outside,
    number_problems,
    offset_parts,
    on_a_real_day,
    on_the_written_day,
    plausible,
    positive_or_nan,
    whole_positive,
)
from .column_map import PART_TARGETS, TIME_UNIX, TIME_UNIX_MS, ColumnMap
from .layouts import ISO_TIME_FORMAT
from .marinecadastre import ship_type_text
from .schema import CANONICAL_SCHEMA

Batch: TypeAlias = pa.RecordBatch | pa.Table

CLASS_A_MESSAGES = frozenset({1, 2, 3, 5, 27})
CLASS_B_MESSAGES = frozenset({18, 19, 24})
NOT_A_VESSEL_MESSAGES = {4: "Base Station", 11: "Base Station", 9: "SAR Airborne", 21: "AtoN"}
_ISO_TIME = (
    r"^(?P<date>\d{4}-\d{2}-\d{2})[T ](?P<time>\d{2}:\d{2}:\d{2})"
    r"(?:\.(?P<fraction>\d+))?(?P<zone>Z|[+-]\d{2}(?::?\d{2})?)?$"
)
_ISO_DAY_AND_SECOND = r"^\d{4}-\d{2}-(?P<day>\d{2})T\d{2}:\d{2}:(?P<second>\d{2})$"
_MAX_ROT_RAW = 126  # ±127 and -128: turning fast without a rate, or no rate at all


def _text(map_: ColumnMap, batch: Batch, target: str) -> pa.Array:
    """A mapped column as cleaned text (null where absent or "not available")."""
    if not map_.has(target):
        return pa.nulls(batch.num_rows, pa.string())
    text = clean_text(batch.column(map_.column(target)))
    words = [str(v) for v in map_.sentinels.get(target, ())]
    if words:
        text = pc.if_else(
            pc.is_in(text, value_set=pa.array(words)), pa.scalar(None, pa.string()), text
        )
    return text


def _raw_number(map_: ColumnMap, batch: Batch, target: str) -> tuple[FloatArray, BoolArray]:
    """A mapped column as numbers as written (NaN where absent, empty or a sentinel), and
    where it held text that is not a number."""
    n = batch.num_rows
    if not map_.has(target):
        return np.full(n, np.nan), np.zeros(n, dtype=bool)
    values = batch.column(map_.column(target))
    sentinels = map_.sentinels.get(target, ())
    words = [v for v in sentinels if isinstance(v, str)]
    if words and not (pa.types.is_integer(values.type) or pa.types.is_floating(values.type)):
        trimmed = pc.utf8_trim_whitespace(values)
        values = pc.if_else(
            pc.is_in(trimmed, value_set=pa.array(words)), pa.scalar(None, pa.string()), values
        )
    numbers, bad = float_column(values)
    limits = [float(v) for v in sentinels if not isinstance(v, str)]
    if limits:
        numbers = np.where(np.isin(numbers, limits), np.nan, numbers)
    return numbers, bad


def _number(map_: ColumnMap, batch: Batch, target: str) -> tuple[FloatArray, BoolArray]:
    """A mapped column in the canonical unit."""
    numbers, bad = _raw_number(map_, batch, target)
    factor = map_.units.get(target, 1.0)
    return (numbers * factor if factor != 1.0 else numbers), bad


def _offsets(map_: ColumnMap, batch: Batch) -> OffsetParts | None:
    """A, B, C, D in metres, cleaned (``clean.offset_parts``); None for a map without any."""
    if not any(map_.has(target) for target in PART_TARGETS):
        return None
    a, b, c, d = (_number(map_, batch, target)[0] for target in PART_TARGETS)
    return offset_parts(a, b, c, d)


def _measure(map_: ColumnMap, batch: Batch, offsets: OffsetParts | None) -> Dimensions:
    """The dimensions as the map makes them, before the plausibility limits: length and
    breadth from A, B, C, D where they give them, else the length and breadth columns."""
    length, _ = _number(map_, batch, "length_m")
    breadth, _ = _number(map_, batch, "breadth_m")
    draught, _ = _number(map_, batch, "draught_m")
    if offsets is None:
        return positive_or_nan(length), positive_or_nan(breadth), positive_or_nan(draught)
    return offsets.dimensions(length, breadth, draught)


def _dimensions(map_: ColumnMap, batch: Batch) -> Dimensions:
    return _measure(map_, batch, _offsets(map_, batch))


def _message_types(map_: ColumnMap, batch: Batch) -> FloatArray:
    return _raw_number(map_, batch, "message_type")[0]


def mobile_types(map_: ColumnMap, batch: Batch) -> pa.Array:
    """The canonical mobile type of each row (null: unknown)."""
    n = batch.num_rows
    if map_.has("message_type"):
        codes = _message_types(map_, batch)
        texts = np.full(n, None, dtype=object)
        texts[np.isin(codes, list(CLASS_A_MESSAGES))] = "Class A"
        texts[np.isin(codes, list(CLASS_B_MESSAGES))] = "Class B"
        for code, text in NOT_A_VESSEL_MESSAGES.items():
            texts[codes == code] = text
        return pa.array(texts, pa.string())
    if map_.has("mobile_type"):
        text = _text(map_, batch, "mobile_type")
        upper = pc.utf8_upper(text)
        class_a = pc.is_in(upper, value_set=pa.array(["A", "CLASS A"]))
        class_b = pc.is_in(upper, value_set=pa.array(["B", "CLASS B"]))
        return pc.if_else(class_a, "Class A", pc.if_else(class_b, "Class B", text))
    return pa.nulls(n, pa.string())


def _vessels(map_: ColumnMap, batch: Batch) -> BoolArray:
    if not (map_.has("message_type") or map_.has("mobile_type")):
        return np.ones(batch.num_rows, dtype=bool)
    return is_vessel(mobile_types(map_, batch))


def unsupported_messages(map_: ColumnMap, batch: Batch) -> BoolArray | None:
    """Rows of AIS message types neither positions, statics nor from non-vessels (a map with
    a ``message_type`` column); None without one."""
    if not map_.has("message_type"):
        return None
    codes = _message_types(map_, batch)
    known = CLASS_A_MESSAGES | CLASS_B_MESSAGES | set(NOT_A_VESSEL_MESSAGES)
    return np.asarray(~np.isin(codes, list(known)) & np.isfinite(codes), dtype=bool)


def mapped_fields(map_: ColumnMap, batch: Batch) -> Fields:
    mmsi, bad_mmsi = mmsi_column(batch.column(map_.column("mmsi")))
    lat, bad_lat = _number(map_, batch, "lat_deg")
    lon, bad_lon = _number(map_, batch, "lon_deg")
    unparseable, problem = number_problems(bad_mmsi, bad_lat, bad_lon)
    dimension_columns = list(map_.dimension_columns)
    return Fields(
        mmsi=mmsi,
        lat_deg=null_outside(lat, -90.0, 90.0),
        lon_deg=null_outside(lon, -180.0, 180.0),
        vessel=_vessels(map_, batch),
        dimensions=DimensionColumns(
            batch.select(dimension_columns)
            if dimension_columns
            else pa.table({"_none": pa.nulls(batch.num_rows, pa.float64())}),
            lambda table: _dimensions(map_, table),
        ),
        unparseable=unparseable,
        problem=problem,
    )


def _ship_types(map_: ColumnMap, batch: Batch) -> pa.Array:
    text = _text(map_, batch, "ship_type")
    codes, not_number = float_column(text)
    coded = ship_type_text(codes)
    return pc.if_else(pa.array(not_number), clean_ship_type(text), coded)


def _nav_status(map_: ColumnMap, batch: Batch) -> pa.Array:
    n = batch.num_rows
    if not map_.has("nav_status"):
        return pa.nulls(n, pa.int8())
    values = batch.column(map_.column("nav_status"))
    codes, not_number = float_column(values)
    with np.errstate(invalid="ignore"):
        ok = (codes >= 0) & (codes <= 15) & (np.floor(codes) == codes)
    result = np.where(ok, codes, np.nan)
    if not_number.any():
        rows = np.flatnonzero(not_number)
        texts = clean_text(values).take(pa.array(rows)).to_pylist()
        for row, text in zip(rows.tolist(), texts, strict=True):
            code = nav_status_code(text)
            result[row] = np.nan if code is None else code
    known = ~np.isnan(result)
    return pa.array(np.where(known, result, 0).astype(np.int8), pa.int8(), mask=~known)


def _rot(map_: ColumnMap, batch: Batch) -> FloatArray:
    values, _ = _number(map_, batch, "rot_deg_per_min")
    if map_.rot_ais:
        with np.errstate(invalid="ignore"):
            known = np.abs(values) <= _MAX_ROT_RAW
        return np.where(known, np.sign(values) * (values / 4.733) ** 2, np.nan) + 0.0
    return clean_rot(values)


def _timestamps(map_: ColumnMap, batch: Batch) -> tuple[pa.Array, BoolArray]:
    """Milliseconds since the epoch as timestamps, and the rows whose time does not parse."""
    column = batch.column(map_.column("timestamp"))
    if map_.time_format in (TIME_UNIX, TIME_UNIX_MS):
        values, _ = float_column(column)
        scale = 1.0 if map_.time_format == TIME_UNIX_MS else 1000.0
        with np.errstate(invalid="ignore", over="ignore"):
            milliseconds = np.round(values * scale)
            good = np.isfinite(milliseconds) & (np.abs(milliseconds) < 2**62)
    elif map_.time_format == ISO_TIME_FORMAT:
        milliseconds, good = iso_milliseconds(column.cast(pa.string()))
    else:
        text = pc.utf8_trim_whitespace(column.cast(pa.string()))
        stamps = pc.strptime(text, format=map_.time_format, unit="s", error_is_null=True)
        milliseconds, good = _seconds_as_milliseconds(stamps)
        good &= on_a_real_day(stamps, text, map_.time_format)
    if map_.has("millisecond"):
        extra, _ = _raw_number(map_, batch, "millisecond")
        extra = np.where(np.isnan(extra), 0.0, extra)
        with np.errstate(invalid="ignore"):
            good &= (extra >= 0) & (extra < 1000) & (np.floor(extra) == extra)
        milliseconds = milliseconds + np.where(good, extra, 0.0)
    whole = np.where(good, milliseconds, 0).astype(np.int64)
    stamps_ms = pa.array(whole, pa.int64(), mask=~good).cast(pa.timestamp("ms", tz="UTC"))
    return stamps_ms, ~good


def _seconds_as_milliseconds(stamps: pa.Array) -> tuple[FloatArray, BoolArray]:
    seconds = pc.fill_null(stamps.cast(pa.int64()), 0).to_numpy(zero_copy_only=False)
    good = np.asarray(stamps.is_valid().to_numpy(zero_copy_only=False), dtype=bool)
    return seconds.astype(np.float64) * 1000.0, good


def iso_milliseconds(text: pa.Array | pa.ChunkedArray) -> tuple[FloatArray, BoolArray]:
    """ISO 8601 times as milliseconds since the epoch (UTC), and which parse.

    ``2023-01-11T00:00:00``, a space for the ``T``, a fraction of a second (kept to the
    millisecond) and a zone (``Z``, ``+01:00``, ``-0500``, ``+01``): what MarineCadastre
    writes, and what pandas and databases write when they save such a column again. A time
    without a zone is UTC, as the layouts say.
    """
    if isinstance(text, pa.ChunkedArray):
        text = text.combine_chunks()
    parts = pc.extract_regex(pc.utf8_trim_whitespace(text), _ISO_TIME)
    whole = pc.binary_join_element_wise(
        pc.struct_field(parts, "date"), pc.struct_field(parts, "time"), "T"
    )
    stamps = pc.strptime(whole, format=ISO_TIME_FORMAT, unit="s", error_is_null=True)
    milliseconds, good = _seconds_as_milliseconds(stamps)
    good &= on_the_written_day(stamps, whole, _ISO_DAY_AND_SECOND)
    fraction = pc.utf8_rpad(
        pc.utf8_slice_codeunits(pc.struct_field(parts, "fraction"), 0, 3), 3, "0"
    )
    fraction_ms = pc.fill_null(pc.cast(fraction, pa.int64()), 0).to_numpy(zero_copy_only=False)
    zones = pc.dictionary_encode(pc.fill_null(pc.struct_field(parts, "zone"), ""))
    offsets_min = np.array([_zone_minutes(z) for z in zones.dictionary.to_pylist()], np.float64)
    zone_min = offsets_min[np.asarray(zones.indices.to_numpy(zero_copy_only=False), np.int64)]
    return milliseconds + fraction_ms - zone_min * 60_000.0, good & np.isfinite(zone_min)


def _zone_minutes(zone: str) -> float:
    """``Z``/empty -> 0, ``+01:00``/``+0100``/``+01`` -> 60, ``-05:30`` -> -330; NaN for a
    zone no place keeps (beyond ±14 h, or 60 minutes or more)."""
    if zone in ("", "Z"):
        return 0.0
    digits = zone[1:].replace(":", "")
    hours, minutes = int(digits[:2]), int(digits[2:]) if len(digits) > 2 else 0
    if hours > 14 or minutes >= 60:
        return math.nan
    offset = hours * 60 + minutes
    return float(-offset if zone[0] == "-" else offset)


def mapped_static_text(map_: ColumnMap, batch: Batch) -> BoolArray:
    """Rows that carry a ship type, name, call sign or IMO."""
    present = np.zeros(batch.num_rows, dtype=bool)
    for target in ("ship_type", "name", "callsign", "imo"):
        if target == "ship_type":
            valid = pc.is_valid(_ship_types(map_, batch))
        else:
            valid = pc.is_valid(_text(map_, batch, target))
        present |= np.asarray(valid.to_numpy(zero_copy_only=False), dtype=bool)
    return present


def mapped_canonical(map_: ColumnMap, batch: Batch) -> tuple[pa.Table, BoolArray]:
    """The rows in the canonical schema, and which had a time that does not parse."""
    stamps, bad_time = _timestamps(map_, batch)
    mmsi, _ = mmsi_column(batch.column(map_.column("mmsi")))
    lat, _ = _number(map_, batch, "lat_deg")
    lon, _ = _number(map_, batch, "lon_deg")
    imo_text = pc.utf8_ltrim(pc.utf8_upper(_text(map_, batch, "imo")), characters="IMO ")
    imo, _ = float_column(imo_text)
    offsets = _offsets(map_, batch)
    measured = _measure(map_, batch, offsets)
    length, breadth, draught = plausible(measured)
    parts = no_offsets(batch.num_rows) if offsets is None else offsets.columns(measured)
    table = pa.table(
        {
            "timestamp": stamps,
            "mmsi": pa.array(mmsi, pa.int64()),
            "lat_deg": nan_to_null(null_outside(lat, -90.0, 90.0)),
            "lon_deg": nan_to_null(null_outside(lon, -180.0, 180.0)),
            "sog_kn": nan_to_null(clean_sog(_number(map_, batch, "sog_kn")[0])),
            "cog_deg": nan_to_null(clean_angle(_number(map_, batch, "cog_deg")[0])),
            "heading_deg": nan_to_null(clean_angle(_number(map_, batch, "heading_deg")[0])),
            "rot_deg_per_min": nan_to_null(_rot(map_, batch)),
            "nav_status": _nav_status(map_, batch),
            "ship_type": _ship_types(map_, batch),
            "mobile_type": mobile_types(map_, batch),
            "length_m": nan_to_null(length),
            "breadth_m": nan_to_null(breadth),
            **parts,
            "draught_m": nan_to_null(draught),
            "name": _text(map_, batch, "name"),
            "callsign": _text(map_, batch, "callsign"),
            "imo": whole_positive(imo),
        },
        schema=CANONICAL_SCHEMA,
    )
    return table, bad_time
