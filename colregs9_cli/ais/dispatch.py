"""Reading one AIS file by its layout: ``--format``'s, or the one detected from its first bytes
(detect.py), whose reader (``READERS``, by ``Layout.read_as``) hands its rows to the row
pipeline (row_pipeline.py).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from ..progress import ProgressSink
from ..query import Query
from .csv_input import read_dma_csv, read_mapped_csv
from .csv_read import CsvReading
from .detect import detect_layout
from .layouts import Layout, ReadAs
from .row_pipeline import FileRead, FileResult, RowSink
from .sources import Source, read_head
from .table_input import read_nmea_file, read_parquet_file

READERS: Mapping[ReadAs, Callable[[FileRead], FileResult]] = {
    ReadAs.DMA_CSV: read_dma_csv,
    ReadAs.MAPPED_CSV: read_mapped_csv,
    ReadAs.NMEA: read_nmea_file,
    ReadAs.PARQUET: read_parquet_file,
}


def read_source(
    source: Source,
    layout: Layout | None,
    query: Query,
    bar: ProgressSink,
    started: CsvReading | None,
    sink: RowSink | None = None,
    needs_time: bool = True,
) -> FileResult:
    """Read ``source`` in ``layout`` (``--format``), else in the layout its data shows;
    ``started``: the file, already being read as a CSV (``csv_read.start_reading``)."""
    if started is not None:
        started.attach_progress(bar)
        read = FileRead(source, started.layout, query, bar, sink, needs_time, started=started)
    else:
        head = read_head(source)
        found = layout if layout is not None else detect_layout(source, head)
        read = FileRead(source, found, query, bar, sink, needs_time, head=head)
    return READERS[read.layout.read_as](read)
