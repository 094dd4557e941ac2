"""Which rows of a canonical Arrow table a query selects: its region (the polygon too), time
window and vessel filter. Used on every read, of files and of datasets alike (after the
pushdown, which is exact only for the box, the window and part of the vessel filter).
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa

from ..query import Query, ms_at_or_after
from .clean import to_numpy_float


def rows_in_query(table: pa.Table, query: Query) -> np.ndarray:
    """The position rows of canonical ``table`` inside the query: its region (polygon too),
    time window and vessel filter."""
    inside = rows_in_window_and_filter(table, query)
    if query.region is not None:
        inside &= query.region.contains(
            to_numpy_float(table.column("lat_deg")), to_numpy_float(table.column("lon_deg"))
        )
    return inside


def rows_in_window_and_filter(table: pa.Table, query: Query) -> np.ndarray:
    """Rows inside the time window and the vessel filter."""
    keep = np.ones(table.num_rows, dtype=bool)
    window = query.time
    if not window.unbounded:
        # the schema's unit: milliseconds since the epoch; a row without a time (NaN: an
        # NMEA message read by stats) is outside any window
        stamps = table.column("timestamp").cast(pa.int64())
        milliseconds = (
            to_numpy_float(stamps.cast(pa.float64())) if stamps.null_count else stamps.to_numpy()
        )
        if window.start is not None:
            keep &= milliseconds >= ms_at_or_after(window.start)
        if window.end is not None:
            keep &= milliseconds < ms_at_or_after(window.end)
    if not query.vessels.selects_all:
        keep &= query.vessels.selects(
            table.column("mmsi").to_numpy(),
            table.column("mobile_type").to_numpy(zero_copy_only=False),
            table.column("ship_type").to_numpy(zero_copy_only=False),
            table.column("length_m").to_numpy(zero_copy_only=False),
        )
    return keep
