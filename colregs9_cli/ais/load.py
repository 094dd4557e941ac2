"""The load pipeline: open, detect, read by blocks, clean, filter by the query, account.

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
batches of about ``_SET_ASIDE_BYTES`` (``_FileResult.settle``), which does the rest of steps
4-7. A kept row whose timestamp does not parse was counted with its block; its report is
taken back when it is settled.

Memory: CSV is read in chunks of whole lines (``csv_chunks.CHUNK_BYTES``); a chunk is
dropped once its rows in the query are cut out of it, so memory grows with the kept rows,
not with the file. Only the columns every row needs are converted for every row; the rest
only for the rows set aside (see csv_chunks.py). A chunk whose numeric columns hold text is
parsed again with every column as text, and a chunk with a malformed row again on one
thread, which gives the row's line; the rest of the file is not affected. NMEA is decoded
whole per file (see nmea.py).

``stream_ais`` reads one file the same way but hands its rows on block by block (a
``RowSink``), static reports converted too, instead of keeping them: ``colregs9 ingest``
(dataset.py) writes them to a Parquet dataset. ``load_ais`` reads such a dataset in place of
files (``_read_dataset``): its rows were cleaned at ingest, so only the query is applied,
pushed down into the scan (dataset_scan.py), and the dimension reports of the vessels in the
query are counted over the whole dataset, as over a whole file.

``count_ais`` reads as ``load_ais`` does but gives the positions as counts of their MMSI,
ship type and dimensions, all that the dimension statistics use; a dataset read alone is
counted as it is scanned, so ``colregs9 stats`` over months of AIS holds no position rows.
"""

from __future__ import annotations

import io
import re
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, TypeAlias

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc

from ..errors import InputFileError, NoDataError, ParameterError
from ..progress import ProgressSink, progress_bar, progress_enabled
from ..query import Query, everything_query
from . import dma, mapped
from .batch import AisBatch
from .clean import (
    DimensionColumns,
    Dimensions,
    Fields,
    any_dimension,
    clean_text,
    implausible,
    implausible_text,
    is_vessel,
    null_outside,
    plausible,
    to_numpy_float,
    valid_mmsi,
)
from .column_map import MAP_PREFIX
from .columns import file_map
from .counting import PARTS_BEFORE_MERGE, RowCounts, sum_by
from .csv_chunks import CsvChunk, CutRows, NotUtf8, ParsedRows, parse_cut_rows
from .csv_read import CsvReading, missing_columns
from .detect import LAYOUTS, csv_header, detect_layout, is_csv_layout, known_layout
from .duplicates import ROW_ORDER, repeated_rows
from .ledger import DropReason, RejectReason, RejectsLedger
from .query_rows import rows_in_window_and_filter
from .schema import (
    CANONICAL_COLUMNS,
    CANONICAL_SCHEMA,
    DIMENSIONS,
    STATS_POSITION_COLUMNS,
    canonical_fields,
)
from .sources import (
    Source,
    decompression_error,
    inspect_source,
    locate_non_utf8,
    open_data,
    read_head,
    sha256_file,
)
from .time_sources import IngestParams

if TYPE_CHECKING:
    from .dataset_scan import Dataset

__all__ = [
    "LAYOUTS",
    "AisData",
    "CountedAis",
    "InputFile",
    "RowSink",
    "StreamedInput",
    "canonical_frame",
    "count_ais",
    "load_ais",
    "no_positions_error",
    "stream_ais",
]

PARQUET_BATCH_ROWS = 256 * 1024
DIMENSION_REPORT_COLUMNS = ("mmsi", *DIMENSIONS, "n_reports")
_EXAMPLE_CHARS = 160
_DECIMAL = re.compile(r"[-+]?\d+(\.\d*)?")
# Convert the rows set aside once they hold this many bytes (see ``_FileResult.set_aside``).
_SET_ASIDE_BYTES = 8 * 1024 * 1024


@dataclass(frozen=True)
class InputFile:
    """One input of a run; ``dataset``: the dataset it was read from (``colregs9 ingest``),
    where ``path``, ``sha256`` and ``rows_read`` are those of the file ingested, and
    ``ingest_query`` the query it was ingested through (as its manifest records it): the
    dataset holds only the rows that query kept."""

    path: Path
    sha256: str
    layout: str
    rows_read: int
    dataset: Path | None = None
    ingest_query: Mapping[str, Any] | None = field(default=None, compare=False)

    @classmethod
    def of_dataset(cls, dataset: Dataset) -> tuple[InputFile, ...]:
        """The inputs ingested into ``dataset``, as its manifest lists them."""
        return tuple(
            cls(
                Path(item.path),
                item.sha256,
                item.layout,
                item.rows_read,
                dataset.directory,
                item.entry.get("query"),
            )
            for item in dataset.inputs
        )


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

    ``fmt`` forces the layout of every file (one of ``LAYOUTS``); by default each file's
    layout is detected from its content. A directory is read as a Parquet dataset made by
    ``colregs9 ingest`` (``_read_dataset``; ``fmt`` does not apply to it). ``started``: the
    first file, already being read (``csv_read.start_reading``). ``columns``: the columns
    of ``positions`` (default: all, ``CANONICAL_COLUMNS``); a dataset read alone decodes
    only these and those the query tests (``_dataset_alone``). ``ordered``: the positions
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
    sources = _open_inputs(paths, query, fmt)
    read = _load(sources, query, fmt, quiet, started, wanted, ordered, needs_time)
    positions = canonical_frame(read.positions)
    if list(positions.columns) != wanted:
        positions = positions[wanted]
    return AisData(
        positions, read.dimension_reports, read.ledger, read.inputs, read.positions.num_rows
    )


