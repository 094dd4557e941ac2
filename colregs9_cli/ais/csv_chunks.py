"""Reading a CSV in chunks of whole lines: every row's filter columns, the rest on demand.

A DMA day file is mostly rows outside the query. Converting all of their columns is what
makes a plain streaming read slow, so each chunk (``CHUNK_BYTES`` of whole lines) is parsed
by pyarrow's ``read_csv`` with only the columns that every row needs (``row_columns``:
position, MMSI, mobile type, dimensions). The few rows that the pipeline keeps are then cut
out of the chunk's bytes by their line offsets (``CsvChunk.cut``) and parsed again with all
columns, together with rows cut from other chunks (``parse_cut_rows``): a parse of a few
rows costs little itself, but waits for pyarrow's threads while they parse the next chunk.
The chunks are read in order and parsed side by side on worker threads, one chunk per core
(``parse_workers``), while the caller works on the ones before, so memory stays at a few
chunks plus the rows cut out.

A row is one non-empty line (ended by LF, CRLF or a lone CR; pyarrow skips empty lines),
unless a quoted field holds a line end: chunks with such a record follow the records with
Python's ``csv`` module to find the lines (slower, but exact). A chunk is cut only at a line
end, so a quoted line end that falls on a chunk boundary splits its record in two
unparseable rows, as pyarrow's own block splitting would. Should the records still not match
the rows (no input known), the chunk is parsed whole with all columns and its line numbers
are the chunk's first.

Each chunk falls back on its own, so a bad row costs one chunk, not the file:

- Malformed rows (a wrong number of fields) are skipped and reported with their file line.
  Parsing on several threads loses line numbers, so rows cut out and parsed on all cores
  are parsed again on one thread if one is malformed (a chunk parses on one thread).
- The ``numeric`` columns are read as numbers (the ``whole`` ones as integers: the MMSI,
  and DMA's lengths and widths in metres). A chunk where one holds something else
  (``north`` for a latitude, ``N/A``, a decimal MMSI or length) is parsed again with every
  column as text, and the caller's cleaning sorts the values out (``CsvChunk.text``
  tells). The same holds for the rows cut out.
  Only an empty field is null: pyarrow's other null spellings (``NULL``, ``NA``, ...) cost
  every number a lookup, and the text path turns them to null.
"""

from __future__ import annotations

import codecs
import collections
import csv
import functools
import io
from collections.abc import Generator, Mapping, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, BinaryIO

import numpy as np
import pyarrow as pa
import pyarrow.csv as pacsv
from numpy.typing import NDArray

CHUNK_BYTES = 16 * 1024 * 1024
# pyarrow's parallel unit inside a chunk.
PARSE_BLOCK_BYTES = 4 * 1024 * 1024
_NEWLINE, _CARRIAGE_RETURN, _FIRST_NON_ASCII = 10, 13, 128


class NotUtf8(Exception):
    """A chunk holds bytes that are not UTF-8."""


@dataclass(frozen=True)
class InvalidRow:
    line: int
    expected_columns: int
    actual_columns: int
    text: str


