"""A dataset read alone, counted as it is scanned for ``colregs9 stats`` (``count_dataset``):
its positions in a query by MMSI, ship type and dimensions, and the dimension reports of
the vessels found, in memory set by the vessels, not by the rows (``counting.RowCounts``).

A query of everything reads the dataset once: every row, position or static report, is
counted, the positions apart from the rest, and both counts come from those groups. The row
groups' statistics tell which hold only positions and which none (``Positions``), so only
the coordinates of row groups holding both are decoded. Any other query reads it twice:
the positions in the query, pushed down into the scan (``dataset_scan.position_filter``),
then every row of the vessels found, at any time and place, as the reports of a file are
counted. Either way the vessels' dimension reports that an ingest query left out of the
dataset (``Dataset.outside_query_reports``) are added, so that they are those of the files.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import pyarrow as pa
import pyarrow.compute as pc

from ..query import Query
from ..vessels import DIMENSIONS
from .counting import RowCounts, sum_by
from .dataset_scan import (
    Dataset,
    Positions,
    position_filter,
    positions_in_query,
    reports_filter,
    scan_columns,
)
from .dimension_reports import sum_counts
from .schema import CANONICAL_COLUMNS, STATS_POSITION_COLUMNS, canonical_fields

REPORT_COLUMNS: tuple[str, ...] = ("mmsi", *DIMENSIONS)


@dataclass(frozen=True)
class DatasetCounts:
    """What ``count_dataset`` counted, sorted by the keys.

    ``position_counts``: ``STATS_POSITION_COLUMNS`` and ``n_positions``, how many positions
    in the query have them. ``report_counts``: ``REPORT_COLUMNS`` and ``n_reports``, how
    many rows (positions and static reports) of the vessels with a position in the query
    have them, with the dimensions as stored, and how many of their rows outside the ingest
    query did.
    """

    position_counts: pa.Table
    report_counts: pa.Table


def count_dataset(dataset: Dataset, query: Query) -> DatasetCounts:
    """Count the positions of ``dataset`` in ``query`` and the rows of the vessels found."""
    if query.region is None and query.time.unbounded and query.vessels.selects_all:
        return _count_everything(dataset)
    positions = RowCounts(canonical_fields(STATS_POSITION_COLUMNS), "n_positions")
    scanned = scan_columns(STATS_POSITION_COLUMNS, query, ordered=False)
    for table in positions_in_query(dataset, query, scanned, position_filter(query)):
        positions.add(table)
    position_counts = positions.finish()
    vessels = pc.unique(position_counts.column("mmsi")).to_pylist()
    return DatasetCounts(position_counts, count_reports(dataset, vessels))


def count_reports(dataset: Dataset, vessels: Sequence[int]) -> pa.Table:
    """``DatasetCounts.report_counts`` of ``vessels``: every row of theirs, positions and
    static reports, at any time and place, counted by ``REPORT_COLUMNS``, with their
    reports outside the ingest query."""
    reports = RowCounts(canonical_fields(REPORT_COLUMNS), "n_reports")
    if len(vessels):
        for table in dataset.scan(reports_filter(vessels), REPORT_COLUMNS):
            reports.add(table)
    return _with_outside(dataset, reports.finish(), vessels)


def _with_outside(dataset: Dataset, counts: pa.Table, vessels: Sequence[int]) -> pa.Table:
    """``counts`` of ``vessels``' reports with those their ingest queries left out, sorted."""
    outside = dataset.outside_query_reports(vessels)
    if outside.num_rows == 0:
        return counts
    summed = sum_counts([counts, outside])
    return summed.sort_by([(key, "ascending") for key in REPORT_COLUMNS])


def _count_everything(dataset: Dataset) -> DatasetCounts:
    """``count_dataset`` for a query of everything: each row read once."""
    keys = [c for c in CANONICAL_COLUMNS if c in {*STATS_POSITION_COLUMNS, *REPORT_COLUMNS}]
    scanned = [c for c in CANONICAL_COLUMNS if c in {*keys, "lat_deg", "lon_deg"}]
    fields = canonical_fields(keys)
    positions, statics = RowCounts(fields, "n"), RowCounts(fields, "n")
    # The ship types as indices into the Parquet dictionaries: fewer bytes to decode and
    # to compare row to row.
    strings = [name for name in keys if pa.types.is_string(fields.field(name).type)]
    for table in dataset.row_groups(Positions.ALL, keys, strings):
        positions.add(table)
    for table in dataset.row_groups(Positions.NONE, keys, strings):
        statics.add(table)
    for table in dataset.row_groups(Positions.SOME, scanned, strings):
        # A position as the pushdown has it (``position_filter``).
        has_position = pc.and_(
            pc.is_valid(table.column("lat_deg")), pc.is_valid(table.column("lon_deg"))
        )
        positions.add(table.filter(has_position))
        statics.add(table.filter(pc.invert(has_position)))
    positioned, unpositioned = positions.finish(), statics.finish()
    position_counts = _summed(positioned, STATS_POSITION_COLUMNS, "n_positions")
    vessels = pc.unique(positioned.column("mmsi"))
    of_vessels = pc.is_in(unpositioned.column("mmsi"), value_set=vessels)
    groups = pa.concat_tables([positioned, unpositioned.filter(of_vessels)])
    report_counts = _summed(groups, REPORT_COLUMNS, "n_reports")
    outside = _with_outside(dataset, report_counts, vessels.to_pylist())
    return DatasetCounts(position_counts, outside)


def _summed(groups: pa.Table, keys: Sequence[str], name: str) -> pa.Table:
    """The counts ``n`` of ``groups`` summed by ``keys`` into the column ``name``, sorted."""
    summed = sum_by([groups.select([*keys, "n"]).rename_columns([*keys, name])], keys, name)
    return summed.sort_by([(key, "ascending") for key in keys])