def _open_inputs(paths: Sequence[Path], query: Query, fmt: str | None) -> list[Source | Dataset]:
    ingest_params(query)
    check_format(fmt)
    if not paths:
        raise InputFileError("no AIS input files given; name at least one file")
    return [_open_input(Path(p)) for p in paths]


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
    ledger = RejectsLedger()
    collected = _Collected(may_repeat=not _dataset_alone(sources), ordered=ordered)
    scanned: Sequence[str] = CANONICAL_COLUMNS
    if not collected.may_repeat:
        from .dataset_scan import scan_columns

        scanned = scan_columns(wanted, query, ordered)
    inputs: list[InputFile] = []
    total_bytes = float(sum(s.size_bytes for s in sources))
    with progress_bar("Reading AIS", total_bytes, progress_enabled(quiet), in_bytes=True) as bar:
        for index, source in enumerate(sources):
            if not isinstance(source, Source):
                inputs.extend(
                    _read_dataset(source, query, scanned, ledger, collected.kept.append, bar)
                )
                collected.datasets.append(source)
                continue
            part = _read_source(
                source, fmt, query, bar, started if index == 0 else None, needs_time=needs_time
            )
            ledger.merge(part.ledger)
            collected.extend(part)
            inputs.append(InputFile(source.path, part.sha256, part.layout, part.ledger.rows_read))
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

    One dataset read alone holds no duplicates (``_dataset_alone``): it is counted as it is
    scanned (``dataset_count``), in memory set by the vessels, not by the rows. Other inputs
    are loaded whole, as duplicates across them are found among all their rows, and then
    counted.
    """
    query = query if query is not None else everything_query()
    sources = _open_inputs(paths, query, fmt)
    if not _dataset_alone(sources):
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
    assert not isinstance(dataset, Source), "_dataset_alone: a dataset"
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
    inputs = _dataset_inputs(dataset, kept, ledger)
    ledger.use(kept)
    if kept == 0:
        raise no_positions_error(inputs, ledger, query)
    vessels = np.unique(position_counts["mmsi"].to_numpy())
    reports = _reports_frame(_cleaned_reports(counted.report_counts), vessels)
    return CountedAis(position_counts, reports, ledger, inputs, kept)


@dataclass(frozen=True)
class StreamedInput:
    """What ``stream_ais`` read of one file. ``ledger`` counts every row but the position
    rows handed to the sink, which the caller is to use, or reject as duplicates."""

    sha256: str
    layout: str
    ledger: RejectsLedger


def stream_ais(
    source: Source, sink: RowSink, query: Query, fmt: str | None, bar: ProgressSink
) -> StreamedInput:
    """Read one AIS file as ``load_ais`` does, handing its cleaned rows to ``sink`` block by
    block instead of keeping them: its memory does not grow with the file (but for NMEA,
    which is decoded whole, see nmea.py). Static reports go to the sink too. ``bar``
    advances by the bytes read."""
    part = _read_source(source, fmt, query, bar, None, sink)
    return StreamedInput(part.sha256, part.layout, part.ledger)


def _dataset_alone(sources: Sequence[Source | Dataset]) -> bool:
    """One dataset whose inputs share no partition: ingest dropped the duplicates of each,
    so its rows hold none (and need not be read whole to find them)."""
    return len(sources) == 1 and not isinstance(sources[0], Source) and sources[0].duplicate_free


def _open_input(path: Path) -> Source | Dataset:
    if not path.is_dir():
        return inspect_source(path)
    from .dataset_scan import Dataset  # pyarrow.dataset: only for runs that read one

    return Dataset.open(path)


def _read_dataset(
    dataset: Dataset,
    query: Query,
    columns: Sequence[str],
    ledger: RejectsLedger,
    keep: Callable[[pa.Table], None],
    bar: ProgressSink,
) -> tuple[InputFile, ...]:
    """Hand a dataset's positions in the query to ``keep``, with the query pushed down into
    the scan (``dataset_scan.position_filter``); the ledger as ``_dataset_inputs`` has it."""
    from .dataset_scan import position_filter, positions_in_query

    kept = 0
    for table in positions_in_query(dataset, query, columns, position_filter(query)):
        keep(table)
        kept += table.num_rows
    bar.advance(dataset.size_bytes)
    return _dataset_inputs(dataset, kept, ledger)


def _dataset_inputs(dataset: Dataset, kept: int, ledger: RejectsLedger) -> tuple[InputFile, ...]:
    """The inputs of ``dataset``, whose ledger goes into ``ledger``: the inputs' own (what
    reading the files themselves counted), with the dataset's rows, all used at ingest,
    shared out again. The static reports are used, as in a file; the ``kept`` positions of
    the query are used (less duplicates across inputs, found in ``_Collected.finish``); the
    others, skipped by the pushdown or by the query's tests, are outside the query."""
    part = dataset.ingest_ledger()
    part.rows_used = dataset.static_rows
    part.outside_query(dataset.rows - dataset.static_rows - kept)
    ledger.merge(part)
    return InputFile.of_dataset(dataset)


def _dataset_reports(dataset: Dataset, vessels: Sequence[int]) -> pa.Table:
    """The dimension reports of ``vessels`` over the whole dataset, cleaned."""
    from .dataset_count import count_reports

    return _cleaned_reports(count_reports(dataset, vessels))


def _cleaned_reports(groups: pa.Table) -> pa.Table:
    """The dimension reports counted as stored (``mmsi``, the dimensions, ``n_reports``),
    cleaned as a file's are (``_count_reports``): rows that report no plausible dimension
    go, and raw values that clean alike (implausible ones become null) are summed."""
    length_m, breadth_m, draught_m = plausible(_canonical_dimensions(groups))
    reported = any_dimension(length_m, breadth_m, draught_m)
    return _sum_counts(
        [
            _report_rows(
                groups.column("mmsi").to_numpy()[reported],
                length_m[reported],
                breadth_m[reported],
                draught_m[reported],
                groups.column("n_reports").to_numpy()[reported],
            )
        ]
    )


def no_positions_error(
    inputs: Sequence[InputFile], ledger: RejectsLedger, query: Query
) -> InputFileError | NoDataError:
    """The error for a read that left no position: the inputs hold none (exit 2), or
    the query selects none of them (exit 3)."""
    if ledger.rows_outside_query == 0:
        return InputFileError(_no_ais_message(inputs, ledger))
    return NoDataError(_no_data_message(query, ledger))


