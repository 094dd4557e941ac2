"""Reading windows of a Parquet dataset made by ``colregs9 ingest`` back: its positions in a
query and a time window, without exact duplicates (``read_dataset_window``), and the time
range of its positions (``dataset_time_range``). Used by ``colregs9 replay`` slab by slab;
``colregs9_cli.jobs.ingest`` gives them to Python users.
"""

from __future__ import annotations

from collections.abc import Sequence
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.dataset as ds

from ..errors import NoDataError
from ..query import Query
from .dataset_scan import Dataset, position_filter, positions_in_query, scan_columns, utc_ms
from .duplicates import ROW_ORDER, repeated_rows
from .schema import CANONICAL_COLUMNS, CANONICAL_SCHEMA


def drop_duplicates(table: pa.Table) -> tuple[pa.Table, pa.Table]:
    """``table`` without rows equal in every column to an earlier one, and the rows dropped.

    Equal rows share their (mmsi, timestamp), and ``table`` must have those rows next to
    each other (as ingest's sort and the windows' do): ``duplicates.repeated_rows`` compares
    only those.
    """
    dropped = repeated_rows(table, np.arange(table.num_rows))
    return table.filter(pa.array(~dropped)), table.filter(pa.array(dropped))


def read_dataset_window(
    dataset_dir: Path | Dataset,
    query: Query,
    start: datetime,
    end: datetime,
    columns: Sequence[str] | None = None,
) -> pa.Table:
    """The positions of the dataset with ``start <= timestamp < end`` inside ``query``
    (region, polygon too, time window and vessel filter), sorted by (mmsi, timestamp),
    exact duplicates dropped; an empty table if there are none.

    ``columns``: the columns of the table (default: all, ``CANONICAL_SCHEMA``). The query,
    the window and the columns are pushed down into the scan (partitions and row groups
    skipped, other columns not decoded; all are read where two inputs share a date, to find
    duplicates). ``dataset_dir`` may be a ``Dataset`` already opened, which saves checking
    its files again for every window. ``start`` and ``end`` are timezone-aware.
    """
    return read_window_counted(dataset_dir, query, start, end, columns)[0]


def read_window_counted(
    dataset_dir: Path | Dataset,
    query: Query,
    start: datetime,
    end: datetime,
    columns: Sequence[str] | None = None,
    mmsis: tuple[int, int] | None = None,
) -> tuple[pa.Table, pa.Table]:
    """``read_dataset_window``, and the rows in the window and the query that were
    dropped as exact duplicates (of rows of another input). ``mmsis``: only the vessels
    with an MMSI in this range (inclusive); a duplicate has its original's MMSI, so the
    vessels may be read in parts."""
    dataset = dataset_dir if isinstance(dataset_dir, Dataset) else Dataset.open(dataset_dir)
    wanted = list(CANONICAL_COLUMNS if columns is None else columns)
    read = scan_columns(wanted, query) if dataset.duplicate_free else CANONICAL_COLUMNS
    expression = position_filter(query, utc_ms(start), utc_ms(end))
    if mmsis is not None:
        expression &= (ds.field("mmsi") >= mmsis[0]) & (ds.field("mmsi") <= mmsis[1])
    tables = list(positions_in_query(dataset, query, read, expression))
    schema = pa.schema([CANONICAL_SCHEMA.field(name) for name in read])
    table = pa.concat_tables(tables) if tables else schema.empty_table()
    order = pc.sort_indices(table, sort_keys=ROW_ORDER)
    table = table.take(order)
    dropped = table.slice(0, 0)
    if not dataset.duplicate_free:
        table, dropped = drop_duplicates(table)
    return table.select(wanted), dropped


def dataset_time_range(dataset_dir: Path | Dataset) -> tuple[datetime, datetime]:
    """The first and last timestamps (UTC) of the dataset's positions, from the Parquet
    row-group statistics alone (no data read). ``NoDataError`` if it holds no position."""
    dataset = dataset_dir if isinstance(dataset_dir, Dataset) else Dataset.open(dataset_dir)
    found = dataset.time_range()
    if found is None:
        raise NoDataError(f"{dataset.directory}: the dataset holds no positions")
    first, last = found
    return first.astimezone(UTC), last.astimezone(UTC)
