"""Cleaning helpers shared by the readers: text to numbers, sentinels to nulls, code tables.

"Not available" becomes null (docs/design.md §4): latitude outside ±90 (91), longitude outside ±180
(181), SOG 102.3 and above, COG 360 and above, heading 360 and above (511), a rate of turn
beyond ±720 deg/min (the sentinel -128 decoded), dimension 0 or less, draught 0 or less, a
dimension beyond what ships have or not finite (``MAX_LENGTH_M`` ...; counted as
``implausible_dimension``), AIS's A, B, C, D as ``offset_parts`` says, IMO 0 or less, and
the texts ``Unknown``, ``Undefined``, ``Unknown value`` and empty text in text columns.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from datetime import datetime

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
from numpy.typing import NDArray

from ..vessels import (
    MAX_BREADTH_M,
    MAX_DRAUGHT_M,
    MAX_LENGTH_M,
    MMSI_MAX,
    MMSI_MIN,
    VESSEL_MOBILE_TYPES,
)
from .schema import ANTENNA_OFFSETS

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

MAX_ROT_DEG_PER_MIN = 720.0
_NUMBER = r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$"
_NULL_TEXTS = ["", "unknown", "undefined", "unknown value", "not available", "n/a"]
NULL_TEXTS = frozenset(_NULL_TEXTS)
# Null in a number column: empty, or one of pyarrow's default null spellings (lower case),
# which the CSV parse leaves to ``to_float`` (see csv_chunks.py).
_NUMBER_NULL_TEXTS = ["", "#n/a", "#n/a n/a", "#na", "-1.#ind", "-1.#qnan", "-nan", "1.#ind"]
_NUMBER_NULL_TEXTS += ["1.#qnan", "n/a", "na", "nan", "null"]

# Navigational status text (DMA and others) -> ITU-R M.1371 code, matched after lower-casing
# and dropping everything but letters. Unrecognised text maps to null.
_NAV_STATUS_TEXTS: dict[str, int] = {
    "underwayusingengine": 0,
    "atanchor": 1,
    "notundercommand": 2,
    "restrictedmanoeuverability": 3,
    "restrictedmaneuverability": 3,
    "restrictedmanoeuvrability": 3,
    "restrictedmaneuvrability": 3,
    "restrictedmanouverability": 3,
    "constrainedbyherdraught": 4,
    "constrainedbyherdraft": 4,
    "constrainedbydraught": 4,
    "moored": 5,
    "aground": 6,
    "engagedinfishing": 7,
    "underwaysailing": 8,
    "reservedforhsc": 9,
    "reservedforfutureamendmenthsc": 9,
    "reservedforwig": 10,
    "reservedforfutureamendmentwig": 10,
    "powerdrivenvesseltowingastern": 11,
    "powerdrivenvesselpushingaheadortowingalongside": 12,
    "reservedforfutureuse": 13,
    "aissart": 14,
    "aissartisactive": 14,
    "unknownvalue": 15,
    "unknown": 15,
    "undefined": 15,
    "notdefined": 15,
    "notdefineddefault": 15,
}
_NOT_LETTERS = re.compile(r"[^a-z]")

# Numeric AIS ship type (ITU-R M.1371 table 53) -> the DMA "Ship type" text. 0 ("not
# available") is absent on purpose: it becomes null, like DMA's "Undefined".
SHIP_TYPE_CATEGORIES: dict[int, str] = {
    **dict.fromkeys(range(1, 20), "Reserved"),
    **dict.fromkeys(range(20, 30), "WIG"),
    30: "Fishing",
    31: "Towing",
    32: "Towing long/wide",
    33: "Dredging",
    34: "Diving",
    35: "Military",
    36: "Sailing",
    37: "Pleasure",
    38: "Reserved",
    39: "Reserved",
    **dict.fromkeys(range(40, 50), "HSC"),
    50: "Pilot",
    51: "SAR",
    52: "Tug",
    53: "Port tender",
    54: "Anti-pollution",
    55: "Law enforcement",
    56: "Spare 1",
    57: "Spare 2",
    58: "Medical",
    59: "Not party to conflict",
    **dict.fromkeys(range(60, 70), "Passenger"),
    **dict.fromkeys(range(70, 80), "Cargo"),
    **dict.fromkeys(range(80, 90), "Tanker"),
    **dict.fromkeys(range(90, 100), "Other"),
}


_SHIP_TYPE_SPELLINGS = {name.lower(): name for name in SHIP_TYPE_CATEGORIES.values()}


def nav_status_code(text: str | None) -> int | None:
    """The ITU code of a navigational status text; DMA's ``Unknown value`` is 15 ("not
    defined", the AIS default), unrecognised or empty text is null."""
    if text is None:
        return None
    key = _NOT_LETTERS.sub("", text.lower())
    if not key:
        return None
    if key in _NAV_STATUS_TEXTS:
        return _NAV_STATUS_TEXTS[key]
    if key.startswith("restricted"):
        return 3
    if key.startswith("constrained"):
        return 4
    return None


