"""Rows counted by the values of some of their columns as they stream by (``RowCounts``),
in memory set by the distinct values, not by the rows: what ``colregs9 stats`` keeps of the
positions (their MMSI, ship type and dimensions) and of the dimension reports.

The rows mostly come in runs of a vessel (a dataset's files are sorted by hour, cell,
vessel and time), so consecutive rows mostly carry the same values. Each table is first cut
into its runs of equal rows: the run ends of Arrow's run-end encoding of each column, taken
together, are those of the rows. There are few runs (37 thousand for the 7 million positions of the
national day), and Arrow's hash grouping then sums them. Equal means what the grouping
means: a null equals a null, a NaN a NaN, and 0.0 is not -0.0. Rows in any order are
counted right; where the runs would be more than half the rows, the rows are grouped as
they are."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

# Runs grouped at once: a grouping costs per call, and the runs waiting bound memory.
COUNT_CHUNK_ROWS = 1 << 20
# Merge the grouped chunks once this many have piled up.
PARTS_BEFORE_MERGE = 64


class RowCounts:
    """How many of the rows added have each distinct combination of the columns of
    ``keys``, in the column ``name``; ``keys`` also gives the types of the result when no
    row was added."""

    def __init__(self, keys: pa.Schema, name: str) -> None:
        self.keys, self.name = list(keys.names), name
        self._empty = pa.schema([*keys, pa.field(name, pa.int64())]).empty_table()
        self._runs: list[pa.Table] = []
        self._run_rows = 0
        self._counted: list[pa.Table] = []

    def add(self, table: pa.Table) -> None:
        for batch in table.select(self.keys).to_batches():
            if batch.num_rows:
                runs = row_runs(batch, self.name)
                self._runs.append(runs)
                self._run_rows += runs.num_rows
        if self._run_rows >= COUNT_CHUNK_ROWS:
            self._count_runs()

    def _count_runs(self) -> None:
        if self._runs:
            self._counted.append(sum_by(self._runs, self.keys, self.name))
        self._runs, self._run_rows = [], 0
        if len(self._counted) >= PARTS_BEFORE_MERGE:
            self._counted = [sum_by(self._counted, self.keys, self.name)]

    def finish(self) -> pa.Table:
        """The counts, one row per combination, sorted by the keys."""
        self._count_runs()
        if not self._counted:
            return self._empty
        summed = sum_by(self._counted, self.keys, self.name)
        return summed.sort_by([(key, "ascending") for key in self.keys])


def row_runs(batch: pa.RecordBatch, name: str) -> pa.Table:
    """One row per run of equal consecutive rows of ``batch`` (equal as the hash grouping
    has it), the first of the run, with the run's length in the column ``name``. Where the
    runs would be more than half the rows (rows in time order, say), the rows themselves,
    each a run of one: their runs would cost more than they save."""
    rows = batch.num_rows
    starts = np.zeros(rows, dtype=bool)
    starts[0] = True
    for column in batch.columns:
        ends = pc.run_end_encode(column, run_end_type=pa.int64()).run_ends.to_numpy()
        if ends.size > rows // 2:
            break
        starts[ends[:-1]] = True
    else:
        first = np.flatnonzero(starts)
        if first.size <= rows // 2:
            lengths = np.diff(first, append=rows)
            return pa.Table.from_batches([batch.take(pa.array(first))]).append_column(
                name, pa.array(lengths, pa.int64())
            )
    return pa.Table.from_batches([batch]).append_column(
        name, pa.array(np.ones(rows, dtype=np.int64))
    )


def sum_by(
    tables: Sequence[pa.Table], keys: Sequence[str], name: str, use_threads: bool = True
) -> pa.Table:
    """The rows of ``tables``, one per distinct combination of ``keys`` (nulls included),
    with the sum of their column ``name``: Arrow's hash grouping."""
    summed = (
        pa.concat_tables(tables)
        .group_by(list(keys), use_threads=use_threads)
        .aggregate([(name, "sum")])
    )
    return summed.select([*keys, f"{name}_sum"]).rename_columns([*keys, name])
