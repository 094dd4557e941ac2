"""Exact duplicates: rows equal in every column to an earlier row, as pandas' ``duplicated``
has it (a null equals a null or a NaN, and -0.0 equals 0.0). The same message received
twice (by two stations, or in two files) is one message. Used when files are read whole
(``load``) and at ingest (``dataset``).
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

# The order in which the duplicates of the positions are sought.
ROW_ORDER = [("mmsi", "ascending"), ("timestamp", "ascending")]


def repeated_rows(table: pa.Table, order: np.ndarray) -> np.ndarray:
    """Which rows of ``table`` taken in ``order`` (sorted by ``ROW_ORDER``) are equal in
    every column to an earlier one, as pandas' ``duplicated`` has it: a null equals a null
    or a NaN, and -0.0 equals 0.0. Such rows share their MMSI and time, so only the rows of
    a (MMSI, time) that repeats are compared, with Arrow's hash grouping."""
    rows = len(order)
    repeated = np.zeros(rows, dtype=bool)
    if rows < 2:
        return repeated
    same_as_next = np.ones(rows - 1, dtype=bool)
    for name, _ in ROW_ORDER:
        column = table.column(name).take(order)
        later, earlier = column.slice(1), column.slice(0, rows - 1)
        same_as_next &= pc.coalesce(
            pc.equal(later, earlier), pc.and_(later.is_null(), earlier.is_null())
        ).to_numpy(zero_copy_only=False)
    candidates = np.zeros(rows, dtype=bool)
    candidates[1:] |= same_as_next
    candidates[:-1] |= same_as_next
    where = np.flatnonzero(candidates)
    if where.size == 0:
        return repeated
    rows_of = table.take(order[where])
    keys = rows_of.column_names
    for index, column in enumerate(rows_of.columns):
        if pa.types.is_floating(column.type):
            # Equal as pandas has it: NaN as null, -0.0 as 0.0 (adding 0.0 turns one into
            # the other).
            no_nan = pc.if_else(pc.is_nan(column), pa.scalar(None, column.type), column)
            rows_of = rows_of.set_column(index, keys[index], pc.add(no_nan, 0.0))
    firsts = (
        rows_of.append_column("row", pa.array(where, pa.int64()))
        .group_by(keys, use_threads=False)
        .aggregate([("row", "min")])
        .column("row_min")
        .to_numpy()
    )
    repeated[where] = True
    repeated[firsts] = False
    return repeated