def nav_status_from_text(values: pa.Array | pa.ChunkedArray) -> pa.Array:
    """Map a text column to int8 codes, looking each distinct text up once."""
    encoded = pc.dictionary_encode(values)
    if isinstance(encoded, pa.ChunkedArray):
        encoded = encoded.combine_chunks()
    codes = pa.array([nav_status_code(t) for t in encoded.dictionary.to_pylist()], pa.int8())
    return pc.take(codes, encoded.indices)


def to_float(values: pa.Array | pa.ChunkedArray) -> tuple[pa.Array, BoolArray]:
    """A column as float64, and where it held text that is not a number.

    Columns read as numbers pass through. Text is cast directly when it all parses, else
    entry by entry: non-numeric text becomes null and is flagged; empty text, ``NULL``,
    ``N/A``, ``NaN`` and the like are just null.
    """
    if isinstance(values, pa.ChunkedArray):
        values = values.combine_chunks()
    n = len(values)
    if pa.types.is_floating(values.type) or pa.types.is_integer(values.type):
        return values.cast(pa.float64()), np.zeros(n, dtype=bool)
    if pa.types.is_null(values.type):
        return pa.nulls(n, pa.float64()), np.zeros(n, dtype=bool)
    absent = pc.is_in(
        pc.utf8_lower(pc.utf8_trim_whitespace(values)), value_set=pa.array(_NUMBER_NULL_TEXTS)
    )
    present = pc.and_(pc.invert(absent), pc.is_valid(values))
    cleaned = pc.if_else(present, values, pa.scalar(None, pa.string()))
    try:
        return pc.cast(cleaned, pa.float64()), np.zeros(n, dtype=bool)
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
        # Arrow's cast takes no padding, which database and fixed-width exports write.
        trimmed = pc.utf8_trim_whitespace(cleaned)
        numeric = pc.fill_null(pc.match_substring_regex(trimmed, _NUMBER), False)
        usable = pc.if_else(numeric, trimmed, pa.scalar(None, pa.string()))
        bad = pc.and_(pc.fill_null(present, False), pc.invert(numeric))
        return pc.cast(usable, pa.float64()), bad.to_numpy(zero_copy_only=False)


def to_numpy_float(values: pa.Array | pa.ChunkedArray) -> FloatArray:
    """Nulls as NaN (filling first is faster than letting to_numpy do it)."""
    if values.null_count:
        values = pc.fill_null(values, pa.scalar(np.nan, pa.float64()))
    return np.asarray(values.to_numpy(zero_copy_only=False), dtype=np.float64)


def float_column(values: pa.Array | pa.ChunkedArray) -> tuple[FloatArray, BoolArray]:
    if pa.types.is_floating(values.type) or pa.types.is_integer(values.type):
        return to_numpy_float(values.cast(pa.float64())), np.zeros(len(values), dtype=bool)
    array, bad = to_float(values)
    return to_numpy_float(array), bad


def null_outside(values: FloatArray, low: float, high: float) -> FloatArray:
    """NaN where a value is outside [low, high] (the AIS sentinels lie outside)."""
    with np.errstate(invalid="ignore"):
        return np.where((values >= low) & (values <= high), values, np.nan)