def _no_ais_message(inputs: Sequence[InputFile], ledger: RejectsLedger) -> str:
    names = ", ".join(str(i.dataset or i.path) for i in inputs)
    return (
        f"{names}: no valid AIS position report in {ledger.rows_read} AIS rows read, "
        f"{_used_and_rejected(ledger)}{_first_reject(ledger)}; check that the input holds AIS "
        "messages (NMEA !AIVDM/!AIVDO with valid checksums, or a known CSV or Parquet layout, "
        "see --format, or --columns for any other CSV) with valid MMSIs and times"
    )


def _no_data_message(query: Query, ledger: RejectsLedger) -> str:
    where = f"query '{query.name}'" + (f" ({query.source})" if query.source else "")
    return (
        f"the {where} selects no vessel positions: {ledger.rows_read} rows read, "
        f"{ledger.rows_outside_query} outside the query, {_used_and_rejected(ledger)}; "
        "check the region, time window and vessel filter against the data"
    )


def _used_and_rejected(ledger: RejectsLedger) -> str:
    """What became of the rows that were neither positions used nor outside the query."""
    rejects = ", ".join(f"{k} {v}" for k, v in sorted(ledger.rejects.items())) or "none"
    used = f"{ledger.rows_used} static reports used, " if ledger.rows_used else ""
    return f"{used}{ledger.rejected_total} rejected ({rejects})"


# The longest reject example quoted in an error line.
_EXAMPLE_CHARS = 300


def _first_reject(ledger: RejectsLedger) -> str:
    """The first example of the most common reject: what the user most likely has to fix."""
    if not ledger.rejects:
        return ""
    reason = max(sorted(ledger.rejects), key=lambda r: ledger.rejects[r])
    examples = ledger.examples.get(reason)
    if not examples:
        return ""
    # One line: an example may quote a field that held line breaks.
    example = examples[0].replace("\r", "\\r").replace("\n", "\\n")
    if len(example) > _EXAMPLE_CHARS:
        example = example[:_EXAMPLE_CHARS] + "…"
    return f"; the first {reason} row: {example}"


# -- one file ---------------------------------------------------------------------------------


Example = Callable[[int, str, str], str]
# Rows of a block set aside: cut out of a CSV chunk, or taken from a canonical table.
_Part: TypeAlias = CutRows | pa.Table


# Tells, of rows without a position, which carry static text (a static report).
_StaticText = Callable[[pa.Table], np.ndarray]


@dataclass(frozen=True)
class _Converted:
    """Rows set aside with all their columns, and how to quote one of them in the ledger."""

    table: pa.Table
    example: Example


@dataclass(frozen=True)
class _Conversion:
    """How a reader turns the rows it set aside into canonical rows.

    ``convert`` gives the parts' rows with all columns (in one or more tables);
    ``canonical`` turns those into the canonical schema and tells the rows whose timestamp
    does not parse; ``static_text`` None: a row without a position is never a static
    report (NMEA position messages).
    """

    convert: Callable[[list[_Part]], list[_Converted]]
    canonical: Callable[[pa.Table], tuple[pa.Table, np.ndarray]]
    static_text: _StaticText | None


class RowSink(Protocol):
    """Where ``stream_ais`` hands the cleaned rows, block by block, in the canonical schema."""

    def positions(self, table: pa.Table) -> None:
        """Position rows in the query, not yet checked for duplicates."""

    def statics(self, table: pa.Table) -> None:
        """Static reports: no position (null lat/lon), a null timestamp where theirs does
        not parse."""


