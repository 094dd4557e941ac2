"""Decoded NMEA messages (nmea.py) as the batch of a read: sentinels to nulls, AIS's A, B, C,
D cleaned (``clean.offset_parts``), implausible dimensions counted, and the static reports
joined to the positions (nmea.py's docstring, "Static join").

The join takes each static field from the report nearest in time that has it, but the four
antenna offsets together, from the nearest report with any of them: A from one message and B
from another could draw a hull no message described. A type 19 position's own offsets win,
as its other static fields do.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
import pyarrow as pa

from .batch import STATIC_SCHEMA, AisBatch
from .clean import (
    SHIP_TYPE_CATEGORIES,
    Dimensions,
    OffsetParts,
    implausible,
    implausible_text,
    offset_parts,
    plausible,
    valid_mmsi,
)
from .ledger import DropReason, RejectsLedger
from .schema import ANTENNA_OFFSETS, CANONICAL_SCHEMA

# The time of a message kept without one (``keep_timeless``): a null timestamp in the tables.
NO_TIME_MS = int(np.iinfo(np.int64).min)


@dataclass
class NmeaColumns:
    """Decoded values as plain lists; sentinels are nulled later, on whole arrays."""

    timestamp: list[int] = field(default_factory=list)  # milliseconds since the epoch
    line_no: list[int] = field(default_factory=list)  # of the message's first sentence
    mmsi: list[int] = field(default_factory=list)
    msg_type: list[int] = field(default_factory=list)
    lat: list[float | None] = field(default_factory=list)
    lon: list[float | None] = field(default_factory=list)
    sog: list[float | None] = field(default_factory=list)
    cog: list[float | None] = field(default_factory=list)
    heading: list[float | None] = field(default_factory=list)
    rot_raw: list[float | None] = field(default_factory=list)
    nav_status: list[float | None] = field(default_factory=list)
    ship_type: list[float | None] = field(default_factory=list)
    to_bow: list[float | None] = field(default_factory=list)
    to_stern: list[float | None] = field(default_factory=list)
    to_port: list[float | None] = field(default_factory=list)
    to_starboard: list[float | None] = field(default_factory=list)
    draught: list[float | None] = field(default_factory=list)
    name: list[str | None] = field(default_factory=list)
    callsign: list[str | None] = field(default_factory=list)
    imo: list[float | None] = field(default_factory=list)


POSITION_TYPES = frozenset({1, 2, 3, 18, 19, 27})
_CLASS_B_TYPES = frozenset({18, 19})
# Type 27 is the long-range broadcast of SOLAS (Class A) ships.
_MOBILE_TYPE = {t: "Class B" if t in _CLASS_B_TYPES else "Class A" for t in POSITION_TYPES}
# Joined field by field from the nearest report that has it.
_JOINED_FIELDS = ("ship_type", "length_m", "breadth_m", "draught_m", "name", "callsign", "imo")


def nmea_batch(
    positions: NmeaColumns, statics: NmeaColumns, source_name: str, ledger: RejectsLedger
) -> AisBatch:
    """The batch of a read: the positions with the static fields joined, and the static
    reports (types 5 and 24). Messages with a valid MMSI whose length or breadth is dropped
    as implausible are counted in ``ledger`` (``implausible_dimension``), once each."""
    static_frame = _static_frame(statics, source_name, ledger)
    # Type 19 positions carry static fields too; they fill other positions of that vessel.
    position_statics = _static_frame(positions, source_name, ledger)
    is_type19 = np.array(positions.msg_type, dtype=np.int64) == 19
    join_source = pd.concat([static_frame, position_statics[is_type19]], ignore_index=True)
    return AisBatch(
        positions=_positions_table(positions, position_statics, join_source),
        statics=_statics_table(static_frame),
        position_lines=np.array(positions.line_no, dtype=np.int64),
        static_lines=np.array(statics.line_no, dtype=np.int64),
    )


def _floats(values: list[float | None]) -> np.ndarray:
    return np.array(values, dtype=np.float64)


def _null_where(values: np.ndarray, not_available: np.ndarray) -> np.ndarray:
    return np.where(not_available, np.nan, values)


def _measured(columns: NmeaColumns) -> tuple[OffsetParts, Dimensions]:
    """The messages' A, B, C, D cleaned, and their length (A+B, or B where the reference
    point is not available), breadth and draught before the limits."""
    offsets = offset_parts(
        _floats(columns.to_bow),
        _floats(columns.to_stern),
        _floats(columns.to_port),
        _floats(columns.to_starboard),
    )
    none = np.full(len(columns.mmsi), np.nan)  # no length or breadth but from the parts
    return offsets, offsets.dimensions(none, none, _floats(columns.draught))


def _count_implausible(
    columns: NmeaColumns, measured: Dimensions, source_name: str, ledger: RejectsLedger
) -> None:
    """Count the messages of ``columns`` whose length or breadth ``_static_frame`` drops as
    implausible, with a valid MMSI (the pipeline rejects the others): ``implausible_dimension``."""
    flagged = implausible(measured) & valid_mmsi(np.array(columns.mmsi, dtype=np.int64))
    if not flagged.any():
        return
    first = int(np.flatnonzero(flagged)[0])
    what = implausible_text(*(float(values[first]) for values in measured))
    ledger.drop(
        DropReason.IMPLAUSIBLE_DIMENSION,
        int(flagged.sum()),
        example=f"{source_name}:{columns.line_no[first]}: implausible dimension dropped "
        f"({what}): MMSI {columns.mmsi[first]}",
    )


def _text(values: list[str | None]) -> pd.Series:
    series = pd.Series(values, dtype=object)
    return series.where(series.notna() & (series != "") & (series != "Unknown"), None)


def _static_frame(columns: NmeaColumns, source_name: str, ledger: RejectsLedger) -> pd.DataFrame:
    """Static fields of ``columns`` with sentinels as nulls, implausible dimensions dropped
    (and counted in ``ledger``); ship_type stays numeric here."""
    offsets, measured = _measured(columns)
    _count_implausible(columns, measured, source_name, ledger)
    length_m, breadth_m, draught_m = plausible(measured)
    ship_type = _floats(columns.ship_type)
    imo = _floats(columns.imo)
    return pd.DataFrame(
        {
            "timestamp": np.array(columns.timestamp, dtype=np.int64),
            "mmsi": np.array(columns.mmsi, dtype=np.int64),
            "ship_type": _null_where(ship_type, ~(ship_type > 0)),
            "length_m": length_m,
            "breadth_m": breadth_m,
            **dict(zip(ANTENNA_OFFSETS, offsets.trusted(measured), strict=True)),
            "draught_m": draught_m,
            "name": _text(columns.name),
            "callsign": _text(columns.callsign),
            "imo": _null_where(imo, ~(imo > 0)),
        }
    )


def _join_statics(positions: pd.DataFrame, statics: pd.DataFrame) -> pd.DataFrame:
    """Fill each static field of ``positions`` from the nearest-in-time report that has it,
    and the four antenna offsets together from the nearest report with any of them."""
    if positions.empty or statics.empty:
        return positions
    ordered = positions.reset_index(names="_row").sort_values("timestamp", kind="stable")
    for names in (*((name,) for name in _JOINED_FIELDS), ANTENNA_OFFSETS):
        wanted = list(names)
        source = statics.loc[statics[wanted].notna().any(axis=1), ["timestamp", "mmsi", *wanted]]
        if source.empty:
            continue
        joined = [f"_joined_{name}" for name in names]
        nearest = pd.merge_asof(
            ordered[["_row", "timestamp", "mmsi"]],
            source.sort_values("timestamp", kind="stable").rename(
                columns=dict(zip(wanted, joined, strict=True))
            ),
            on="timestamp",
            by="mmsi",
            direction="nearest",
        )
        own = ordered[wanted].notna().any(axis=1).to_numpy()
        for name, from_report in zip(wanted, joined, strict=True):
            ordered[name] = np.where(own, ordered[name].to_numpy(), nearest[from_report].to_numpy())
    return ordered.sort_values("_row").drop(columns="_row").reset_index(drop=True)


def _ship_type_text(codes: pd.Series) -> pa.Array:
    text = codes.map(lambda code: SHIP_TYPE_CATEGORIES.get(int(code)), na_action="ignore")
    return pa.array(text.where(text.notna(), None), type=pa.string())


def _timestamps(milliseconds: pd.Series) -> pa.Array:
    """Milliseconds as timestamps; ``NO_TIME_MS`` (a message kept without a time) as null."""
    values = milliseconds.to_numpy(dtype=np.int64)
    missing = values == NO_TIME_MS
    return pa.array(
        values,
        type=pa.timestamp("ms", tz="UTC"),
        mask=missing if missing.any() else None,
    )


def _optional(values: pd.Series | np.ndarray, dtype: pa.DataType) -> pa.Array:
    return pa.array(values, type=dtype, from_pandas=True)


def _positions_table(
    columns: NmeaColumns, own_static: pd.DataFrame, statics: pd.DataFrame
) -> pa.Table:
    long_range = np.array(columns.msg_type, dtype=np.int64) == 27
    lat = _floats(columns.lat)
    lon = _floats(columns.lon)
    sog = _floats(columns.sog)
    cog = _floats(columns.cog)
    heading = _floats(columns.heading)
    rot_raw = _floats(columns.rot_raw)
    # ±127 is "turning faster than 5°/30 s, no turn indicator": no rate is known.
    rot_known = np.abs(rot_raw) <= 126
    rot = np.where(rot_known, np.sign(rot_raw) * (rot_raw / 4.733) ** 2, np.nan)
    positions = pd.DataFrame(
        {
            "timestamp": own_static["timestamp"],
            "mmsi": own_static["mmsi"],
            "lat_deg": _null_where(lat, ~(np.abs(lat) <= 90)),
            "lon_deg": _null_where(lon, ~(np.abs(lon) <= 180)),
            # Type 27 sends whole knots and degrees, with 63 and 511 as "not available".
            "sog_kn": _null_where(sog, ~np.where(long_range, sog < 63, sog < 102.3)),
            "cog_deg": _null_where(cog, ~(cog < 360)),
            "heading_deg": _null_where(heading, ~(heading < 360)),
            "rot_deg_per_min": rot,
            "nav_status": _floats(columns.nav_status),
            **own_static.drop(columns=["timestamp", "mmsi"]),
        }
    )
    positions = _join_statics(positions, statics)
    mobile_type = [_MOBILE_TYPE[t] for t in columns.msg_type]
    return pa.table(
        {
            "timestamp": _timestamps(positions["timestamp"]),
            "mmsi": pa.array(positions["mmsi"], type=pa.int64()),
            "lat_deg": _optional(positions["lat_deg"], pa.float64()),
            "lon_deg": _optional(positions["lon_deg"], pa.float64()),
            "sog_kn": _optional(positions["sog_kn"], pa.float64()),
            "cog_deg": _optional(positions["cog_deg"], pa.float64()),
            "heading_deg": _optional(positions["heading_deg"], pa.float64()),
            "rot_deg_per_min": _optional(positions["rot_deg_per_min"], pa.float64()),
            "nav_status": _optional(positions["nav_status"], pa.int8()),
            "ship_type": _ship_type_text(positions["ship_type"]),
            "mobile_type": pa.array(mobile_type, type=pa.string()),
            **_dimension_columns(positions),
            "name": _optional(positions["name"], pa.string()),
            "callsign": _optional(positions["callsign"], pa.string()),
            "imo": _optional(positions["imo"], pa.int64()),
        },
        schema=CANONICAL_SCHEMA,
    )


def _dimension_columns(frame: pd.DataFrame) -> dict[str, pa.Array]:
    names = ("length_m", "breadth_m", *ANTENNA_OFFSETS, "draught_m")
    return {name: _optional(frame[name], pa.float64()) for name in names}


def _statics_table(statics: pd.DataFrame) -> pa.Table:
    return pa.table(
        {
            "timestamp": _timestamps(statics["timestamp"]),
            "mmsi": pa.array(statics["mmsi"], type=pa.int64()),
            "ship_type": _ship_type_text(statics["ship_type"]),
            **_dimension_columns(statics),
            "name": _optional(statics["name"], pa.string()),
            "callsign": _optional(statics["callsign"], pa.string()),
            "imo": _optional(statics["imo"], pa.int64()),
        },
        schema=STATIC_SCHEMA,
    )