def positive_or_nan(values: FloatArray) -> FloatArray:
    with np.errstate(invalid="ignore"):
        return np.where(values > 0, values, np.nan)


def clean_sog(values: FloatArray) -> FloatArray:
    with np.errstate(invalid="ignore"):
        return np.where((values >= 0) & (values < 102.25), values, np.nan)


def clean_angle(values: FloatArray) -> FloatArray:
    """COG or heading: [0, 360) is valid; 360 (COG) and 511 (heading) are not available."""
    with np.errstate(invalid="ignore"):
        return np.where((values >= 0) & (values < 360), values, np.nan)


def clean_rot(values: FloatArray) -> FloatArray:
    with np.errstate(invalid="ignore"):
        cleaned = np.where(np.abs(values) <= MAX_ROT_DEG_PER_MIN, values, np.nan)
    return cleaned + 0.0  # turns -0.0 into 0.0


def clean_text(values: pa.Array | pa.ChunkedArray) -> pa.Array:
    """Trimmed text with the "not available" spellings (``Unknown``, empty, ...) as null."""
    if isinstance(values, pa.ChunkedArray):
        values = values.combine_chunks()
    if pa.types.is_null(values.type):
        return pa.nulls(len(values), pa.string())
    text = pc.utf8_trim_whitespace(values.cast(pa.string()))
    missing = pc.is_in(pc.utf8_lower(text), value_set=pa.array(_NULL_TEXTS))
    return pc.if_else(missing, pa.scalar(None, pa.string()), text)


def clean_ship_type(values: pa.Array | pa.ChunkedArray) -> pa.Array:
    """``clean_text``, with each ship type category of ``SHIP_TYPE_CATEGORIES`` in one
    spelling whatever its case (DMA's ``Cargo``, an export's ``CARGO``): one group in
    ``stats --by ship_type``, as a query matches them. Other texts stay as written."""
    text = clean_text(values)
    encoded = pc.dictionary_encode(text)
    names = [
        None if name is None else _SHIP_TYPE_SPELLINGS.get(name.lower(), name)
        for name in encoded.dictionary.to_pylist()
    ]
    return pc.take(pa.array(names, pa.string()), encoded.indices)


def valid_mmsi(mmsi: NDArray[np.int64]) -> BoolArray:
    """Nine digits with maritime identification digits (the first three) in 201-775."""
    return (mmsi >= MMSI_MIN) & (mmsi <= MMSI_MAX)


def is_vessel(mobile_type: pa.Array) -> BoolArray:
    mask = pc.is_in(mobile_type, value_set=pa.array(sorted(VESSEL_MOBILE_TYPES)))
    return np.asarray(pc.fill_null(mask, False).to_numpy(zero_copy_only=False), dtype=bool)


Dimensions = tuple[FloatArray, FloatArray, FloatArray]

# The largest dimensions a ship has: ``vessels.MAX_LENGTH_M`` and the others.
_LIMITS_M = (MAX_LENGTH_M, MAX_BREADTH_M, MAX_DRAUGHT_M)


def plausible(dimensions: Dimensions) -> Dimensions:
    """Length, breadth and draught with implausible values (module limits) as NaN."""
    return (
        null_outside(dimensions[0], 0.0, MAX_LENGTH_M),
        null_outside(dimensions[1], 0.0, MAX_BREADTH_M),
        null_outside(dimensions[2], 0.0, MAX_DRAUGHT_M),
    )


def implausible(dimensions: Dimensions) -> BoolArray:
    """Rows with a dimension that is reported (positive) but beyond the module limits or not
    finite: ``plausible`` would drop it."""
    with np.errstate(invalid="ignore"):
        beyond = [
            (values > 0.0) & ~(values <= limit_m)
            for values, limit_m in zip(dimensions, _LIMITS_M, strict=True)
        ]
    return np.asarray(beyond[0] | beyond[1] | beyond[2], dtype=bool)


