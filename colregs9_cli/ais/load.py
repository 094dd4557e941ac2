"""The load pipeline: open, detect, read by blocks, clean, filter by the query, account.

Its modules: inputs.py opens the inputs and tells what each is; dispatch.py reads each file
in its layout (layouts.py, detect.py) with that layout's reader (csv_input.py,
table_input.py), which hands the rows, block by block, to the row pipeline (row_pipeline.py:
steps 1-7 below); this module collects the files' rows, drops the duplicates (step 8) and
counts the dimension reports (dimension_reports.py).

Every input row ends in exactly one place of the ``RejectsLedger``, checked in this order
(a row is counted at the first step that stops it, so later problems of the same row are
not looked at):

1. ``unparseable``: a line with the wrong number of fields, or text where the MMSI,
   latitude or longitude must be a number (CSV); reader-level problems (NMEA).
2. ``not_a_vessel``: a mobile type other than ``Class A``/``Class B`` (base station, AtoN,
   SAR aircraft, ...). Checked before the MMSI, because base stations (00MID...) and AtoN
   (99MID...) have MMSIs outside the ship range by design.
3. ``invalid_mmsi``: not 9 digits, or maritime identification digits outside 201-775.
4. No position (lat 91, lon 181, empty, out of range): a row that carries static fields
   (a dimension, draught, ship type, name, call sign or IMO) is a static report and is
   *used* (it feeds the per-vessel dimensions, not the positions); otherwise it is
   ``position_not_available``. NMEA static messages (types 5, 24) are static reports; an
   NMEA position message without a position is ``position_not_available``.
5. Outside the query's region: ``outside_query``. Only rows inside the region have their
   timestamps and text converted, which is what keeps a large file cheap.
6. ``unparseable``: a timestamp that does not parse.
7. Outside the vessel filter or the time window: ``outside_query``.
8. ``duplicate``: a row equal in every canonical column to an earlier kept row (also across
   files). Detected among the kept rows only.
9. Otherwise the row is *used*: a position in ``AisData.positions``.

``dimension_reports`` counts each distinct (length, breadth, draught) combination a vessel
reported, over every row that passed steps 1-3 and carried a dimension, inside or outside
the query, position rows and static reports alike, minus rows rejected in steps 6 and 8.
It is restricted to the vessels that have a position in the query. Rows outside the region
are not checked for a bad timestamp or duplicates, so they count as reports as they are.

Steps 1-3, the region test of step 5 and the dimension counts are done block by block on
the columns every row needs. The rows inside the region, and the rows with neither a
position nor a dimension (step 4 needs their text columns), are set aside and converted in
batches of about ``row_pipeline._SET_ASIDE_BYTES`` (``FileResult.settle``), which does the
rest of steps 4-7. A kept row whose timestamp does not parse was counted with its block; its
report is taken back when it is settled.

Memory: CSV is read in chunks of whole lines (``csv_chunks.CHUNK_BYTES``); a chunk is
dropped once its rows in the query are cut out of it, so memory grows with the kept rows,
not with the file. Only the columns every row needs are converted for every row; the rest
only for the rows set aside (see csv_chunks.py). A chunk whose numeric columns hold text is
parsed again with every column as text, and a chunk with a malformed row again on one
thread, which gives the row's line; the rest of the file is not affected. NMEA is decoded
whole per file (see nmea.py).

Of several NMEA files (a log split by day), the positions of each take the static fields
they still lack from the static messages of all (static_join.py), as ``colregs9 ingest``
does, and their dimension reports change with them; so each file of a load of several hands
its rows to a sink (``_KeptRows``) that keeps its static reports too.

``stream_ais`` reads one file the same way but hands its rows on block by block (a
``row_pipeline.RowSink``), static reports converted too, instead of keeping them:
``colregs9 ingest`` (dataset.py) writes them to a Parquet dataset. ``load_ais`` reads such a
dataset in place of files (``inputs.read_dataset``): its rows were cleaned at ingest, so only
the query is applied, pushed down into the scan (dataset_scan.py), and the dimension reports
of the vessels in the query are counted over the whole dataset, with those of the rows its
ingest query left out (``dataset_count.count_reports``), as over a whole file.

``count_ais`` reads as ``load_ais`` does but gives the positions as counts of their MMSI,
ship type and dimensions, all that the dimension statistics use; a dataset read alone is
counted as it is scanned, so ``colregs9 stats`` over months of AIS holds no position rows.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc

from ..errors import ParameterError
from ..progress import ProgressSink, progress_bar, progress_enabled
from ..query import Query, everything_query
from ..vessels import DIMENSIONS
from .counting import RowCounts
from .csv_read import CsvReading
from .dimension_reports import (
    NO_REPORTS,
    cleaned_reports,
    reports_frame,
    rows_reports,
    subtract_counts,
    sum_counts,
)
from .dispatch import read_source
from .duplicates import ROW_ORDER, repeated_rows
from .inputs import (
    InputFile,
    dataset_alone,
    dataset_inputs,
    dataset_reports,
    no_positions_error,
    open_inputs,
    read_dataset,
)
from .layouts import NMEA, find_layout
from .ledger import RejectReason, RejectsLedger
from .row_pipeline import FileResult, RowSink
from .schema import CANONICAL_COLUMNS, CANONICAL_SCHEMA, STATS_POSITION_COLUMNS, canonical_fields
from .sources import Source
from .static_join import STATIC_COLUMNS, fill_statics

if TYPE_CHECKING:
    from .dataset_scan import Dataset

__all__ = [
    "AisData",
    "CountedAis",
    "StreamedInput",
    "canonical_frame",
    "count_ais",
    "load_ais",
    "stream_ais",
]


@dataclass(frozen=True)
class AisData:
    """Cleaned positions inside the query, with the vessels' dimension reports and the ledger.

    ``positions``: ``CANONICAL_COLUMNS``, sorted by (mmsi, timestamp). ``dimension_reports``:
    ``mmsi, length_m, breadth_m, draught_m, n_reports``, one row per distinct combination a
    vessel reported (see the module docstring). ``rows_in_query == len(positions)``.
    """

    positions: pd.DataFrame
    dimension_reports: pd.DataFrame
    ledger: RejectsLedger
    inputs: tuple[InputFile, ...]
    rows_in_query: int


def load_ais(
    paths: Sequence[Path],
    query: Query | None = None,
    fmt: str | None = None,
    quiet: bool = True,
    started: CsvReading | None = None,
    columns: Sequence[str] | None = None,
    ordered: bool = True,
    needs_time: bool = True,
) -> AisData:
    """Read AIS files (any mix of layouts) through ``query`` into cleaned positions.

    ``fmt`` forces the layout of every file (a name of ``layouts.LAYOUTS``, or a ``--columns``
    map's); by default each file's
    layout is detected from its content. A directory is read as a Parquet dataset made by
    ``colregs9 ingest`` (``inputs.read_dataset``; ``fmt`` does not apply to it). ``started``: the
    first file, already being read (``csv_read.start_reading``). ``columns``: the columns
    of ``positions`` (default: all, ``CANONICAL_COLUMNS``); a dataset read alone decodes
    only these and those the query tests (``inputs.dataset_alone``). ``ordered``: the positions
    sorted by MMSI and time; a caller that needs no order (``stats``) saves the sort of a
    dataset read alone. ``needs_time`` False (``stats``): NMEA messages without a time are
    kept, with a null timestamp (outside any time window), and counted under the time source
    ``none``; otherwise a log in which no message has a time is refused. Raises ``InputFileError``
    for unreadable files, ``NoDataError`` (exit code 3) when no position row is left in the
    query.
    """
    query = query if query is not None else everything_query()
    wanted = list(CANONICAL_COLUMNS if columns is None else columns)
    if not set(wanted) <= set(CANONICAL_COLUMNS):
        raise ParameterError(f"columns {wanted}: give canonical columns ({CANONICAL_COLUMNS})")
    sources = open_inputs(paths, query, fmt)
    read = _load(sources, query, fmt, quiet, started, wanted, ordered, needs_time)
    positions = canonical_frame(read.positions)
    if list(positions.columns) != wanted:
        positions = positions[wanted]
    return AisData(
        positions, read.dimension_reports, read.ledger, read.inputs, read.positions.num_rows
    )


def _load(
    sources: Sequence[Source | Dataset],
    query: Query,
    fmt: str | None,
    quiet: bool,
    started: CsvReading | None,
    wanted: Sequence[str],
    ordered: bool,
    needs_time: bool,
) -> _Read:
    forced = find_layout(fmt) if fmt is not None else None
    ledger = RejectsLedger()
    collected = _Collected(may_repeat=not dataset_alone(sources), ordered=ordered)
    scanned: Sequence[str] = CANONICAL_COLUMNS
    if not collected.may_repeat:
        from .dataset_scan import scan_columns

        scanned = scan_columns(wanted, query, ordered)
    inputs: list[InputFile] = []
    total_bytes = float(sum(s.size_bytes for s in sources))
    several = sum(isinstance(s, Source) for s in sources) > 1
    with progress_bar("Reading AIS", total_bytes, progress_enabled(quiet), in_bytes=True) as bar:
        for index, source in enumerate(sources):
            if not isinstance(source, Source):
                inputs.extend(
                    read_dataset(source, query, scanned, ledger, collected.kept.append, bar)
                )
                collected.datasets.append(source)
                continue
            sink = _KeptRows() if several else None
            first = started if index == 0 else None
            part = read_source(source, forced, query, bar, first, sink, needs_time)
            ledger.merge(part.ledger)
            collected.extend(part, sink)
            inputs.append(InputFile(source.path, part.sha256, part.layout, part.ledger.rows_read))
    collected.join_nmea_statics()
    positions, dimension_reports = collected.finish(ledger, wanted)
    if positions.num_rows == 0:
        raise no_positions_error(inputs, ledger, query)
    return _Read(positions, dimension_reports, ledger, tuple(inputs))


@dataclass(frozen=True)
class _Read:
    """What ``_load`` read: ``AisData`` with the positions still an Arrow table."""

    positions: pa.Table
    dimension_reports: pd.DataFrame
    ledger: RejectsLedger
    inputs: tuple[InputFile, ...]


@dataclass(frozen=True)
class CountedAis:
    """``AisData`` with the positions counted: ``position_counts`` holds
    ``schema.STATS_POSITION_COLUMNS``, one row per distinct (mmsi, ship type, dimensions) of
    the positions, sorted, and ``n_positions``, how many positions have them."""

    position_counts: pd.DataFrame
    dimension_reports: pd.DataFrame
    ledger: RejectsLedger
    inputs: tuple[InputFile, ...]
    rows_in_query: int


def count_ais(
    paths: Sequence[Path],
    query: Query | None = None,
    fmt: str | None = None,
    quiet: bool = True,
    started: CsvReading | None = None,
) -> CountedAis:
    """What ``load_ais(..., needs_time=False)`` reads, with the positions counted by their
    MMSI, ship type and dimensions (``CountedAis``): what the dimension statistics need.

    One dataset read alone holds no duplicates (``inputs.dataset_alone``): it is counted as it is
    scanned (``dataset_count``), in memory set by the vessels, not by the rows. Other inputs
    are loaded whole, as duplicates across them are found among all their rows, and then
    counted.
    """
    query = query if query is not None else everything_query()
    sources = open_inputs(paths, query, fmt)
    if not dataset_alone(sources):
        counts = RowCounts(canonical_fields(STATS_POSITION_COLUMNS), "n_positions")
        read = _load(sources, query, fmt, quiet, started, STATS_POSITION_COLUMNS, False, False)
        counts.add(read.positions)
        return CountedAis(
            counts.finish().to_pandas(),
            read.dimension_reports,
            read.ledger,
            read.inputs,
            read.positions.num_rows,
        )
    dataset = sources[0]
    assert not isinstance(dataset, Source), "dataset_alone: a dataset"
    return _counted_dataset(dataset, query, quiet)


def _counted_dataset(dataset: Dataset, query: Query, quiet: bool) -> CountedAis:
    from .dataset_count import count_dataset

    with progress_bar(
        "Reading AIS", float(dataset.size_bytes), progress_enabled(quiet), in_bytes=True
    ) as bar:
        counted = count_dataset(dataset, query)
        bar.advance(dataset.size_bytes)
    position_counts = counted.position_counts.to_pandas()
    kept = int(position_counts["n_positions"].sum())
    ledger = RejectsLedger()
    inputs = dataset_inputs(dataset, kept, ledger)
    ledger.use(kept)
    if kept == 0:
        raise no_positions_error(inputs, ledger, query)
    vessels = np.unique(position_counts["mmsi"].to_numpy())
    reports = reports_frame(cleaned_reports(counted.report_counts), vessels)
    return CountedAis(position_counts, reports, ledger, inputs, kept)


@dataclass(frozen=True)
class StreamedInput:
    """What ``stream_ais`` read of one file. ``ledger`` counts every row but the position
    rows handed to the sink, which the caller is to use, or reject as duplicates.
    ``dimension_reports``: the file's dimension reports as ``load_ais`` counts them (every
    vessel's, inside the query or not; duplicates not yet taken back), summed
    (``dimension_reports.sum_counts``)."""

    sha256: str
    layout: str
    ledger: RejectsLedger
    dimension_reports: pa.Table


def stream_ais(
    source: Source, sink: RowSink, query: Query, fmt: str | None, bar: ProgressSink
) -> StreamedInput:
    """Read one AIS file as ``load_ais`` does, handing its cleaned rows to ``sink`` block by
    block instead of keeping them: its memory does not grow with the file (but for NMEA,
    which is decoded whole, see nmea.py). Static reports go to the sink too. ``bar``
    advances by the bytes read."""
    layout = find_layout(fmt) if fmt is not None else None
    part = read_source(source, layout, query, bar, None, sink)
    reports = sum_counts([NO_REPORTS, *part.dimension_parts])
    return StreamedInput(part.sha256, part.layout, part.ledger, reports)


class _KeptRows:
    """The ``RowSink`` of each file of a load of several: its positions in the query, and
    its static reports (which a load otherwise only counts), for the join across NMEA
    files (``_Collected.join_nmea_statics``)."""

    def __init__(self) -> None:
        self.kept: list[pa.Table] = []
        self.reports: list[pa.Table] = []

    def positions(self, table: pa.Table) -> None:
        self.kept.append(table)

    def statics(self, table: pa.Table) -> None:
        self.reports.append(table.select(list(STATIC_COLUMNS)))


@dataclass
class _Collected:
    kept: list[pa.Table] = field(default_factory=list)
    dimension_parts: list[pa.Table] = field(default_factory=list)
    # Datasets read: their dimension reports are counted for the vessels in the query only.
    datasets: list[Dataset] = field(default_factory=list)
    # False when the rows cannot hold exact duplicates (``dataset_alone``): none are sought.
    may_repeat: bool = True
    ordered: bool = True
    # The NMEA files read through a ``_KeptRows``: how many, their tables in ``kept`` (by
    # index) and their static reports.
    nmea_files: int = 0
    nmea_kept: list[int] = field(default_factory=list)
    nmea_statics: list[pa.Table] = field(default_factory=list)

    def extend(self, part: FileResult, sink: _KeptRows | None = None) -> None:
        kept = part.kept if sink is None else sink.kept
        if sink is not None and part.layout == NMEA.name:
            self.nmea_files += 1
            self.nmea_kept.extend(range(len(self.kept), len(self.kept) + len(kept)))
            self.nmea_statics.extend(sink.reports)
        self.kept.extend(kept)
        if part.dimension_parts:
            self.dimension_parts.append(sum_counts(part.dimension_parts))

    def join_nmea_statics(self) -> None:
        """Give the positions of each NMEA file the static fields they lack from the static
        reports of all of them (``static_join``), as an ingest of the files does; their
        dimension reports change with them."""
        if self.nmea_files < 2 or not self.nmea_statics:
            return
        statics = pa.concat_tables(self.nmea_statics)
        for index in self.nmea_kept:
            before = self.kept[index]
            self.kept[index] = fill_statics(before, statics)
            changed = [rows_reports(before, -1), rows_reports(self.kept[index])]
            self.dimension_parts.append(sum_counts(changed))

    def finish(self, ledger: RejectsLedger, wanted: Sequence[str]) -> tuple[pa.Table, pd.DataFrame]:
        """Sort, drop exact duplicates (ledger), and count the used rows; the positions with
        the ``wanted`` columns. In Arrow, and without a sorted copy of every column: the
        rows are held for the duplicates, but only the wanted columns are taken."""
        table = pa.concat_tables(self.kept) if self.kept else CANONICAL_SCHEMA.empty_table()
        self.kept = []
        # Text columns as large strings: a take joins a column's chunks, and a string
        # column's offsets end at 2 GiB.
        table = table.cast(_large_text(table.schema))
        rows = np.arange(len(table))
        reordered = self.ordered or self.may_repeat
        if reordered:
            rows = pc.sort_indices(table.select(["mmsi", "timestamp"]), ROW_ORDER).to_numpy()
        duplicate = repeated_rows(table, rows) if self.may_repeat else np.zeros(len(rows), bool)
        vessels = pc.unique(table.column("mmsi")).to_pylist()
        datasets = [dataset_reports(d, vessels) for d in self.datasets if vessels]
        counts = sum_counts([NO_REPORTS, *self.dimension_parts, *datasets])
        if duplicate.any():
            dropped = table.select(["mmsi", "timestamp", *DIMENSIONS]).take(rows[duplicate])
            first = canonical_frame(dropped.slice(0, 1).select(["mmsi", "timestamp"])).iloc[0]
            ledger.reject(
                RejectReason.DUPLICATE,
                len(dropped),
                example=f"MMSI {first['mmsi']} at {first['timestamp']}: repeated row",
            )
            counts = subtract_counts(counts, dropped)
            rows = rows[~duplicate]
        ledger.use(len(rows))
        positions = table.select(list(wanted))
        if reordered:
            positions = positions.take(rows)
        vessels_used = np.unique(table.column("mmsi").take(rows).to_numpy())
        return positions, reports_frame(counts, vessels_used)


def _large_text(schema: pa.Schema) -> pa.Schema:
    return pa.schema(
        [f.with_type(pa.large_string()) if pa.types.is_string(f.type) else f for f in schema]
    )


def canonical_frame(table: pa.Table) -> pd.DataFrame:
    """Canonical columns (those of ``table``, in canonical order): int64 MMSI, nullable
    Int8/Int64 for status and IMO, NaN floats."""
    frame = table.to_pandas()
    if "mmsi" in frame.columns:
        frame["mmsi"] = frame["mmsi"].astype(np.int64)
    if "timestamp" in frame.columns:
        frame["timestamp"] = pd.to_datetime(frame["timestamp"], utc=True)
    for name, dtype in (("nav_status", "Int8"), ("imo", "Int64")):
        if name in frame.columns:
            frame[name] = frame[name].astype(dtype)
    return frame[[c for c in CANONICAL_COLUMNS if c in frame.columns]]