class CsvChunk:
    """One chunk: ``rows`` holds the row columns of its valid rows, in file order."""

    def __init__(
        self,
        rows: pa.Table,
        invalid: list[tuple[int | None, int, int, str]],
        data: memoryview,
        has_carriage_return: bool,
        text: bool,
        first_line: int,
        layout: _Layout,
    ) -> None:
        self.rows = rows
        self.text = text
        self._invalid = invalid  # (record number from 1, expected, actual fields, text)
        self._malformed = np.array([n - 1 for n, *_ in invalid if n is not None], np.int64)
        self._data = data
        self._line_ends = _line_ends(np.frombuffer(data, np.uint8), has_carriage_return)
        self.line_count = len(self._line_ends)
        self._first_line = first_line
        self._layout = layout

    @functools.cached_property
    def _records(self) -> _Records | None:
        return _find_records(self._data, self._line_ends, self.rows.num_rows + len(self._invalid))

    @functools.cached_property
    def invalid_rows(self) -> list[InvalidRow]:
        """The malformed rows, skipped, with the file line each starts on."""
        records = self._records if self._invalid else None
        return [
            InvalidRow(
                self._first_line + int(records.first_line[number - 1])
                if records is not None and number is not None
                else self._first_line,
                expected,
                actual,
                line_text,
            )
            for number, expected, actual, line_text in self._invalid
        ]

    @functools.cached_property
    def _row_spans(self) -> _Records | None:
        """Where each row lies in the chunk; None if the records do not match the rows."""
        records = self._records
        if records is None:
            return None
        if not len(self._malformed):
            return records
        keep = np.delete(np.arange(len(records.first_line)), self._malformed)
        return _Records(records.first_line[keep], records.start[keep], records.end[keep])

    def line_of(self, row: int) -> int:
        """The file line (1-based) where a row starts."""
        if self._row_spans is None:
            return self._first_line
        return self._first_line + int(self._row_spans.first_line[row])

    def take(self, rows: NDArray[np.int64], columns: Sequence[str] | None = None) -> pa.Table:
        """The given rows (indices into ``rows``), in that order, with ``columns`` (by
        default all) converted."""
        return parse_cut_rows([self.cut(rows)], columns)[0].table

    def cut(self, rows: NDArray[np.int64]) -> CutRows:
        """The given rows (indices into ``rows``) cut out of the chunk, to be parsed with
        all columns later, together with rows cut from other chunks (``parse_cut_rows``)."""
        if self._row_spans is None:
            whole, _ = _parse_numbers_or_text(
                self._data, self._layout, self._layout.all_columns, self.text
            )
            lines = np.full(len(rows), self._first_line, np.int64)
            return CutRows(self._layout, lines, self.text, table=whole.take(pa.array(rows)))
        spans = self._row_spans
        data = _gather(self._data, spans.start[rows], spans.end[rows] + 1)
        return CutRows(self._layout, self._first_line + spans.first_line[rows], self.text, data)


@dataclass(frozen=True)
class CutRows:
    """Rows cut out of a chunk: their bytes (or, where the chunk's records could not be
    found, the rows already parsed) and the file line each starts on."""

    layout: _Layout
    lines: NDArray[np.int64]
    text: bool
    data: memoryview | None = None
    table: pa.Table | None = None

    @property
    def size_bytes(self) -> int:
        return len(self.data) if self.data is not None else 0


@dataclass(frozen=True)
class ParsedRows:
    table: pa.Table
    lines: NDArray[np.int64]


def parse_cut_rows(
    cuts: Sequence[CutRows], columns: Sequence[str] | None = None
) -> list[ParsedRows]:
    """The cut rows with ``columns`` (default: all) converted, in order: the rows given as
    bytes are parsed in one go, and rows already parsed follow as they are.

    Numbers are read as numbers where every cut row allows it, else every column as text
    (``ParsedRows.table`` tells by its column types).
    """
    if not cuts:
        return []
    layout = cuts[0].layout
    wanted = layout.all_columns if columns is None else columns
    parsed: list[ParsedRows] = []
    pieces = [cut for cut in cuts if cut.data is not None]
    if pieces:
        data = b"".join(cut.data for cut in pieces)  # type: ignore[misc]
        text = any(cut.text for cut in pieces)
        table, _ = _parse_numbers_or_text(memoryview(data), layout, wanted, text)
        parsed.append(ParsedRows(table, np.concatenate([cut.lines for cut in pieces])))
    parsed.extend(
        ParsedRows(cut.table.select(list(wanted)), cut.lines)
        for cut in cuts
        if cut.table is not None
    )
    return parsed