def implausible_text(length_m: float, breadth_m: float, draught_m: float) -> str:
    """The dimensions of one row that ``plausible`` drops, for the ledger's examples
    (``length 900 m, draught inf m``)."""
    return ", ".join(
        f"{name} {value:g} m"
        for name, value, limit_m in zip(
            ("length", "breadth", "draught"),
            (length_m, breadth_m, draught_m),
            _LIMITS_M,
            strict=True,
        )
        if value > 0.0 and not value <= limit_m
    )


@dataclass(frozen=True)
class DimensionColumns:
    """A block's dimension columns as read, one row per row, and ``measure``, the reader's
    way of turning such columns into length, breadth and draught in metres (A+B, or Length;
    NaN = not available) before the module limits; ``clean`` applies them (``plausible``).

    Cleaning is left until it is needed: a vessel repeats its dimensions in row after row,
    so the pipeline counts the distinct rows as read and cleans only those.
    """

    table: pa.Table
    measure: Callable[[pa.Table], Dimensions]

    def clean(self, table: pa.Table) -> Dimensions:
        """The dimensions of ``table`` (columns as ``self.table``'s, more may follow), with
        the implausible ones dropped."""
        return plausible(self.measure(table))

    def of_rows(self, rows: NDArray[np.int64]) -> Dimensions:
        return self.clean(self.table.take(pa.array(rows, pa.int64())))

    def measured_rows(self, rows: NDArray[np.int64]) -> Dimensions:
        """``measure`` for some rows of ``self.table`` (indices): before the limits."""
        return self.measure(self.table.take(pa.array(rows, pa.int64())))

    def implausible(self, table: pa.Table | None = None) -> BoolArray:
        """Which rows of ``table`` (default ``self.table``) report a dimension that
        ``clean`` drops as implausible: beyond the module limits or not finite."""
        return implausible(self.measure(self.table if table is None else table))

    def implausible_rows(self, rows: NDArray[np.int64]) -> BoolArray:
        """``implausible`` for some rows of ``self.table`` (indices)."""
        return self.implausible(self.table.take(pa.array(rows, pa.int64())))


@dataclass(frozen=True)
class OffsetParts:
    """Each row's AIS A, B, C, D cleaned by ``offset_parts`` (NaN: not available), and the
    length and breadth they give (NaN where they give none), before the module limits."""

    to_bow_m: FloatArray
    to_stern_m: FloatArray
    to_port_m: FloatArray
    to_starboard_m: FloatArray
    length_m: FloatArray
    breadth_m: FloatArray

    def dimensions(
        self, length_m: FloatArray, breadth_m: FloatArray, draught_m: FloatArray
    ) -> Dimensions:
        """A reader's measure (``DimensionColumns``): length and breadth from the parts
        where they give them, else from the length and breadth columns where > 0; the
        draught where > 0. Before the module limits."""
        return (
            np.where(np.isnan(self.length_m), positive_or_nan(length_m), self.length_m),
            np.where(np.isnan(self.breadth_m), positive_or_nan(breadth_m), self.breadth_m),
            positive_or_nan(draught_m),
        )

    def trusted(self, measured: Dimensions) -> list[FloatArray]:
        """A, B, C, D, all four NaN on the rows whose length or breadth in ``measured``
        (``dimensions``) ``plausible`` drops: a corrupt row's parts are not trusted either,
        and the row is counted once, as ``implausible_dimension``, with its length or
        breadth."""
        with np.errstate(invalid="ignore"):
            dropped = (measured[0] > 0.0) & ~(measured[0] <= MAX_LENGTH_M)
            dropped |= (measured[1] > 0.0) & ~(measured[1] <= MAX_BREADTH_M)
        parts = [self.to_bow_m, self.to_stern_m, self.to_port_m, self.to_starboard_m]
        if not dropped.any():
            return parts
        return [np.where(dropped, np.nan, part) for part in parts]

    def columns(self, measured: Dimensions) -> dict[str, pa.Array]:
        """``trusted`` as the four canonical columns (``schema.ANTENNA_OFFSETS``)."""
        return {
            name: nan_to_null(part)
            for name, part in zip(ANTENNA_OFFSETS, self.trusted(measured), strict=True)
        }


