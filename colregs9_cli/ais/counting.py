"""Rows counted by the values of some of their columns as they stream by (``RowCounts``),
in memory set by the distinct values, not by the rows: what ``colregs9 stats`` keeps of the
positions (their MMSI, ship type and dimensions) and of the dimension reports.

The rows mostly come in runs of a vessel (a dataset's files are sorted by hour, cell,
vessel and time), so consecutive rows mostly carry the same values. Each table is first cut
into its runs of equal rows: a run starts where any column differs from the row before
(``changes``). There are few runs (37 thousand for the 7 million positions of the
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
# The integers of each fixed width, to compare values by their bits.
_WORDS: dict[int, type[np.signedinteger]] = {64: np.int64, 32: np.int32, 16: np.int16, 8: np.int8}


class RowCounts:
    """How many of the rows added have each distinct combination of the columns of
    ``keys``, in the column ``name``; ``keys`` also gives the types of the result (a
    column added as a dictionary of the key's type is counted by its values)."""

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
                if runs.schema != self._empty.schema:
                    runs = runs.cast(self._empty.schema)
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
        starts[1:] |= changes(column)
        if np.count_nonzero(starts) > rows // 2:
            break
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


def changes(column: pa.Array) -> np.ndarray:
    """Whether each row but the first differs from the row before, as the hash grouping has
    it: a null equals a null; numbers and times compare by their bits, so a NaN equals a
    NaN of the same bits and 0.0 is not -0.0 (two NaNs of other bits differ here, which only
    splits a run the grouping then merges). Compared in NumPy over Arrow's buffers where the
    type allows, which is faster than Arrow's run-end encoding of the column
    (tests/benchmarks/README.md, "the counts read without the coordinates")."""
    rows = len(column)
    if rows < 2:
        return np.zeros(0, dtype=bool)
    if pa.types.is_dictionary(column.type):
        # One value per index, so equal indices are equal values (a value the dictionary
        # holds twice only splits a run).
        return changes(column.indices)
    if pa.types.is_string(column.type):
        differ = pc.not_equal(column[1:], column[:-1]).fill_null(False)
        changed = differ.to_numpy(zero_copy_only=False)
    elif _by_bits(column.type):
        words = _WORDS[column.type.bit_width]
        values = np.frombuffer(column.buffers()[1], words, rows + column.offset)[column.offset :]
        changed = values[1:] != values[:-1]
    else:
        ends = pc.run_end_encode(column, run_end_type=pa.int64()).run_ends.to_numpy()
        changed = np.zeros(rows - 1, dtype=bool)
        changed[ends[:-1] - 1] = True
        return changed
    if column.null_count:
        valid = np.unpackbits(
            np.frombuffer(column.buffers()[0], np.uint8),
            count=rows + column.offset,
            bitorder="little",
        )[column.offset :].view(bool)
        # Values under nulls are anything: a change only where both rows have one.
        changed &= valid[1:]
        changed &= valid[:-1]
        changed |= valid[1:] != valid[:-1]
    return changed


def _by_bits(kind: pa.DataType) -> bool:
    """Values stored as plain integers of a width NumPy has (not bit-packed booleans)."""
    plain = pa.types.is_integer(kind) or pa.types.is_floating(kind) or pa.types.is_temporal(kind)
    return plain and not pa.types.is_interval(kind) and kind.bit_width in _WORDS


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
