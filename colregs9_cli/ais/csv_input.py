"""Reading a CSV file through the row pipeline (row_pipeline.py): chunk by chunk
(csv_chunks.py, csv_read.py), each chunk's rows converted by its layout's converters, DMA's
(dma.py) or a column map's (mapped.py).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pyarrow as pa

from ..errors import InputFileError
from . import dma, mapped
from .clean import Fields
from .columns import file_map, missing_columns
from .csv_chunks import CsvChunk, CutRows, NotUtf8, ParsedRows, parse_cut_rows
from .csv_read import CsvReading
from .detect import csv_header
from .layouts import DMA_ABCD, MAP_PREFIX, Layout
from .ledger import EXAMPLE_CHARS, RejectReason
from .row_pipeline import (
    Conversion,
    Converted,
    Example,
    FileRead,
    FileResult,
    Part,
    StaticText,
    classify,
)
from .sources import Source, locate_non_utf8

_DECIMAL = re.compile(r"[-+]?\d+(\.\d*)?")


@dataclass(frozen=True)
class CsvConverters:
    """How a CSV layout's columns become the row pipeline's: ``fields`` for every row,
    ``canonical`` for the rows kept, ``static_text`` for the rows without a position."""

    fields: Callable[[pa.RecordBatch], Fields]
    static_text: StaticText
    canonical: Callable[[pa.RecordBatch], tuple[pa.Table, np.ndarray]]
    example_columns: dict[str, str]  # what -> the column to quote in reject examples
    # Rows of AIS message types that are neither positions, statics nor non-vessels.
    unsupported: Callable[[pa.RecordBatch], np.ndarray | None] = lambda _: None


def read_dma_csv(read: FileRead) -> FileResult:
    """A DMA "aisdk" CSV, its columns converted by dma.py."""
    return _read_csv(read, _dma_converters)


def read_mapped_csv(read: FileRead) -> FileResult:
    """A CSV read through a column map (column_map.py), its columns converted by mapped.py."""
    return _read_csv(read, _mapped_converters)


def _dma_converters(layout: Layout, header: tuple[str, ...]) -> CsvConverters:
    abcd = set(DMA_ABCD) <= set(layout.header)
    return CsvConverters(
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


def _mapped_converters(layout: Layout, header: tuple[str, ...]) -> CsvConverters:
    map_ = file_map(layout, header)
    mobile = next(
        (map_.column(t) for t in ("message_type", "mobile_type") if map_.has(t)),
        map_.column("mmsi"),
    )
    return CsvConverters(
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


def _open_csv(read: FileRead) -> CsvReading:
    """The file opened for reading in chunks, once its header has the layout's columns."""
    source, layout = read.source, read.layout
    header = csv_header(source, read.head, layout)
    missing = missing_columns(layout, header.columns)
    if missing:
        if layout.map_file is not None:
            raise InputFileError(
                f"{source.name}: the map {layout.name.removeprefix(MAP_PREFIX)} names the "
                f"column {missing[0]!r}, which the header does not have; check the map's "
                "[columns]"
            )
        raise InputFileError(
            f"{source.name}: the {layout.name} layout needs the column {missing[0]!r}, which "
            f"the header does not have; check the file or the --format given"
        )
    return CsvReading(source, layout, header, read.bar)


def _read_csv(
    read: FileRead, converters: Callable[[Layout, tuple[str, ...]], CsvConverters]
) -> FileResult:
    source = read.source
    reading = read.started if read.started is not None else _open_csv(read)
    spec = converters(reading.layout, reading.header.columns)
    conversion = Conversion(_csv_conversion(source.name, spec), spec.canonical, spec.static_text)
    result = FileResult(
        read.query, source.name, conversion, layout=reading.layout.name, sink=read.sink
    )
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


def _csv_chunk(result: FileResult, spec: CsvConverters, chunk: CsvChunk) -> None:
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
            f"{bad.actual_columns}{spans}: {bad.text[:EXAMPLE_CHARS]}",
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

    classify(result, spec.fields(rows), chunk.cut, example, spec.unsupported(rows))


def _line_example(name: str, line: int, why: str, value: object) -> str:
    # A chunk read as text gives its numbers as text: quote them as numbers all the same.
    if isinstance(value, str) and _DECIMAL.fullmatch(value):
        value = float(value)
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    return f"{name}:{line}: {why} {value!r}"


def _csv_conversion(name: str, spec: CsvConverters) -> Callable[[list[Part]], list[Converted]]:
    def convert(parts: list[Part]) -> list[Converted]:
        cuts = [part for part in parts if isinstance(part, CutRows)]
        return [
            Converted(rows.table, _cut_example(name, spec, rows)) for rows in parse_cut_rows(cuts)
        ]

    return convert


def _cut_example(name: str, spec: CsvConverters, rows: ParsedRows) -> Example:
    def example(row: int, what: str, why: str) -> str:
        value = rows.table.column(spec.example_columns[what])[row].as_py()
        return _line_example(name, int(rows.lines[row]), why, value)

    return example
