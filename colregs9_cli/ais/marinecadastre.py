"""The US MarineCadastre AIS CSV (``MMSI,BaseDateTime,LAT,LON,SOG,COG,Heading,VesselName,
IMO,CallSign,VesselType,Status,Length,Width,Draft,Cargo,TransceiverClass``), read by block.

``BaseDateTime`` is ISO 8601 UTC without an offset. The numeric ``VesselType`` (ITU-R
M.1371) maps to the DMA ship type texts (30 Fishing, 31 Towing, 52 Tug, 60-69 Passenger,
70-79 Cargo, 80-89 Tanker, ...; 0 is null, codes outside 1-99 are "Other"); ``Status`` is
already the ITU code (0-15, anything else null); ``TransceiverClass`` A/B becomes the mobile
type ``Class A``/``Class B``. ``IMO`` is written ``IMO9307839``. Length and breadth are the
``Length`` and ``Width`` columns (this layout has no A, B, C, D).
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from .clean import (
    SHIP_TYPE_CATEGORIES,
    BoolArray,
    DimensionColumns,
    Dimensions,
    Fields,
    clean_angle,
    clean_sog,
    clean_text,
    float_column,
    is_vessel,
    mmsi_column,
    nan_to_null,
    null_outside,
    number_problems,
    plausible,
    positive_or_nan,
    whole_positive,
)
from .columns import MARINECADASTRE_DIMENSION_COLUMNS as DIMENSION_COLUMNS
from .columns import MARINECADASTRE_STATIC_TEXT_COLUMNS as STATIC_TEXT_COLUMNS
from .schema import CANONICAL_SCHEMA

_OTHER = "Other"


def _mobile_type(values: pa.Array | pa.ChunkedArray) -> pa.Array:
    text = pc.utf8_upper(pc.utf8_trim_whitespace(values))
    return pc.if_else(
        pc.equal(text, "A"),
        "Class A",
        pc.if_else(pc.equal(text, "B"), "Class B", pa.scalar(None, pa.string())),
    )


def ship_type_text(codes: np.ndarray) -> pa.Array:
    """Numeric ship types to the DMA category texts (0 and NaN: null)."""
    texts = [
        None if not np.isfinite(code) or code == 0 else SHIP_TYPE_CATEGORIES.get(int(code), _OTHER)
        for code in codes
    ]
    return pa.array(texts, pa.string())


def marinecadastre_fields(batch: pa.RecordBatch) -> Fields:
    mmsi, bad_mmsi = mmsi_column(batch.column("mmsi"))
    lat, bad_lat = float_column(batch.column("lat"))
    lon, bad_lon = float_column(batch.column("lon"))
    unparseable, problem = number_problems(bad_mmsi, bad_lat, bad_lon)
    return Fields(
        mmsi=mmsi,
        lat_deg=null_outside(lat, -90.0, 90.0),
        lon_deg=null_outside(lon, -180.0, 180.0),
        vessel=is_vessel(_mobile_type(batch.column("transceiverclass"))),
        dimensions=DimensionColumns(batch.select(list(DIMENSION_COLUMNS)), _dimensions),
        unparseable=unparseable,
        problem=problem,
    )


def _dimensions(table: pa.Table) -> Dimensions:
    length, breadth, draught = (float_column(table.column(c))[0] for c in DIMENSION_COLUMNS)
    return plausible((positive_or_nan(length), positive_or_nan(breadth), positive_or_nan(draught)))


def marinecadastre_static_text(batch: pa.RecordBatch) -> BoolArray:
    present = np.asarray(
        pc.fill_null(pc.greater(float_column(batch.column("vesseltype"))[0], 0), False)
    )
    for column in STATIC_TEXT_COLUMNS:
        valid = pc.is_valid(clean_text(batch.column(column)))
        present |= np.asarray(valid.to_numpy(zero_copy_only=False), dtype=bool)
    return present


def marinecadastre_canonical(batch: pa.RecordBatch) -> tuple[pa.Table, BoolArray]:
    stamps_text = pc.utf8_replace_slice(
        pc.utf8_trim_whitespace(batch.column("basedatetime")), 10, 11, "T"
    )
    stamps = pc.strptime(stamps_text, format="%Y-%m-%dT%H:%M:%S", unit="s", error_is_null=True)
    bad_time = np.asarray(pc.is_null(stamps).to_numpy(zero_copy_only=False), dtype=bool)
    mmsi, _ = mmsi_column(batch.column("mmsi"))
    status, _ = float_column(batch.column("status"))
    with np.errstate(invalid="ignore"):
        status_ok = (status >= 0) & (status <= 15) & (np.floor(status) == status)
    imo_text = pc.utf8_ltrim(pc.utf8_upper(clean_text(batch.column("imo"))), characters="IMO")
    imo, _ = float_column(imo_text)
    length, breadth, draught = _dimensions(batch)
    table = pa.table(
        {
            "timestamp": stamps.cast(pa.timestamp("ms", tz="UTC")),
            "mmsi": pa.array(mmsi, pa.int64()),
            "lat_deg": nan_to_null(null_outside(float_column(batch.column("lat"))[0], -90.0, 90.0)),
            "lon_deg": nan_to_null(
                null_outside(float_column(batch.column("lon"))[0], -180.0, 180.0)
            ),
            "sog_kn": nan_to_null(clean_sog(float_column(batch.column("sog"))[0])),
            "cog_deg": nan_to_null(clean_angle(float_column(batch.column("cog"))[0])),
            "heading_deg": nan_to_null(clean_angle(float_column(batch.column("heading"))[0])),
            "rot_deg_per_min": pa.nulls(batch.num_rows, pa.float64()),
            "nav_status": pa.array(
                np.where(status_ok, status, 0).astype(np.int8), pa.int8(), mask=~status_ok
            ),
            "ship_type": ship_type_text(float_column(batch.column("vesseltype"))[0]),
            "mobile_type": _mobile_type(batch.column("transceiverclass")),
            "length_m": nan_to_null(length),
            "breadth_m": nan_to_null(breadth),
            "draught_m": nan_to_null(draught),
            "name": clean_text(batch.column("vesselname")),
            "callsign": clean_text(batch.column("callsign")),
            "imo": whole_positive(imo),
        },
        schema=CANONICAL_SCHEMA,
    )
    return table, bad_time