def offset_parts(a: FloatArray, b: FloatArray, c: FloatArray, d: FloatArray) -> OffsetParts:
    """AIS A (to the bow), B (to the stern), C (to port), D (to starboard) as read, in
    metres, cleaned the one way every reader cleans them (ITU-R M.1371, "reference point
    for reported position"):

    - a part of 0 or less, or NaN, is not available (0 is AIS's "not available");
    - A = C = 0 with B, D > 0 is "reference point not available, dimensions available":
      no part is available, and the vessel is B long and D wide;
    - length is A + B where both are given, breadth C + D. A part given alone (its
      partner not available) gives no length, unless it alone is beyond what ships have
      (``MAX_LENGTH_M``, ``MAX_BREADTH_M``) or not finite: it is then the length (or
      breadth), which the limits drop as implausible and the ledger counts, rather than
      a corrupt part kept silently.
    """
    with np.errstate(invalid="ignore"):
        no_reference = (a == 0.0) & (c == 0.0) & (b > 0.0) & (d > 0.0)
        bow, stern, port, starboard = (
            np.where(no_reference, np.nan, positive_or_nan(part)) for part in (a, b, c, d)
        )
        length_m = np.where(no_reference, b, _span(bow, stern, MAX_LENGTH_M))
        breadth_m = np.where(no_reference, d, _span(port, starboard, MAX_BREADTH_M))
    return OffsetParts(bow, stern, port, starboard, length_m, breadth_m)


def _span(first: FloatArray, second: FloatArray, limit_m: float) -> FloatArray:
    """first + second where both are given (> 0); a lone part beyond ``limit_m`` (or
    infinite) as itself; else NaN. The parts are positive or NaN."""
    with np.errstate(invalid="ignore"):
        lone = np.where(np.isnan(first), second, first)
        return np.where(
            ~np.isnan(first) & ~np.isnan(second),
            first + second,
            np.where(lone > limit_m, lone, np.nan),
        )


def no_offsets(rows: int) -> dict[str, pa.Array]:
    """The four canonical offset columns, all null: a layout without A, B, C, D."""
    return dict.fromkeys(ANTENNA_OFFSETS, pa.nulls(rows, pa.float64()))


def any_dimension(length_m: FloatArray, breadth_m: FloatArray, draught_m: FloatArray) -> BoolArray:
    return ~(np.isnan(length_m) & np.isnan(breadth_m) & np.isnan(draught_m))


@dataclass
class Fields:
    """What the pipeline needs of every row of a block before choosing the rows to keep.

    ``mmsi`` is -1 where missing or not a number. ``unparseable`` marks rows with text
    where a number belongs (in MMSI, latitude or longitude), with ``problem`` saying what
    for the ledger's examples (empty when no row is unparseable). Positions are cleaned
    (NaN = not available); dimensions are as read, with their cleaning.
    """

    mmsi: NDArray[np.int64]
    lat_deg: FloatArray
    lon_deg: FloatArray
    vessel: BoolArray
    dimensions: DimensionColumns
    unparseable: BoolArray
    problem: list[str]

    def __len__(self) -> int:
        return len(self.mmsi)


# Larger than any MMSI (nine digits); the row is then an invalid MMSI.
_MMSI_LIMIT = 1e12


def mmsi_column(values: pa.Array | pa.ChunkedArray) -> tuple[NDArray[np.int64], BoolArray]:
    """MMSIs as int64 (-1 where missing or not an integer), and where the text was not a number."""
    if pa.types.is_integer(values.type):
        filled = pc.fill_null(values, -1).to_numpy()
        return np.asarray(filled, dtype=np.int64), np.zeros(len(values), dtype=bool)
    floats, bad = float_column(values)
    whole = np.isfinite(floats) & (np.floor(floats) == floats)
    bad = bad | (np.isfinite(floats) & ~whole)
    # A number too long for any MMSI (20 digits would not even fit int64) is invalid, not cast.
    whole &= np.abs(np.where(whole, floats, 0.0)) < _MMSI_LIMIT
    return np.where(whole, floats, -1).astype(np.int64), bad