@dataclass
class _FileResult:
    """What one file contributed; merged into the run only when the file was read whole.

    The rows inside the region and the rows with neither a position nor a dimension are
    set aside block by block and converted in batches (``settle``): their other columns are
    wanted for few rows, and converting them a few rows at a time costs more than the
    conversion itself, most of all while the next CSV chunk is parsed on every core.

    With a ``sink`` (``stream_ais``) the position rows go to it instead of ``kept``, and the
    static reports are converted too and go to it (a load only counts them).
    """

    query: Query
    name: str
    conversion: _Conversion
    ledger: RejectsLedger = field(default_factory=RejectsLedger)
    kept: list[pa.Table] = field(default_factory=list)
    dimension_parts: list[pa.Table] = field(default_factory=list)
    layout: str = ""
    sha256: str = ""
    sink: RowSink | None = None
    _kept_aside: list[_Part] = field(default_factory=list)
    _static_aside: list[_Part] = field(default_factory=list)
    _reports_aside: list[_Part] = field(default_factory=list)
    _aside_bytes: int = 0

    def set_aside(
        self, kept: _Part | None = None, static: _Part | None = None, report: _Part | None = None
    ) -> None:
        """Set aside rows in the region (``kept``), rows to be told static reports or rows
        without a position (``static``) and static reports already counted (``report``,
        only with a sink); settle once enough have gathered."""
        for part, parts in (
            (kept, self._kept_aside),
            (static, self._static_aside),
            (report, self._reports_aside),
        ):
            if part is not None:
                parts.append(part)
                self._aside_bytes += part.size_bytes if isinstance(part, CutRows) else part.nbytes
        if self._aside_bytes >= _SET_ASIDE_BYTES:
            self.settle()

    def settle(self) -> None:
        """Convert the rows set aside and account for them (steps 4-7 of the module doc)."""
        kept, static, reports = self._kept_aside, self._static_aside, self._reports_aside
        self._kept_aside, self._static_aside, self._reports_aside = [], [], []
        self._aside_bytes = 0
        for part in self.conversion.convert(static) if static else ():
            self._settle_static(part)
        for part in self.conversion.convert(reports) if reports else ():
            self._emit_statics(part.table)
        for part in self.conversion.convert(kept) if kept else ():
            self._settle_kept(part)

    def _emit_statics(self, rows: pa.Table) -> None:
        """Static reports, converted rows with all their columns, to the sink."""
        if self.sink is not None and rows.num_rows:
            table, bad_time = self.conversion.canonical(rows)
            self.sink.statics(_static_rows(table, bad_time | _time_out_of_range(table)))

    def _settle_static(self, part: _Converted) -> None:
        """Rows with neither a position nor a dimension: a static report if they carry
        static text, else rejected."""
        static_text = self.conversion.static_text
        assert static_text is not None, "rows are set aside as static only with static text"
        present = static_text(part.table)
        self.ledger.use(int(present.sum()))
        if present.any():
            self._emit_statics(part.table.filter(pa.array(present)))
        absent = np.flatnonzero(~present)
        reason = RejectReason.NO_POSITION
        if absent.size:
            example = (
                part.example(int(absent[0]), "latitude", "no position: latitude")
                if self.ledger.wants_example(reason)
                else None
            )
            self.ledger.reject(reason, int(absent.size), example=example)

    def _settle_kept(self, part: _Converted) -> None:
        """Rows in the region: canonical, then checked for their timestamp, the time window
        and the vessel filter."""
        table, bad_time = self.conversion.canonical(part.table)
        bad_time = bad_time | _time_out_of_range(table)
        if bad_time.any():
            first = int(np.flatnonzero(bad_time)[0])
            self.ledger.reject(
                RejectReason.UNPARSEABLE,
                int(bad_time.sum()),
                example=part.example(
                    first,
                    "time",
                    f"timestamp does not parse or lies outside {AIS_TIME_MIN:%Y}–"
                    f"{AIS_TIME_END.year - 1}:",
                ),
            )
            self._uncount_dimensions(table.filter(pa.array(bad_time)))
            table = table.filter(pa.array(~bad_time))
        selected = rows_in_window_and_filter(table, self.query)
        self.ledger.outside_query(int((~selected).sum()))
        if self.sink is not None:
            self.sink.positions(table.filter(pa.array(selected)))
        else:
            self.kept.append(table.filter(pa.array(selected)))

    def add_dimensions(
        self,
        mmsi: np.ndarray,
        dimensions: DimensionColumns,
        rows: np.ndarray,
        example: Example | None = None,
    ) -> None:
        """Count the dimensions reported by ``rows`` (a mask); rows without any are left out.
        Rows with a dimension dropped as implausible are counted in the ledger
        (``implausible_dimension``), quoted by ``example(row, "MMSI", why)``."""
        if not rows.any():
            return
        counts, implausible = _count_reports(mmsi, dimensions, rows)
        self._add_counts(counts)
        if implausible:
            reason = DropReason.IMPLAUSIBLE_DIMENSION
            sample = None
            if example is not None and self.ledger.wants_example(reason):
                sample = _implausible_example(dimensions, rows, example)
            self.ledger.drop(reason, implausible, example=sample)

    def _uncount_dimensions(self, rows: pa.Table) -> None:
        """Take back the dimensions counted for canonical ``rows`` that were rejected after
        their block was counted."""
        length_m, breadth_m, draught_m = plausible(_canonical_dimensions(rows))
        reported = any_dimension(length_m, breadth_m, draught_m)
        if reported.any():
            mmsi = rows.column("mmsi").to_numpy()[reported]
            self._add_counts(
                _report_rows(
                    mmsi,
                    length_m[reported],
                    breadth_m[reported],
                    draught_m[reported],
                    times=np.full(len(mmsi), -1),
                )
            )

    def _add_counts(self, counts: pa.Table) -> None:
        self.dimension_parts.append(counts)
        if len(self.dimension_parts) >= PARTS_BEFORE_MERGE:
            self.dimension_parts = [_sum_counts(self.dimension_parts)]


def _count_reports(
    mmsi: np.ndarray, dimensions: DimensionColumns, rows: np.ndarray
) -> tuple[pa.Table, int]:
    """The reports (``_report_rows``) of the cleaned dimensions of ``rows``, without the
    rows that report none, and how many of ``rows`` have a dimension dropped as implausible.
    The rows are grouped as read first, and only the groups are cleaned; groups that clean
    alike are summed later."""
    key = "mmsi"
    while key in dimensions.table.column_names:
        key = f"_{key}"
    keyed = dimensions.table.append_column(key, pa.array(np.where(rows, mmsi, -1), pa.int64()))
    groups = keyed.group_by(keyed.column_names, use_threads=False).aggregate([([], "count_all")])
    groups = groups.filter(pc.not_equal(groups.column(key), -1))
    measured = dimensions.measure(groups)
    length_m, breadth_m, draught_m = plausible(measured)
    reported = any_dimension(length_m, breadth_m, draught_m)
    times = groups.column("count_all").to_numpy()
    implausible_count = int(times[implausible(measured)].sum())
    counts = _report_rows(
        groups.column(key).to_numpy()[reported],
        length_m[reported],
        breadth_m[reported],
        draught_m[reported],
        times[reported],
    )
    return counts, implausible_count


def _implausible_example(dimensions: DimensionColumns, rows: np.ndarray, example: Example) -> str:
    """The first of ``rows`` (a mask) with an implausible dimension, quoted with its values."""
    candidates = np.flatnonzero(rows)
    first = int(candidates[np.argmax(dimensions.implausible_rows(candidates))])
    length_m, breadth_m, draught_m = dimensions.measured_rows(np.array([first]))
    what = implausible_text(float(length_m[0]), float(breadth_m[0]), float(draught_m[0]))
    return example(first, "MMSI", f"implausible dimension dropped ({what}): MMSI")


def _report_rows(
    mmsi: np.ndarray,
    length_m: np.ndarray,
    breadth_m: np.ndarray,
    draught_m: np.ndarray,
    times: np.ndarray | None = None,
) -> pa.Table:
    """Reports as rows of ``DIMENSION_REPORT_COLUMNS``, each counting ``times`` (default
    once); NaN dimensions become null. A combination may take several rows until the rows
    are summed (``_sum_counts``)."""
    return pa.table(
        {
            "mmsi": pa.array(mmsi, pa.int64()),
            "length_m": pa.array(length_m, pa.float64(), from_pandas=True),
            "breadth_m": pa.array(breadth_m, pa.float64(), from_pandas=True),
            "draught_m": pa.array(draught_m, pa.float64(), from_pandas=True),
            "n_reports": pa.array(np.ones(len(mmsi)) if times is None else times, pa.int64()),
        }
    )


def _sum_counts(parts: Sequence[pa.Table]) -> pa.Table:
    """Counts of (mmsi, dimensions) from several parts combined into one per combination.

    Arrow's hash grouping, about twice as fast as pandas'; on the calling thread, as the CSV
    reader keeps pyarrow's thread pool busy.
    """
    return sum_by(parts, ["mmsi", *DIMENSIONS], "n_reports", use_threads=False)