def _gather(data: memoryview, starts: NDArray[np.int64], stops: NDArray[np.int64]) -> memoryview:
    """The byte ranges ``[start, stop)`` of ``data`` one after another."""
    # Adjacent ranges (runs of consecutive lines) are copied as one.
    joined = np.r_[False, starts[1:] == stops[:-1]]
    firsts = np.flatnonzero(~joined)
    run_starts = starts[firsts].tolist()
    run_stops = stops[np.r_[firsts[1:] - 1, len(stops) - 1]].tolist() if len(firsts) else []
    return memoryview(b"".join(data[a:b] for a, b in zip(run_starts, run_stops, strict=True)))


@dataclass(frozen=True)
class _Records:
    """Per CSV record: its first line (index in the chunk), and the byte offsets of the start
    of that line and of the line end that closes the record."""

    first_line: NDArray[np.int64]
    start: NDArray[np.int64]
    end: NDArray[np.int64]


def _find_records(data: memoryview, line_ends: NDArray[np.int64], count: int) -> _Records | None:
    """Where the chunk's ``count`` records (valid or malformed, blank lines aside) lie.

    A record is one non-empty line, unless a quoted field holds a line end, which pyarrow
    accepts: then the records are followed as Python's ``csv`` module reads them (the same
    dialect), which is slow but only for such chunks. None if that still gives another count.
    """
    if len(line_ends) == count:  # each record one line: no blank line, no quoted line end
        starts = np.empty_like(line_ends)
        starts[:1] = 0
        starts[1:] = line_ends[:-1] + 1
        return _Records(np.arange(count), starts, line_ends)
    starts, ends, non_empty = _lines(data, line_ends)
    if len(non_empty) == count:
        return _Records(non_empty, starts[non_empty], ends[non_empty])
    reader = csv.reader(io.StringIO(codecs.decode(bytes(data), "utf-8"), newline=""))
    first: list[int] = []
    last: list[int] = []
    consumed = 0
    for record in reader:
        if record:
            first.append(consumed)
            last.append(reader.line_num - 1)
        consumed = reader.line_num
    if len(first) != count or consumed != len(line_ends):
        return None
    first_line, last_line = np.array(first, np.int64), np.array(last, np.int64)
    return _Records(first_line, starts[first_line], ends[last_line])


@dataclass(frozen=True)
class _Layout:
    names: Sequence[str]
    row_columns: Sequence[str]
    all_columns: Sequence[str]
    numeric: frozenset[str]
    whole: frozenset[str]
    delimiter: str = ","


def read_chunks(
    stream: BinaryIO,
    names: Sequence[str],
    has_header: bool,
    row_columns: Sequence[str],
    all_columns: Sequence[str],
    numeric: Sequence[str],
    whole: Sequence[str] = (),
    delimiter: str = ",",
) -> Generator[CsvChunk, None, None]:
    """The chunks of a CSV stream, in order, each parsed on a worker thread while the ones
    before it are used.

    ``names`` are the file's columns; ``row_columns`` are converted for every row,
    ``all_columns`` for the rows taken; ``numeric`` columns are read as numbers where they
    can be, those also in ``whole`` as integers. Raises ``pa.ArrowInvalid`` for data
    pyarrow cannot read, ``NotUtf8``, and whatever reading the stream raises.
    """
    layout = _Layout(
        names, row_columns, all_columns, frozenset(numeric), frozenset(whole), delimiter
    )
    pieces = _Pieces(stream, first_line=2 if has_header else 1, skip_header=has_header)
    workers = parse_workers()
    with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="colregs9-csv") as pool:
        pending: collections.deque[Future[_Parsed]] = collections.deque()
        line = 0
        try:
            while True:
                # Pieces are read here, in file order; each is parsed by its own worker.
                while len(pending) < workers and (piece := pieces.read()) is not None:
                    pending.append(pool.submit(_parse_piece, piece, layout))
                if not pending:
                    return
                parsed = pending.popleft().result()
                line = line or pieces.first_line  # known once the first piece is read
                chunk = CsvChunk(*parsed, first_line=line, layout=layout)
                line += chunk.line_count
                yield chunk
        finally:
            for future in pending:
                future.cancel()


