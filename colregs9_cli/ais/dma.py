"""The Danish Maritime Authority "aisdk" CSV: the 26-column layout (with A, B, C, D) and the
older 22-column one, read block by block.

Column meanings: ``Timestamp`` is ``dd/mm/yyyy HH:MM:SS`` UTC; ``Navigational status`` is
text (mapped to ITU codes by ``clean.nav_status_code``); ``Ship type`` is DMA's category
text, kept as it is except ``Undefined`` (null); ``Type of mobile`` is the mobile type
(``Class A``, ``Class B``, ``Base Station``, ``AtoN``, ...). ``A``, ``B``, ``C``, ``D`` (the
antenna's distances to the bow, stern, port and starboard) become the canonical
``to_bow_m`` ... ``to_starboard_m`` as ``clean.offset_parts`` cleans them; length is A+B and
breadth C+D where they give them (B and D where A = C = 0), otherwise the ``Length`` and
``Width`` columns. The 22-column layout has no A, B, C, D: its parts are null.

A row without a position that carries static fields (a dimension, draught, ship type,
name, call sign or IMO) is a static report.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from .clean import (
    BoolArray,
    DimensionColumns,
    Dimensions,
    Fields,
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
    nav_status_from_text,
    no_offsets,
    null_outside,
    number_problems,
    offset_parts,
    on_the_written_day,
    plausible,
    positive_or_nan,
    whole_positive,
)
from .layouts import DMA_ABCD, DMA_TIME_FORMAT
from .schema import CANONICAL_SCHEMA

_STATIC_TEXT_COLUMNS = ("ship type", "name", "callsign", "imo")
_DMA_DAY_AND_SECOND = r"^(?P<day>\d{1,2})/\d{1,2}/\d{4}\s+\d{1,2}:\d{1,2}:(?P<second>\d{1,2})$"


def _dimension_columns(has_abcd: bool) -> tuple[str, ...]:
    dimensions = ("width", "length", "draught")
    return (*dimensions, *DMA_ABCD) if has_abcd else dimensions


def _offsets(batch: pa.RecordBatch | pa.Table, has_abcd: bool) -> OffsetParts | None:
    """A, B, C, D cleaned (``clean.offset_parts``); None for the 22-column layout."""
    if not has_abcd:
        return None
    a, b, c, d = (float_column(batch.column(k))[0] for k in DMA_ABCD)
    return offset_parts(a, b, c, d)


def _measure(batch: pa.RecordBatch | pa.Table, offsets: OffsetParts | None) -> Dimensions:
    """Length and breadth from A, B, C, D where they give them (``offset_parts``), else from
    Length and Width (before the plausibility limits, which ``DimensionColumns.clean``
    applies)."""
    width, _ = float_column(batch.column("width"))
    length, _ = float_column(batch.column("length"))
    draught, _ = float_column(batch.column("draught"))
    if offsets is None:
        return positive_or_nan(length), positive_or_nan(width), positive_or_nan(draught)
    return offsets.dimensions(length, width, draught)


def _dimensions(batch: pa.RecordBatch | pa.Table, has_abcd: bool) -> Dimensions:
    return _measure(batch, _offsets(batch, has_abcd))


def dma_fields(batch: pa.RecordBatch, has_abcd: bool) -> Fields:
    mmsi, bad_mmsi = mmsi_column(batch.column("mmsi"))
    lat, bad_lat = float_column(batch.column("latitude"))
    lon, bad_lon = float_column(batch.column("longitude"))
    unparseable, problem = number_problems(bad_mmsi, bad_lat, bad_lon)
    dimensions = batch.select(list(_dimension_columns(has_abcd)))
    return Fields(
        mmsi=mmsi,
        lat_deg=null_outside(lat, -90.0, 90.0),
        lon_deg=null_outside(lon, -180.0, 180.0),
        vessel=_is_vessel(batch.column("type of mobile")),
        dimensions=DimensionColumns(dimensions, lambda table: _dimensions(table, has_abcd)),
        unparseable=unparseable,
        problem=problem,
    )


def _is_vessel(mobile_type: pa.Array) -> BoolArray:
    # Trimming every row costs as much as the test itself; only the rows that fail need it.
    vessel = is_vessel(mobile_type)
    others = np.flatnonzero(~vessel)
    if others.size:
        vessel[others] = is_vessel(pc.utf8_trim_whitespace(mobile_type.take(others)))
    return vessel


def dma_static_text(batch: pa.RecordBatch) -> BoolArray:
    """Rows that carry a ship type, name, call sign or IMO."""
    present = np.zeros(batch.num_rows, dtype=bool)
    for column in _STATIC_TEXT_COLUMNS:
        valid = pc.is_valid(clean_text(batch.column(column)))
        present |= np.asarray(valid.to_numpy(zero_copy_only=False), dtype=bool)
    return present


def dma_canonical(batch: pa.RecordBatch, has_abcd: bool) -> tuple[pa.Table, BoolArray]:
    """The rows in the canonical schema, and which had a timestamp that does not parse."""
    stamps_text = pc.utf8_trim_whitespace(batch.column("timestamp"))
    stamps = pc.strptime(stamps_text, format=DMA_TIME_FORMAT, unit="s", error_is_null=True)
    bad_time = ~on_the_written_day(stamps, stamps_text, _DMA_DAY_AND_SECOND)
    mmsi, _ = mmsi_column(batch.column("mmsi"))
    lat, _ = float_column(batch.column("latitude"))
    lon, _ = float_column(batch.column("longitude"))
    offsets = _offsets(batch, has_abcd)
    measured = _measure(batch, offsets)
    length, breadth, draught = plausible(measured)
    parts = no_offsets(batch.num_rows) if offsets is None else offsets.columns(measured)
    imo, _ = float_column(clean_text(batch.column("imo")))
    table = pa.table(
        {
            "timestamp": stamps.cast(pa.timestamp("ms", tz="UTC")),
            "mmsi": pa.array(mmsi, pa.int64()),
            "lat_deg": nan_to_null(null_outside(lat, -90.0, 90.0)),
            "lon_deg": nan_to_null(null_outside(lon, -180.0, 180.0)),
            "sog_kn": nan_to_null(clean_sog(float_column(batch.column("sog"))[0])),
            "cog_deg": nan_to_null(clean_angle(float_column(batch.column("cog"))[0])),
            "heading_deg": nan_to_null(clean_angle(float_column(batch.column("heading"))[0])),
            "rot_deg_per_min": nan_to_null(clean_rot(float_column(batch.column("rot"))[0])),
            "nav_status": nav_status_from_text(batch.column("navigational status")),
            "ship_type": clean_ship_type(batch.column("ship type")),
            "mobile_type": clean_text(batch.column("type of mobile")),
            "length_m": nan_to_null(length),
            "breadth_m": nan_to_null(breadth),
            **parts,
            "draught_m": nan_to_null(draught),
            "name": clean_text(batch.column("name")),
            "callsign": clean_text(batch.column("callsign")),
            "imo": whole_positive(imo),
        },
        schema=CANONICAL_SCHEMA,
    )
    return table, bad_time