def _read_source(
    source: Source,
    fmt: str | None,
    query: Query,
    bar: ProgressSink,
    started: CsvReading | None,
    sink: RowSink | None = None,
    needs_time: bool = True,
) -> _FileResult:
    if started is not None:
        started.attach_progress(bar)
        return _read_csv(source, started.layout, query, started, sink)
    head = read_head(source)
    layout = fmt if fmt is not None else detect_layout(source, head)
    if layout == "parquet":
        return _read_parquet(source, query, bar, sink)
    if layout == "nmea":
        return _read_nmea(source, query, bar, sink, needs_time)
    if not is_csv_layout(layout):
        check_format(layout)
    header = csv_header(source, head, layout)
    missing = missing_columns(layout, header)
    if missing:
        if layout.startswith(MAP_PREFIX):
            raise InputFileError(
                f"{source.name}: the map {layout[len(MAP_PREFIX) :]} names the column "
                f"{missing[0]!r}, which the header does not have; check the map's [columns]"
            )
        raise InputFileError(
            f"{source.name}: the {layout} layout needs the column {missing[0]!r}, which the "
            f"header does not have; check the file or the --format given"
        )
    return _read_csv(source, layout, query, CsvReading(source, layout, header, bar), sink)


def check_format(fmt: str | None) -> None:
    """``ParameterError`` unless ``fmt`` is None, a layout or a column map (``columns:``)."""
    if fmt is not None and not known_layout(fmt):
        raise ParameterError(f"--format {fmt!r} is not a layout; use one of {', '.join(LAYOUTS)}")


@dataclass(frozen=True)
class _CsvLayout:
    fields: Callable[[pa.RecordBatch], Fields]
    static_text: _StaticText
    canonical: Callable[[pa.RecordBatch], tuple[pa.Table, np.ndarray]]
    example_columns: dict[str, str]  # what -> the column to quote in reject examples
    # Rows of AIS message types that are neither positions, statics nor non-vessels.
    unsupported: Callable[[pa.RecordBatch], np.ndarray | None] = lambda _: None


def _csv_layout(layout: str, header: tuple[str, ...]) -> _CsvLayout:
    if layout in ("dma26", "dma22"):
        abcd = layout == "dma26"
        return _CsvLayout(
            fields=lambda b: dma.dma_fields(b, abcd),
            static_text=dma.dma_static_text,
            canonical=lambda b: dma.dma_canonical(b, abcd),
            example_columns={
                "MMSI": "mmsi",
                "latitude": "latitude",
                "longitude": "longitude",
                "mobile": "type of mobile",
                "time": "timestamp",
            },
        )
    map_ = file_map(layout, header)
    mobile = next(
        (map_.column(t) for t in ("message_type", "mobile_type") if map_.has(t)),
        map_.column("mmsi"),
    )
    return _CsvLayout(
        fields=lambda b: mapped.mapped_fields(map_, b),
        static_text=lambda b: mapped.mapped_static_text(map_, b),
        canonical=lambda b: mapped.mapped_canonical(map_, b),
        example_columns={
            "MMSI": map_.column("mmsi"),
            "latitude": map_.column("lat_deg"),
            "longitude": map_.column("lon_deg"),
            "mobile": mobile,
            "message": map_.column("message_type") if map_.has("message_type") else mobile,
            "time": map_.column("timestamp"),
        },
        unsupported=lambda b: mapped.unsupported_messages(map_, b),
    )


def _read_csv(
    source: Source, layout: str, query: Query, reading: CsvReading, sink: RowSink | None
) -> _FileResult:
    spec = _csv_layout(layout, reading.header.columns)
    conversion = _Conversion(_csv_conversion(source.name, spec), spec.canonical, spec.static_text)
    result = _FileResult(query, source.name, conversion, layout=layout, sink=sink)
    with reading:
        try:
            for chunk in reading.chunks():
                _csv_chunk(result, spec, chunk)
            result.settle()
        except NotUtf8:
            raise _non_utf8_error(source) from None
        except pa.ArrowInvalid as exc:
            raise InputFileError(
                f"{source.name}: cannot read the CSV ({exc}); check the file"
            ) from None
        result.sha256 = reading.finish()
    if result.ledger.rows_read == 0:
        raise InputFileError(
            f"{source.name}: no data rows after the header; give a file with AIS rows"
        )
    return result


def _non_utf8_error(source: Source) -> InputFileError:
    located = locate_non_utf8(source)
    if located is None:
        return InputFileError(f"{source.name}: the file is not UTF-8; convert it to UTF-8")
    line, offset, byte = located
    return InputFileError(
        f"{source.name}:{line}: byte 0x{byte:02x} at offset {offset} is not UTF-8; "
        "convert the file to UTF-8 (e.g. iconv -f latin1 -t utf-8)"
    )


def _csv_chunk(result: _FileResult, spec: _CsvLayout, chunk: CsvChunk) -> None:
    for bad in chunk.invalid_rows:
        # A stray quote makes one malformed record of the lines up to the next quote: each
        # of those lines is a row read and rejected, not lost inside the record.
        lines = len(bad.text.splitlines()) or 1
        spans = f" (a quote left open: {lines} lines)" if lines > 1 else ""
        result.ledger.read(lines)
        result.ledger.reject(
            RejectReason.UNPARSEABLE,
            lines,
            example=f"{result.name}:{bad.line}: expected {bad.expected_columns} fields, found "
            f"{bad.actual_columns}{spans}: {bad.text[:_EXAMPLE_CHARS]}",
        )
    rows = chunk.rows
    result.ledger.read(rows.num_rows)

    def example(row: int, what: str, why: str) -> str:
        column = spec.example_columns[what]
        if column in rows.column_names:
            value = rows.column(column)[row].as_py()
        else:
            value = chunk.take(np.array([row]), [column]).column(column)[0].as_py()
        return _line_example(result.name, chunk.line_of(row), why, value)

    _classify(result, spec.fields(rows), chunk.cut, example, spec.unsupported(rows))


