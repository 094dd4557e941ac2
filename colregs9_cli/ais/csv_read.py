"""Opening a CSV input for chunked reading: on the caller's thread, or ahead of it.

``CsvReading`` opens the file (decompressing and hashing it, see sources.py) and gives its
chunks (see csv_chunks.py). ``start_reading`` opens the first input of a run ahead of time:
a thread reads and parses its first chunks into a queue while the caller imports the
libraries of the analysis (pandas and matplotlib take about half a second, on one core, which
would leave the other idle). This module and the ones it imports need only pyarrow and
numpy.
"""

from __future__ import annotations

import contextlib
import queue
import threading
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType

from ..errors import Colregs9Error
from ..progress import ProgressSink
from .columns import csv_columns, missing_columns
from .csv_chunks import CsvChunk, read_chunks
from .detect import CsvHeader, csv_header, detect_layout
from .layouts import Layout, find_layout
from .sources import OpenedData, Source, inspect_source, open_data, read_head

# How many parsed chunks may wait for the caller (about 25 MB each, bytes and row columns).
# The imports of ``colregs9 stats`` take about as long as parsing 12 chunks on the other
# core; with fewer the read-ahead stops and a core idles. Each chunk waiting holds memory
# (figures: tests/benchmarks/README.md, "Figures moved from code comments").
AHEAD_CHUNKS = 12
_POLL_S = 0.05


class _LateProgress:
    """A progress sink that keeps what is reported until a bar is attached."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._kept = 0.0
        self._bar: ProgressSink | None = None

    def advance(self, amount: float = 1.0) -> None:
        with self._lock:
            if self._bar is None:
                self._kept += amount
                return
        self._bar.advance(amount)

    def describe(self, note: str) -> None:
        if self._bar is not None:
            self._bar.describe(note)

    def attach(self, bar: ProgressSink) -> None:
        with self._lock:
            self._bar = bar
            kept, self._kept = self._kept, 0.0
        bar.advance(kept)


@dataclass(frozen=True)
class _Failed:
    error: BaseException


_END = object()


class CsvReading:
    """One CSV input being read in chunks; a context manager that closes the file.

    Errors of the read (decompression, pyarrow, ``NotUtf8``) are raised by ``chunks`` on the
    caller's thread, also when the chunks are read ahead; leaving the ``with`` block with a
    decompression error turns it into ``InputFileError`` (``sources.open_data``).
    """

    def __init__(
        self,
        source: Source,
        layout: Layout,
        header: CsvHeader,
        progress: ProgressSink | None,
        ahead: bool = False,
    ) -> None:
        """``progress`` None: report to the bar given later (``attach_progress``)."""
        self.source = source
        self.layout = layout
        self.header = header
        self._exits = contextlib.ExitStack()
        self._progress = _LateProgress()
        if progress is not None:
            self._progress.attach(progress)
        self._opened: OpenedData = self._exits.enter_context(open_data(source, self._progress))
        columns = csv_columns(layout, header.columns)
        self._chunks = read_chunks(
            self._opened.stream,
            header.columns,
            header.has_header,
            row_columns=columns.row_columns,
            all_columns=columns.columns,
            numeric=columns.numeric,
            whole=columns.whole,
            delimiter=columns.delimiter,
        )
        self._exits.callback(self._chunks.close)
        self._queue: queue.Queue[object] | None = None
        self._stop = threading.Event()
        self._pump_thread: threading.Thread | None = None
        if ahead:
            self._queue = queue.Queue(maxsize=AHEAD_CHUNKS)
            self._pump_thread = threading.Thread(
                target=self._pump, name="colregs9-csv-ahead", daemon=True
            )
            self._pump_thread.start()
            self._exits.callback(self._stop_pump)

    def attach_progress(self, bar: ProgressSink) -> None:
        """Report the bytes read so far, and from now on, to ``bar``."""
        self._progress.attach(bar)

    def chunks(self) -> Iterator[CsvChunk]:
        if self._queue is None:
            yield from self._chunks
            return
        while (item := self._queue.get()) is not _END:
            if isinstance(item, _Failed):
                raise item.error
            assert isinstance(item, CsvChunk)
            yield item

    def finish(self) -> str:
        """The file's sha256, once every chunk has been read."""
        self._stop_pump()
        return self._opened.finish()

    def _pump(self) -> None:
        assert self._queue is not None
        try:
            for chunk in self._chunks:
                if not self._put(chunk):
                    return
            self._put(_END)
        except BaseException as error:  # raised again on the caller's thread
            self._put(_Failed(error))

    def _put(self, item: object) -> bool:
        """Queue ``item`` unless the reading is being stopped; whether it was queued."""
        assert self._queue is not None
        while not self._stop.is_set():
            try:
                self._queue.put(item, timeout=_POLL_S)
                return True
            except queue.Full:
                continue
        return False

    def _stop_pump(self) -> None:
        if self._pump_thread is None:
            return
        self._stop.set()
        self._pump_thread.join()

    def __enter__(self) -> CsvReading:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> bool | None:
        return self._exits.__exit__(kind, error, trace)


@contextlib.contextmanager
def start_reading(paths: Sequence[Path], fmt: str | None) -> Iterator[CsvReading | None]:
    """Start reading the first input ahead, if it is a CSV that looks readable; else None,
    and ``load_ais`` opens it as usual (and reports what is wrong with it)."""
    reading = None
    with contextlib.suppress(Colregs9Error):
        source = inspect_source(paths[0]) if paths else None
        if source is not None:
            head = read_head(source)
            layout = find_layout(fmt) if fmt is not None else detect_layout(source, head)
            header = csv_header(source, head, layout) if layout.read_as.is_csv else None
            if header is not None and not missing_columns(layout, header.columns):
                reading = CsvReading(source, layout, header, None, ahead=True)
    if reading is None:
        yield None
        return
    with reading:
        yield reading