def number_problems(
    bad_mmsi: BoolArray, bad_lat: BoolArray, bad_lon: BoolArray
) -> tuple[BoolArray, list[str]]:
    """``Fields.unparseable`` and ``Fields.problem`` from where each column held text."""
    unparseable = bad_mmsi | bad_lat | bad_lon
    if not unparseable.any():
        return unparseable, []
    problem = np.where(bad_mmsi, "MMSI", np.where(bad_lat, "latitude", "longitude"))
    return unparseable, problem.tolist()


def nan_to_null(values: np.ndarray) -> pa.Array:
    return pa.array(values, pa.float64(), from_pandas=True)


def whole_positive(values: np.ndarray) -> pa.Array:
    with np.errstate(invalid="ignore"):
        usable = (values > 0) & (np.floor(values) == values)
    return pa.array(np.where(usable, values, 0).astype(np.int64), pa.int64(), mask=~usable)


def on_the_written_day(
    stamps: pa.Array | pa.ChunkedArray, text: pa.Array | pa.ChunkedArray, pattern: str
) -> BoolArray:
    """Whether each time parsed (not null) falls on the day of the month its text gives.

    Arrow's ``strptime`` carries a day past the month's end over (``30/02`` is 2 March),
    which would place a corrupt time in another day. Such a day lands on the 1st to 3rd, so
    only the times read there are checked. ``pattern`` captures the text's ``day`` and
    ``second``; a leap second (``23:59:60``) is read as the next second, midnight.
    """
    parsed = np.asarray(pc.is_valid(stamps).to_numpy(zero_copy_only=False), dtype=bool)
    early = pc.fill_null(pc.less_equal(pc.day(stamps), 3), False)
    (suspects,) = np.nonzero(np.asarray(early.to_numpy(zero_copy_only=False), dtype=bool))
    if not suspects.size:
        return parsed
    taken = pa.array(suspects)
    parts = pc.extract_regex(pc.take(text, taken), pattern)
    day = pc.cast(pc.struct_field(parts, "day"), pa.int64())
    leap = pc.fill_null(pc.equal(pc.cast(pc.struct_field(parts, "second"), pa.int64()), 60), False)
    back = pc.if_else(leap, pa.scalar(1, pa.duration("s")), pa.scalar(0, pa.duration("s")))
    same = pc.fill_null(pc.equal(pc.day(pc.subtract(pc.take(stamps, taken), back)), day), False)
    parsed[suspects] = np.asarray(same.to_numpy(zero_copy_only=False), dtype=bool)
    return parsed


def on_a_real_day(
    stamps: pa.Array | pa.ChunkedArray, text: pa.Array | pa.ChunkedArray, time_format: str
) -> BoolArray:
    """``on_the_written_day`` for any strftime ``time_format``: whether each time parsed (not
    null) was written on a day of the calendar. Only the times read as the 1st to 3rd are
    checked: printed back in the format, and where the text is not written as the format
    prints it (no zero padding, say), by Python's ``strptime``, which refuses such a day."""
    parsed = np.asarray(pc.is_valid(stamps).to_numpy(zero_copy_only=False), dtype=bool)
    if "%d" not in time_format:
        return parsed
    early = pc.fill_null(pc.less_equal(pc.day(stamps), 3), False)
    (suspects,) = np.nonzero(np.asarray(early.to_numpy(zero_copy_only=False), dtype=bool))
    if not suspects.size:
        return parsed
    taken = pa.array(suspects)
    written = pc.take(text, taken)
    try:
        printed = pc.strftime(pc.take(stamps, taken), format=time_format)
        same = pc.fill_null(pc.equal(printed, written), False)
        as_printed = np.asarray(same.to_numpy(zero_copy_only=False), dtype=bool)
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError):
        as_printed = np.zeros(suspects.size, dtype=bool)
    for index in np.flatnonzero(~as_printed):
        try:
            datetime.strptime(str(written[index]), time_format)
        except ValueError:
            parsed[suspects[index]] = False
    return parsed