def _line_example(name: str, line: int, why: str, value: object) -> str:
    # A chunk read as text gives its numbers as text: quote them as numbers all the same.
    if isinstance(value, str) and _DECIMAL.fullmatch(value):
        value = float(value)
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    return f"{name}:{line}: {why} {value!r}"


def _csv_conversion(name: str, spec: _CsvLayout) -> Callable[[list[_Part]], list[_Converted]]:
    def convert(parts: list[_Part]) -> list[_Converted]:
        cuts = [part for part in parts if isinstance(part, CutRows)]
        return [
            _Converted(rows.table, _cut_example(name, spec, rows)) for rows in parse_cut_rows(cuts)
        ]

    return convert


def _cut_example(name: str, spec: _CsvLayout, rows: ParsedRows) -> Example:
    def example(row: int, what: str, why: str) -> str:
        value = rows.table.column(spec.example_columns[what])[row].as_py()
        return _line_example(name, int(rows.lines[row]), why, value)

    return example


def _classify(
    result: _FileResult,
    fields: Fields,
    cut: Callable[[np.ndarray], _Part],
    example: Example,
    unsupported: np.ndarray | None = None,
) -> None:
    """Account every row of one block (see the module docstring) and set aside the rows
    whose other columns decide the rest (``_FileResult.settle``).

    ``cut(rows)`` gives those rows of the block, to be converted later. ``unsupported``:
    rows of AIS message types that are neither positions nor statics (a CSV of decoded
    messages), rejected as such after the unparseable rows.
    """
    ledger = result.ledger
    query = result.query
    left = np.ones(len(fields), dtype=bool)

    def reject(mask: np.ndarray, reason: RejectReason, what: str, why: str) -> None:
        rows = np.flatnonzero(mask)
        if rows.size:
            wanted = ledger.wants_example(reason)
            sample = example(int(rows[0]), what, why) if wanted else None
            ledger.reject(reason, int(rows.size), example=sample)

    unparseable = fields.unparseable
    if unparseable.any():
        first = int(np.flatnonzero(unparseable)[0])
        what = fields.problem[first]
        reject(unparseable, RejectReason.UNPARSEABLE, what, f"{what} is not a number:")
    left &= ~unparseable
    if unsupported is not None:
        unsupported = left & unsupported
        reject(unsupported, RejectReason.UNSUPPORTED_MESSAGE, "message", "message type")
        left &= ~unsupported
    not_vessel = left & ~fields.vessel
    reject(not_vessel, RejectReason.NOT_A_VESSEL, "mobile", "mobile type")
    left &= ~not_vessel
    bad_mmsi = left & ~valid_mmsi(fields.mmsi)
    reject(bad_mmsi, RejectReason.INVALID_MMSI, "MMSI", "MMSI")
    left &= ~bad_mmsi

    # Every row past these checks counts: one without a position or a dimension adds
    # nothing, and a kept row whose timestamp does not parse is taken back when settled.
    result.add_dimensions(fields.mmsi, fields.dimensions, left, example)
    no_position = left & (np.isnan(fields.lat_deg) | np.isnan(fields.lon_deg))
    if no_position.any():
        rows = np.flatnonzero(no_position)
        dimensioned = any_dimension(*fields.dimensions.of_rows(rows))
        ledger.use(int(dimensioned.sum()))  # static reports with a dimension
        if result.sink is not None and dimensioned.any():
            result.set_aside(report=cut(rows[dimensioned]))
        undecided = np.zeros(len(fields), dtype=bool)
        undecided[rows[~dimensioned]] = True
        if result.conversion.static_text is None:
            reject(undecided, RejectReason.NO_POSITION, "latitude", "no position: latitude")
        elif undecided.any():
            result.set_aside(static=cut(np.flatnonzero(undecided)))
    left &= ~no_position

    if query.region is not None and left.any():
        rows = np.flatnonzero(left)
        inside = query.region.contains(fields.lat_deg[rows], fields.lon_deg[rows])
        ledger.outside_query(int((~inside).sum()))
        left[rows[~inside]] = False
    if left.any():
        result.set_aside(kept=cut(np.flatnonzero(left)))


# AIS began in the late 1990s; a time outside these years is a corrupt field, and years past
# 2262 would not even fit pandas' nanosecond times later on.
AIS_TIME_MIN = datetime(1980, 1, 1, tzinfo=UTC)
AIS_TIME_END = datetime(2100, 1, 1, tzinfo=UTC)


def _time_out_of_range(table: pa.Table) -> np.ndarray:
    """Rows whose timestamp lies outside [AIS_TIME_MIN, AIS_TIME_END)."""
    milliseconds = table.column("timestamp").cast(pa.int64()).to_numpy(zero_copy_only=False)
    low = round(AIS_TIME_MIN.timestamp() * 1000)
    high = round(AIS_TIME_END.timestamp() * 1000)
    with np.errstate(invalid="ignore"):
        return np.asarray((milliseconds < low) | (milliseconds >= high), dtype=bool)


# -- canonical tables (NMEA, Parquet) ---------------------------------------------------------


def _canonical_dimensions(table: pa.Table) -> Dimensions:
    """The canonical columns as numbers, before the plausibility limits."""
    length_m, breadth_m, draught_m = (to_numpy_float(table.column(name)) for name in DIMENSIONS)
    return length_m, breadth_m, draught_m


def _canonical_fields(table: pa.Table) -> Fields:
    mmsi = pc.fill_null(table.column("mmsi"), -1).to_numpy()
    n = table.num_rows
    return Fields(
        mmsi=np.asarray(mmsi, dtype=np.int64),
        lat_deg=null_outside(to_numpy_float(table.column("lat_deg")), -90.0, 90.0),
        lon_deg=null_outside(to_numpy_float(table.column("lon_deg")), -180.0, 180.0),
        vessel=is_vessel(table.column("mobile_type").combine_chunks()),
        dimensions=DimensionColumns(table.select(list(DIMENSIONS)), _canonical_dimensions),
        unparseable=np.zeros(n, dtype=bool),
        problem=[],
    )


def _taker(table: pa.Table) -> Callable[[np.ndarray], _Part]:
    return lambda rows: table.take(pa.array(rows, pa.int64()))