def parse_workers() -> int:
    """How many chunks are parsed at once, each on one thread: pyarrow's threads (a 16 MB
    chunk splits into 4 blocks), up to 4. Chunks side by side cost less CPU than one chunk at
    a time on all threads, which splits and merges its blocks (figures:
    tests/benchmarks/README.md, "Figures moved from code comments")."""
    return max(1, min(CHUNK_BYTES // PARSE_BLOCK_BYTES, pa.cpu_count()))


class _Pieces:
    """Whole-line pieces of a stream, each in its own buffer, and the file line the first
    one starts on (set by the read that finds the header)."""

    def __init__(self, stream: BinaryIO, first_line: int, skip_header: bool) -> None:
        self._stream = stream
        self._carry = b""
        self._skip_header = skip_header
        self._ended = False
        self.first_line = first_line

    def read(self) -> tuple[memoryview, bool] | None:
        """The next piece, and whether it holds a carriage return; None from the end on."""
        while not self._ended:
            carried = len(self._carry)
            # A new buffer per piece: a chunk, and the tables parsed from it, keep it alive
            # for as long as they need it (room for the carried bytes, a chunk and a newline).
            buffer = bytearray(carried + CHUNK_BYTES + 1)
            buffer[:carried] = self._carry
            room = memoryview(buffer)[carried : carried + CHUNK_BYTES]
            got = self._stream.readinto(room)  # type: ignore[attr-defined]
            end = carried + got
            if got:
                cut = _last_line_end(buffer, end)
                if cut == 0:
                    self._carry = bytes(buffer[:end])
                    continue
                self._carry = bytes(buffer[cut:end])
            else:
                self._carry = b""
                if end and buffer[end - 1] not in (_NEWLINE, _CARRIAGE_RETURN):
                    buffer[end] = _NEWLINE
                    end += 1
                cut = end
            start = 0
            if self._skip_header:
                start = self._past_blank_lines(buffer, cut)
                if start < cut:
                    self._skip_header = False
                    start = _first_line_end(buffer, start, cut)
            if start < cut:
                return memoryview(buffer)[start:cut], buffer.find(b"\r", start, cut) != -1
            self._ended = not got
        return None

    def _past_blank_lines(self, buffer: bytearray, end: int) -> int:
        """Just past the blank lines before the header, which count as lines of the file."""
        start = 0
        while start < end and buffer[start] in (_NEWLINE, _CARRIAGE_RETURN):
            crlf = (
                buffer[start] == _CARRIAGE_RETURN
                and start + 1 < end
                and (buffer[start + 1] == _NEWLINE)
            )
            self.first_line += 0 if crlf else 1
            start += 1
        return start


def _last_line_end(buffer: bytearray, end: int) -> int:
    """Just past the last line end before ``end`` (0 if none): a newline, else a lone CR.
    A CR in the last byte may be the first half of a CRLF whose LF is not read yet."""
    cut = buffer.rfind(b"\n", 0, end) + 1
    return cut if cut else buffer.rfind(b"\r", 0, end - 1) + 1


def _first_line_end(buffer: bytearray, start: int, end: int) -> int:
    """Just past the line from ``start`` (the header), which may end in LF, CRLF or a lone CR."""
    newline, carriage = buffer.find(b"\n", start, end), buffer.find(b"\r", start, end)
    if carriage != -1 and (newline == -1 or carriage + 1 < newline):
        return carriage + 1
    return newline + 1 if newline != -1 else end


_Parsed = tuple[pa.Table, list[tuple[int | None, int, int, str]], memoryview, bool, bool]


def _parse_piece(piece: tuple[memoryview, bool], layout: _Layout) -> _Parsed:
    """A piece parsed on the calling thread: its rows, malformed rows, bytes, whether it
    holds a carriage return, and whether it was read as text."""
    data, has_carriage_return = piece
    if np.frombuffer(data, np.uint8).max() >= _FIRST_NON_ASCII:
        try:
            codecs.utf_8_decode(data, "strict", True)
        except UnicodeDecodeError:
            raise NotUtf8 from None
    invalid: list[tuple[int | None, int, int, str]] = []
    rows, text = _parse_numbers_or_text(
        data, layout, layout.row_columns, False, invalid, threads=False
    )
    return rows, invalid, data, has_carriage_return, text


def _parse_numbers_or_text(
    data: memoryview,
    layout: _Layout,
    columns: Sequence[str],
    text: bool,
    invalid: list[tuple[int | None, int, int, str]] | None = None,
    threads: bool = True,
) -> tuple[pa.Table, bool]:
    """Parse with numbers as numbers, on all cores (``threads``) or on the calling thread;
    again on one thread if a row is malformed (for its line number), and again as text if a
    number column holds text. Returns the table and whether it was read as text. Malformed
    rows are skipped and go to ``invalid``.
    """
    block_bytes = PARSE_BLOCK_BYTES
    while True:
        found: list[tuple[int | None, int, int, str]] = []

        def invalid_row(row: Any, found: list = found, threads: bool = threads) -> str:
            found.append((row.number, row.expected_columns, row.actual_columns, row.text))
            return "error" if threads else "skip"

        types = {c: _type(c, layout, text) for c in columns}
        try:
            table = _parse(
                data, layout.names, types, threads, invalid_row, block_bytes, layout.delimiter
            )
        except pa.ArrowInvalid as exc:
            if "straddles" in str(exc) and block_bytes <= len(data):
                block_bytes = len(data) + 1  # a line longer than a block: one block
            elif threads and found:
                threads = False
            elif not text and "conversion error" in str(exc):
                text = True
            else:
                raise
            continue
        if invalid is not None:
            invalid.extend(found)
        return table, text


def _type(column: str, layout: _Layout, text: bool) -> pa.DataType:
    if text or column not in layout.numeric:
        return pa.string()
    return pa.int64() if column in layout.whole else pa.float64()


def _line_ends(raw: NDArray[np.uint8], has_carriage_return: bool) -> NDArray[np.int64]:
    """Offsets of the line ends: each LF, and each CR not followed by a LF (old Mac files)."""
    ends = np.flatnonzero(raw == _NEWLINE)
    if not has_carriage_return:
        return ends
    returns = np.flatnonzero(raw == _CARRIAGE_RETURN)
    following = np.minimum(returns + 1, len(raw) - 1)
    lone = returns[(returns + 1 == len(raw)) | (raw[following] != _NEWLINE)]
    return np.union1d(ends, lone) if len(lone) else ends


def _lines(
    data: memoryview, ends: NDArray[np.int64]
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """Start and line-end offset (``ends``) of each line of ``data``, and the indices of the
    non-empty lines (pyarrow skips lines that are empty or hold only a carriage return)."""
    raw = np.frombuffer(data, np.uint8)
    starts = np.empty_like(ends)
    starts[:1] = 0
    starts[1:] = ends[:-1] + 1
    length = ends - starts
    empty = (length == 0) | ((length == 1) & (raw[starts] == _CARRIAGE_RETURN))
    return starts, ends, np.flatnonzero(~empty)


def _parse(
    data: memoryview,
    names: Sequence[str],
    types: Mapping[str, pa.DataType],
    threads: bool,
    invalid_row: Any = None,
    block_bytes: int = PARSE_BLOCK_BYTES,
    delimiter: str = ",",
) -> pa.Table:
    return pacsv.read_csv(
        pa.BufferReader(pa.py_buffer(data)),
        read_options=pacsv.ReadOptions(
            column_names=list(names), block_size=block_bytes, use_threads=threads
        ),
        parse_options=pacsv.ParseOptions(delimiter=delimiter, invalid_row_handler=invalid_row),
        convert_options=pacsv.ConvertOptions(
            column_types=dict(types),
            include_columns=list(types),
            null_values=[""],
            strings_can_be_null=False,
            quoted_strings_can_be_null=False,
        ),
    )
