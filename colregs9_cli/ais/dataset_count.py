"""A dataset read alone, counted as it is scanned for ``colregs9 stats`` (``count_dataset``):
its positions in a query by MMSI, ship type and dimensions, and the dimension reports of
the vessels found, in memory set by the vessels, not by the rows (``counting.RowCounts``).

A query of everything reads the dataset once: every row, position or static report, is
counted with a flag saying whether it has a position, and both counts come from those
groups. Any other query reads it twice: the positions in the query, pushed down into the
scan (``dataset_scan.position_filter``), then every row of the vessels found, at any time
and place, as the reports of a file are counted.

``count_ahead`` runs the count on a thread while ``colregs9 stats`` imports matplotlib and
its analysis modules, which hold the interpreter's lock on one core for about a quarter of a
second; the scan and the run-end encoding run in Arrow, off the lock. So this module imports
none of them. (``pyarrow.dataset`` itself imports pandas.)
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

import pyarrow as pa
import pyarrow.compute as pc

from ..errors import Colregs9Error
from ..query import Query
from .counting import RowCounts, sum_by
from .dataset_scan import (
    Dataset,
    is_dataset,
    position_filter,
    positions_in_query,
    reports_filter,
    scan_columns,
)
from .schema import CANONICAL_COLUMNS, DIMENSIONS, STATS_POSITION_COLUMNS

REPORT_COLUMNS: tuple[str, ...] = ("mmsi", *DIMENSIONS)
# The flag of the rows with a position, in a query of everything.
_HAS_POSITION = "has_position"


@dataclass(frozen=True)
class DatasetCounts:
    """What ``count_dataset`` counted, sorted by the keys.

    ``position_counts``: ``STATS_POSITION_COLUMNS`` and ``n_positions``, how many positions
    in the query have them. ``report_counts``: ``REPORT_COLUMNS`` and ``n_reports``, how
    many rows (positions and static reports) of the vessels with a position in the query
    have them, with the dimensions as stored.
    """

    position_counts: pa.Table
    report_counts: pa.Table


def count_dataset(
    dataset: Dataset, query: Query, stop: threading.Event | None = None
) -> DatasetCounts:
    """Count the positions of ``dataset`` in ``query`` and the rows of the vessels found.
    Once ``stop`` is set, the scans end early and the counts are partial."""
    if query.region is None and query.time.unbounded and query.vessels.selects_all:
        return _count_everything(dataset, stop)
    positions = RowCounts(STATS_POSITION_COLUMNS, "n_positions")
    scanned = scan_columns(STATS_POSITION_COLUMNS, query, ordered=False)
    for table in _until(stop, positions_in_query(dataset, query, scanned, position_filter(query))):
        positions.add(table)
    position_counts = positions.finish()
    vessels = pc.unique(position_counts.column("mmsi")).to_pylist()
    return DatasetCounts(position_counts, count_reports(dataset, vessels, stop))


def count_reports(
    dataset: Dataset, vessels: Sequence[int], stop: threading.Event | None = None
) -> pa.Table:
    """``DatasetCounts.report_counts`` of ``vessels``: every row of theirs, positions and
    static reports, at any time and place, counted by ``REPORT_COLUMNS``."""
    reports = RowCounts(REPORT_COLUMNS, "n_reports")
    if len(vessels):
        for table in _until(stop, dataset.scan(reports_filter(vessels), REPORT_COLUMNS)):
            reports.add(table)
    return reports.finish()


def _count_everything(dataset: Dataset, stop: threading.Event | None) -> DatasetCounts:
    """``count_dataset`` for a query of everything, in one scan."""
    keys = [c for c in CANONICAL_COLUMNS if c in {*STATS_POSITION_COLUMNS, *REPORT_COLUMNS}]
    scanned = [c for c in CANONICAL_COLUMNS if c in {*keys, "lat_deg", "lon_deg"}]
    rows = RowCounts([*keys, _HAS_POSITION], "n")
    for table in _until(stop, dataset.scan(pc.scalar(True), scanned)):
        # A position as the pushdown has it (``position_filter``).
        has_position = pc.and_(
            pc.is_valid(table.column("lat_deg")), pc.is_valid(table.column("lon_deg"))
        )
        rows.add(table.select(keys).append_column(_HAS_POSITION, has_position))
    groups = rows.finish()
    positioned = groups.filter(groups.column(_HAS_POSITION))
    position_counts = _summed(positioned, STATS_POSITION_COLUMNS, "n_positions")
    of_vessels = pc.is_in(groups.column("mmsi"), value_set=pc.unique(positioned.column("mmsi")))
    report_counts = _summed(groups.filter(of_vessels), REPORT_COLUMNS, "n_reports")
    return DatasetCounts(position_counts, report_counts)


def _summed(groups: pa.Table, keys: Sequence[str], name: str) -> pa.Table:
    """The counts ``n`` of ``groups`` summed by ``keys`` into the column ``name``, sorted."""
    summed = sum_by([groups.select([*keys, "n"]).rename_columns([*keys, name])], keys, name)
    return summed.sort_by([(key, "ascending") for key in keys])


def _until(stop: threading.Event | None, tables: Iterator[pa.Table]) -> Iterator[pa.Table]:
    for table in tables:
        if stop is not None and stop.is_set():
            return
        yield table


class CountingAhead:
    """``count_dataset`` of one dataset on a thread of its own; a context manager that
    stops the count, if it still runs, and waits for its thread."""

    def __init__(self, dataset: Dataset, query: Query) -> None:
        self.dataset, self.query = dataset, query
        self._stop = threading.Event()
        self._outcome: DatasetCounts | BaseException | None = None
        self._thread = threading.Thread(target=self._count, name="colregs9-count-ahead")
        self._thread.start()

    def _count(self) -> None:
        try:
            self._outcome = count_dataset(self.dataset, self.query, self._stop)
        except BaseException as error:  # raised again on the caller's thread
            self._outcome = error

    def result(self) -> DatasetCounts:
        """The counts, once counted; the count's error raised here."""
        self._thread.join()
        if isinstance(self._outcome, BaseException):
            raise self._outcome
        assert self._outcome is not None, "a joined count has an outcome"
        return self._outcome

    def __enter__(self) -> CountingAhead:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        self._stop.set()
        self._thread.join()


@contextlib.contextmanager
def count_ahead(paths: Sequence[Path], query: Query) -> Iterator[CountingAhead | None]:
    """Start counting the input of ``colregs9 stats`` if it is one dataset that opens and
    holds no duplicates (``Dataset.duplicate_free``); else None, and ``load.count_ais``
    reads the inputs as usual (and reports what is wrong with them)."""
    ahead = None
    if len(paths) == 1 and is_dataset(Path(paths[0])):
        with contextlib.suppress(Colregs9Error):
            dataset = Dataset.open(Path(paths[0]))
            if dataset.duplicate_free:
                ahead = CountingAhead(dataset, query)
    if ahead is None:
        yield None
        return
    with ahead:
        yield ahead