def _table_conversion(name: str, static_text: _StaticText | None) -> _Conversion:
    def convert(parts: list[_Part]) -> list[_Converted]:
        table = pa.concat_tables(part for part in parts if isinstance(part, pa.Table))
        return [_Converted(table, _table_example(name, table))]

    return _Conversion(convert, _canonical_identity, static_text)


def _canonical_identity(table: pa.Table) -> tuple[pa.Table, np.ndarray]:
    bad_time = table.column("timestamp").is_null().to_numpy(zero_copy_only=False)
    return table, np.asarray(bad_time, dtype=bool)


def _canonical_static_text(table: pa.Table) -> np.ndarray:
    present = np.zeros(table.num_rows, dtype=bool)
    for column in ("ship_type", "name", "callsign", "imo"):
        present |= np.asarray(table.column(column).is_valid().to_numpy(zero_copy_only=False))
    return present


def _table_example(name: str, table: pa.Table, lines: np.ndarray | None = None) -> Example:
    """Examples of rejected rows of ``table``, naming their ``lines`` where they are known."""

    def example(row: int, what: str, why: str) -> str:
        column = {"MMSI": "mmsi", "mobile": "mobile_type", "time": "timestamp"}.get(what, "lat_deg")
        value = table.column(column)[row].as_py()
        mmsi = table.column("mmsi")[row].as_py()
        where = name if lines is None else f"{name}:{int(lines[row])}"
        if what == "MMSI":
            return f"{where}: {why} {mmsi}"
        return f"{where}: MMSI {mmsi}: {why} {value!r}"

    return example


def ingest_params(query: Query) -> IngestParams:
    """The query's ``[ingest]`` table, checked (``ParameterError`` naming the file)."""
    from ..config import dataclass_from_table

    where = f"{query.source if query.source is not None else 'query'} [ingest]"
    return dataclass_from_table(IngestParams, dict(query.tables.get("ingest", {})), where)


def _read_nmea(
    source: Source, query: Query, bar: ProgressSink, sink: RowSink | None, needs_time: bool
) -> _FileResult:
    """An NMEA log; with ``needs_time`` False its messages without a time are kept (a null
    timestamp is then no time, not a bad one), else a log where none has a time is refused."""
    from .nmea import NmeaCounts, read_nmea

    ingest = ingest_params(query)
    conversion = _table_conversion(source.name, None)
    if not needs_time:
        conversion = _Conversion(conversion.convert, _timeless_identity, None)
    result = _FileResult(query, source.name, conversion, layout="nmea", sink=sink)
    counts = NmeaCounts()
    with open_data(source, bar) as opened:
        text = io.TextIOWrapper(opened.stream, encoding="utf-8", errors="replace", newline="")
        try:
            batches = list(
                read_nmea(
                    _lines(text),
                    source.name,
                    result.ledger,
                    ingest.nmea_time_sources,
                    keep_timeless=not needs_time,
                    counts=counts,
                )
            )
        except (EOFError, OSError) as exc:
            raise decompression_error(source, exc) from None
        result.sha256 = opened.finish()
    if needs_time and counts.timeless and not result.ledger.time_sources:
        raise _no_time_error(source, counts.timeless, ingest.nmea_time_sources)
    for batch in batches:
        _nmea_batch(result, batch)
    result.settle()
    return result


def _no_time_error(source: Source, messages: int, in_use: Sequence[str]) -> InputFileError:
    looked = {
        "tag_block": "tag blocks with c:",
        "pghp": "$PGHP lines",
        "arrival": "trailing unix times",
    }
    sources = ", ".join(looked.get(str(s), str(s)) for s in in_use)
    return InputFileError(
        f"{source.name}: no line has a time ({messages} AIS messages; looked for {sources}); "
        "replay and ingest place positions in time and need one: give a log written with "
        "receive times (tag blocks or trailing unix times), or use colregs9 stats, which "
        "reads a log without times"
    )


def _timeless_identity(table: pa.Table) -> tuple[pa.Table, np.ndarray]:
    """NMEA rows kept without a time: a null timestamp is no time, not a bad one."""
    return table, np.zeros(table.num_rows, dtype=bool)


def _lines(text: io.TextIOWrapper) -> Iterator[str]:
    for line in text:
        yield line.rstrip("\r\n")


def _nmea_batch(result: _FileResult, batch: AisBatch) -> None:
    positions = batch.positions
    _classify(
        result,
        _canonical_fields(positions),
        _taker(positions),
        _table_example(result.name, positions, batch.position_lines),
    )
    statics = batch.statics
    if statics.num_rows == 0:
        return
    mmsi = np.asarray(pc.fill_null(statics.column("mmsi"), -1).to_numpy(), dtype=np.int64)
    bad = ~valid_mmsi(mmsi)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        lines = batch.static_lines
        where = result.name if lines is None else f"{result.name}:{int(lines[first])}"
        result.ledger.reject(
            RejectReason.INVALID_MMSI,
            int(bad.sum()),
            example=f"{where}: static report: MMSI {int(mmsi[first])}",
        )
    result.ledger.use(int((~bad).sum()))
    dimensions = DimensionColumns(statics.select(list(DIMENSIONS)), _canonical_dimensions)
    result.add_dimensions(mmsi, dimensions, ~bad)  # implausible ones were counted in nmea.py
    if result.sink is not None and not bad.all():
        result.sink.statics(_statics_canonical(statics.filter(pa.array(~bad))))


def _statics_canonical(statics: pa.Table) -> pa.Table:
    """NMEA static reports (``STATIC_SCHEMA``) in the canonical schema."""
    n = statics.num_rows
    columns = [
        statics.column(f.name) if f.name in statics.column_names else pa.nulls(n, f.type)
        for f in CANONICAL_SCHEMA
    ]
    table = pa.Table.from_arrays(columns, schema=CANONICAL_SCHEMA)
    return _static_rows(table, _time_out_of_range(table))


