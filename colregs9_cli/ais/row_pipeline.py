"""One file's rows through the checks of load.py's docstring, block by block.

A reader (csv_input.py, table_input.py; ``dispatch.READERS``) is given a ``FileRead`` and
hands each block of the file to ``classify``, which accounts every row (steps 1-3, the region
test of step 5 and the dimension counts) and sets aside the rows whose other columns decide
the rest; ``FileResult.settle`` converts those in batches and does steps 4-7. What one file
contributed is a ``FileResult``: the rows kept (or handed to a ``RowSink``), the dimension
reports and the ledger.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from datetime import UTC, datetime
from typing import Protocol, TypeAlias

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from ..progress import ProgressSink
from ..query import Query
from .clean import (
    DimensionColumns,
    Fields,
    any_dimension,
    implausible_text,
    plausible,
    valid_mmsi,
)
from .counting import PARTS_BEFORE_MERGE
from .csv_chunks import CutRows
from .csv_read import CsvReading
from .dimension_reports import canonical_dimensions, count_reports, report_rows, sum_counts
from .layouts import Layout
from .ledger import DropReason, RejectReason, RejectsLedger
from .query_rows import rows_in_window_and_filter
from .sources import Source

# Convert the rows set aside once they hold this many bytes (see ``FileResult.set_aside``).
_SET_ASIDE_BYTES = 8 * 1024 * 1024

Example = Callable[[int, str, str], str]
# Rows of a block set aside: cut out of a CSV chunk, or taken from a canonical table.
Part: TypeAlias = CutRows | pa.Table
# Tells, of rows without a position, which carry static text (a static report).
StaticText = Callable[[pa.Table], np.ndarray]


@dataclass(frozen=True)
class Converted:
    """Rows set aside with all their columns, and how to quote one of them in the ledger."""

    table: pa.Table
    example: Example


@dataclass(frozen=True)
class Conversion:
    """How a reader turns the rows it set aside into canonical rows.

    ``convert`` gives the parts' rows with all columns (in one or more tables);
    ``canonical`` turns those into the canonical schema and tells the rows whose timestamp
    does not parse; ``static_text`` None: a row without a position is never a static
    report (NMEA position messages).
    """

    convert: Callable[[list[Part]], list[Converted]]
    canonical: Callable[[pa.Table], tuple[pa.Table, np.ndarray]]
    static_text: StaticText | None


class RowSink(Protocol):
    """Where ``stream_ais`` hands the cleaned rows, block by block, in the canonical schema."""

    def positions(self, table: pa.Table) -> None:
        """Position rows in the query, not yet checked for duplicates."""

    def statics(self, table: pa.Table) -> None:
        """Static reports: no position (null lat/lon), a null timestamp where theirs does
        not parse."""


@dataclass(frozen=True)
class FileRead:
    """One file for its layout's reader (``dispatch.READERS``): the rows in ``query`` go to
    ``sink`` if there is one (``stream_ais``), else they are kept; ``bar`` advances by the bytes
    read. ``head``: the first bytes of its data; ``started``: the file already being read
    (``csv_read.start_reading``). ``needs_time`` False: NMEA messages without a time are
    kept (see ``load.load_ais``).
    """

    source: Source
    layout: Layout
    query: Query
    bar: ProgressSink
    sink: RowSink | None = None
    needs_time: bool = True
    head: bytes = b""
    started: CsvReading | None = None


@dataclass
class FileResult:
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
    conversion: Conversion
    ledger: RejectsLedger = field(default_factory=RejectsLedger)
    kept: list[pa.Table] = field(default_factory=list)
    dimension_parts: list[pa.Table] = field(default_factory=list)
    layout: str = ""
    sha256: str = ""
    sink: RowSink | None = None
    _kept_aside: list[Part] = field(default_factory=list)
    _static_aside: list[Part] = field(default_factory=list)
    _reports_aside: list[Part] = field(default_factory=list)
    _aside_bytes: int = 0

    def set_aside(
        self, kept: Part | None = None, static: Part | None = None, report: Part | None = None
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
        """Convert the rows set aside and account for them (steps 4-7 of load.py's docstring)."""
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
            self.sink.statics(static_rows(table, bad_time | time_out_of_range(table)))

    def _settle_static(self, part: Converted) -> None:
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

    def _settle_kept(self, part: Converted) -> None:
        """Rows in the region: canonical, then checked for their timestamp, the time window
        and the vessel filter."""
        table, bad_time = self.conversion.canonical(part.table)
        bad_time = bad_time | time_out_of_range(table)
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
        counts, implausible = count_reports(mmsi, dimensions, rows)
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
        length_m, breadth_m, draught_m = plausible(canonical_dimensions(rows))
        reported = any_dimension(length_m, breadth_m, draught_m)
        if reported.any():
            mmsi = rows.column("mmsi").to_numpy()[reported]
            self._add_counts(
                report_rows(
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
            self.dimension_parts = [sum_counts(self.dimension_parts)]


def _implausible_example(dimensions: DimensionColumns, rows: np.ndarray, example: Example) -> str:
    """The first of ``rows`` (a mask) with an implausible dimension, quoted with its values."""
    candidates = np.flatnonzero(rows)
    first = int(candidates[np.argmax(dimensions.implausible_rows(candidates))])
    length_m, breadth_m, draught_m = dimensions.measured_rows(np.array([first]))
    what = implausible_text(float(length_m[0]), float(breadth_m[0]), float(draught_m[0]))
    return example(first, "MMSI", f"implausible dimension dropped ({what}): MMSI")


def classify(
    result: FileResult,
    fields: Fields,
    cut: Callable[[np.ndarray], Part],
    example: Example,
    unsupported: np.ndarray | None = None,
) -> None:
    """Account every row of one block (load.py's docstring) and set aside the rows
    whose other columns decide the rest (``FileResult.settle``).

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


def time_out_of_range(table: pa.Table) -> np.ndarray:
    """Rows whose timestamp lies outside [AIS_TIME_MIN, AIS_TIME_END)."""
    milliseconds = table.column("timestamp").cast(pa.int64()).to_numpy(zero_copy_only=False)
    low = round(AIS_TIME_MIN.timestamp() * 1000)
    high = round(AIS_TIME_END.timestamp() * 1000)
    with np.errstate(invalid="ignore"):
        return np.asarray((milliseconds < low) | (milliseconds >= high), dtype=bool)


def static_rows(table: pa.Table, bad_time: np.ndarray) -> pa.Table:
    """Canonical rows as static reports: no position (a static report may carry half of
    one), and a null timestamp where it does not parse or lies outside the AIS years."""
    stamps: pa.Array | pa.ChunkedArray = table.column("timestamp")
    if bad_time.any():
        stamps = pc.if_else(pa.array(bad_time), pa.scalar(None, stamps.type), stamps)
    nowhere = pa.nulls(table.num_rows, pa.float64())
    for name, column in (("timestamp", stamps), ("lat_deg", nowhere), ("lon_deg", nowhere)):
        table = table.set_column(table.schema.get_field_index(name), name, column)
    return table