def _static_rows(table: pa.Table, bad_time: np.ndarray) -> pa.Table:
    """Canonical rows as static reports: no position (a static report may carry half of
    one), and a null timestamp where it does not parse or lies outside the AIS years."""
    stamps: pa.Array | pa.ChunkedArray = table.column("timestamp")
    if bad_time.any():
        stamps = pc.if_else(pa.array(bad_time), pa.scalar(None, stamps.type), stamps)
    nowhere = pa.nulls(table.num_rows, pa.float64())
    for name, column in (("timestamp", stamps), ("lat_deg", nowhere), ("lon_deg", nowhere)):
        table = table.set_column(table.schema.get_field_index(name), name, column)
    return table


def _read_parquet(
    source: Source, query: Query, bar: ProgressSink, sink: RowSink | None
) -> _FileResult:
    import pyarrow.parquet as pq  # only here: 20 ms to import, for every CSV run otherwise

    if source.compression != "none":
        raise InputFileError(
            f"{source.name}: a compressed Parquet file; give the .parquet file itself"
        )
    conversion = _table_conversion(source.name, _canonical_static_text)
    result = _FileResult(query, source.name, conversion, layout="parquet", sink=sink)
    try:
        parquet = pq.ParquetFile(source.path)
    except (pa.ArrowException, OSError) as exc:
        raise InputFileError(f"{source.name}: not a readable Parquet file ({exc})") from None
    names = parquet.schema_arrow.names
    missing = [c for c in CANONICAL_COLUMNS if c not in names]
    if missing:
        raise InputFileError(
            f"{source.name}: the Parquet file lacks the canonical column {missing[0]!r}; "
            f"it needs {', '.join(CANONICAL_COLUMNS)}"
        )
    try:
        for record_batch in parquet.iter_batches(
            batch_size=PARQUET_BATCH_ROWS, columns=list(CANONICAL_COLUMNS)
        ):
            table = _to_canonical(source, pa.Table.from_batches([record_batch]))
            result.ledger.read(table.num_rows)
            _classify(
                result, _canonical_fields(table), _taker(table), _table_example(result.name, table)
            )
        result.settle()
    except (pa.ArrowException, OSError) as exc:
        raise InputFileError(f"{source.name}: cannot read the Parquet file ({exc})") from None
    bar.advance(source.size_bytes)
    result.sha256 = sha256_file(source.path)
    return result


def _to_canonical(source: Source, table: pa.Table) -> pa.Table:
    columns = []
    for target in CANONICAL_SCHEMA:
        column = table.column(target.name)
        if pa.types.is_timestamp(column.type) and column.type.tz is None:
            column = column.cast(pa.timestamp(column.type.unit, tz="UTC"))
        if target.name in ("ship_type", "mobile_type", "name", "callsign"):
            column = clean_text(column.cast(pa.string()))
        try:
            columns.append(column.cast(target.type, safe=target.name != "timestamp"))
        except (pa.ArrowInvalid, pa.ArrowNotImplementedError) as exc:
            raise InputFileError(
                f"{source.name}: column {target.name!r} of type {column.type} cannot be read as "
                f"{target.type} ({exc})"
            ) from None
    return pa.Table.from_arrays(columns, schema=CANONICAL_SCHEMA)


# -- the run ----------------------------------------------------------------------------------


@dataclass
class _Collected:
    kept: list[pa.Table] = field(default_factory=list)
    dimension_parts: list[pa.Table] = field(default_factory=list)
    # Datasets read: their dimension reports are counted for the vessels in the query only.
    datasets: list[Dataset] = field(default_factory=list)
    # False when the rows cannot hold exact duplicates (``_dataset_alone``): none are sought.
    may_repeat: bool = True
    ordered: bool = True

    def extend(self, part: _FileResult) -> None:
        self.kept.extend(part.kept)
        if part.dimension_parts:
            self.dimension_parts.append(_sum_counts(part.dimension_parts))

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
        empty = np.empty(0)
        vessels = pc.unique(table.column("mmsi")).to_pylist()
        datasets = [_dataset_reports(d, vessels) for d in self.datasets if vessels]
        counts = _sum_counts(
            [_report_rows(empty, empty, empty, empty), *self.dimension_parts, *datasets]
        )
        if duplicate.any():
            dropped = table.select(["mmsi", "timestamp", *DIMENSIONS]).take(rows[duplicate])
            first = canonical_frame(dropped.slice(0, 1).select(["mmsi", "timestamp"])).iloc[0]
            ledger.reject(
                RejectReason.DUPLICATE,
                len(dropped),
                example=f"MMSI {first['mmsi']} at {first['timestamp']}: repeated row",
            )
            counts = _subtract_counts(counts, dropped)
            rows = rows[~duplicate]
        ledger.use(len(rows))
        positions = table.select(list(wanted))
        if reordered:
            positions = positions.take(rows)
        vessels_used = np.unique(table.column("mmsi").take(rows).to_numpy())
        return positions, _reports_frame(counts, vessels_used)


def _large_text(schema: pa.Schema) -> pa.Schema:
    return pa.schema(
        [f.with_type(pa.large_string()) if pa.types.is_string(f.type) else f for f in schema]
    )


def _reports_frame(counts: pa.Table, vessels: np.ndarray) -> pd.DataFrame:
    """``AisData.dimension_reports``: the counted reports of ``vessels``, sorted."""
    frame = counts.to_pandas()
    reports = frame[frame["mmsi"].isin(vessels) & (frame["n_reports"] > 0)]
    reports = reports.sort_values(["mmsi", *DIMENSIONS], ignore_index=True)
    reports["n_reports"] = reports["n_reports"].astype(np.int64)
    return reports[list(DIMENSION_REPORT_COLUMNS)]


def _subtract_counts(counts: pa.Table, dropped: pa.Table) -> pa.Table:
    """``counts`` less the dimension reports of the ``dropped`` rows."""
    length_m, breadth_m, draught_m = (to_numpy_float(dropped.column(d)) for d in DIMENSIONS)
    reported = any_dimension(length_m, breadth_m, draught_m)
    if not reported.any():
        return counts
    removed = _report_rows(
        dropped.column("mmsi").to_numpy()[reported],
        length_m[reported],
        breadth_m[reported],
        draught_m[reported],
        times=np.full(int(reported.sum()), -1),
    )
    return _sum_counts([counts, removed])


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
