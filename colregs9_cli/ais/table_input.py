"""Reading the files whose rows come as canonical tables through the row pipeline
(row_pipeline.py): NMEA logs, decoded whole by nmea.py, and Parquet files with the canonical
columns, read by batches of rows. A Parquet file is cleaned again as a CSV is (its dimensions
within the limits, A, B, C, D as ``clean.offset_parts`` has them); one written before the
canonical schema had A, B, C, D is read with them null.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Iterator, Sequence

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from ..errors import InputFileError
from ..vessels import DIMENSIONS, MAX_BREADTH_M, MAX_LENGTH_M
from .batch import AisBatch
from .clean import (
    DimensionColumns,
    Dimensions,
    Fields,
    OffsetParts,
    clean_text,
    is_vessel,
    nan_to_null,
    null_outside,
    offset_parts,
    plausible,
    to_numpy_float,
    valid_mmsi,
)
from .dimension_reports import canonical_dimensions
from .ledger import RejectReason
from .row_pipeline import (
    Conversion,
    Converted,
    Example,
    FileRead,
    FileResult,
    Part,
    StaticText,
    classify,
    static_rows,
    time_out_of_range,
)
from .schema import ANTENNA_OFFSETS, CANONICAL_COLUMNS, CANONICAL_SCHEMA
from .sources import Source, decompression_error, open_data, sha256_file
from .time_sources import ingest_params

PARQUET_BATCH_ROWS = 256 * 1024


def _canonical_fields(table: pa.Table, offsets: bool = False) -> Fields:
    """The fields of canonical rows. ``offsets``: their dimensions are measured with their
    A, B, C, D (``_parquet_dimensions``: a Parquet file is cleaned again); else as stored
    (decoded NMEA, cleaned by nmea_tables.py)."""
    mmsi = pc.fill_null(table.column("mmsi"), -1).to_numpy()
    n = table.num_rows
    if offsets:
        dimensions = DimensionColumns(
            table.select([*DIMENSIONS, *ANTENNA_OFFSETS]), _parquet_dimensions
        )
    else:
        dimensions = DimensionColumns(table.select(list(DIMENSIONS)), canonical_dimensions)
    return Fields(
        mmsi=np.asarray(mmsi, dtype=np.int64),
        lat_deg=null_outside(to_numpy_float(table.column("lat_deg")), -90.0, 90.0),
        lon_deg=null_outside(to_numpy_float(table.column("lon_deg")), -180.0, 180.0),
        vessel=is_vessel(table.column("mobile_type").combine_chunks()),
        dimensions=dimensions,
        unparseable=np.zeros(n, dtype=bool),
        problem=[],
    )


def _parquet_offsets(table: pa.Table) -> OffsetParts:
    a, b, c, d = (to_numpy_float(table.column(name)) for name in ANTENNA_OFFSETS)
    return offset_parts(a, b, c, d)


def _parquet_dimensions(table: pa.Table) -> Dimensions:
    """A Parquet file's dimensions before the limits: as stored (the canonical columns are
    the file's word), but from A, B, C, D (``clean.offset_parts``) where the stored one is
    null, or where the parts alone are beyond the limits, so that such a row is counted as
    implausible and its parts dropped rather than kept silently."""
    return _parquet_measure(table, _parquet_offsets(table))


def _parquet_measure(table: pa.Table, offsets: OffsetParts) -> Dimensions:
    length_m, breadth_m, draught_m = canonical_dimensions(table)
    with np.errstate(invalid="ignore"):
        return (
            np.where(
                np.isnan(length_m) | (offsets.length_m > MAX_LENGTH_M), offsets.length_m, length_m
            ),
            np.where(
                np.isnan(breadth_m) | (offsets.breadth_m > MAX_BREADTH_M),
                offsets.breadth_m,
                breadth_m,
            ),
            draught_m,
        )


def _parquet_canonical(table: pa.Table) -> tuple[pa.Table, np.ndarray]:
    """A Parquet file's rows cleaned as a reader cleans its rows: the implausible dimensions
    dropped (``clean.plausible``, counted with the rows' block), and A, B, C, D as
    ``clean.offset_parts`` cleans them, null where the row's length or breadth is dropped."""
    table, bad_time = _canonical_identity(table)
    offsets = _parquet_offsets(table)
    measured = _parquet_measure(table, offsets)
    cleaned = {
        **dict(zip(DIMENSIONS, (nan_to_null(v) for v in plausible(measured)), strict=True)),
        **offsets.columns(measured),
    }
    for name, column in cleaned.items():
        table = table.set_column(table.schema.get_field_index(name), name, column)
    return table, bad_time


def _taker(table: pa.Table) -> Callable[[np.ndarray], Part]:
    return lambda rows: table.take(pa.array(rows, pa.int64()))


def _table_conversion(
    name: str,
    static_text: StaticText | None,
    canonical: Callable[[pa.Table], tuple[pa.Table, np.ndarray]] | None = None,
) -> Conversion:
    def convert(parts: list[Part]) -> list[Converted]:
        table = pa.concat_tables(part for part in parts if isinstance(part, pa.Table))
        return [Converted(table, _table_example(name, table))]

    return Conversion(convert, canonical or _canonical_identity, static_text)


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


def read_nmea_file(read: FileRead) -> FileResult:
    """An NMEA log; with ``needs_time`` False its messages without a time are kept (a null
    timestamp is then no time, not a bad one), else a log where none has a time is refused."""
    from .nmea import NmeaCounts, read_nmea

    source, query, needs_time = read.source, read.query, read.needs_time
    ingest = ingest_params(query)
    conversion = _table_conversion(source.name, None)
    if not needs_time:
        conversion = Conversion(conversion.convert, _timeless_identity, None)
    result = FileResult(query, source.name, conversion, layout=read.layout.name, sink=read.sink)
    counts = NmeaCounts()
    with open_data(source, read.bar) as opened:
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


def _nmea_batch(result: FileResult, batch: AisBatch) -> None:
    positions = batch.positions
    classify(
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
    dimensions = DimensionColumns(statics.select(list(DIMENSIONS)), canonical_dimensions)
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
    return static_rows(table, time_out_of_range(table))


def read_parquet_file(read: FileRead) -> FileResult:
    """A Parquet file with the canonical columns, read by batches of rows."""
    import pyarrow.parquet as pq  # only here: its import would slow every CSV run

    source = read.source
    if source.compression != "none":
        raise InputFileError(
            f"{source.name}: a compressed Parquet file; give the .parquet file itself"
        )
    conversion = _table_conversion(source.name, _canonical_static_text, _parquet_canonical)
    result = FileResult(
        read.query, source.name, conversion, layout=read.layout.name, sink=read.sink
    )
    try:
        parquet = pq.ParquetFile(source.path)
    except (pa.ArrowException, OSError) as exc:
        raise InputFileError(f"{source.name}: not a readable Parquet file ({exc})") from None
    names = parquet.schema_arrow.names
    twice = [c for c in CANONICAL_COLUMNS if names.count(c) > 1]
    if twice:  # which of them holds the data cannot be told; other columns are not read
        raise InputFileError(
            f"{source.name}: the Parquet file has the column {twice[0]!r} "
            f"{names.count(twice[0])} times; write it again with each canonical column once"
        )
    # A, B, C, D may be absent: files written before the canonical schema had them.
    required = [c for c in CANONICAL_COLUMNS if c not in ANTENNA_OFFSETS]
    missing = [c for c in required if c not in names]
    if missing:
        raise InputFileError(
            f"{source.name}: the Parquet file lacks the canonical column {missing[0]!r}; "
            f"it needs {', '.join(required)} (and may have {', '.join(ANTENNA_OFFSETS)})"
        )
    try:
        for record_batch in parquet.iter_batches(
            batch_size=PARQUET_BATCH_ROWS, columns=[c for c in CANONICAL_COLUMNS if c in names]
        ):
            table = _to_canonical(source, pa.Table.from_batches([record_batch]))
            result.ledger.read(table.num_rows)
            classify(
                result,
                _canonical_fields(table, offsets=True),
                _taker(table),
                _table_example(result.name, table),
            )
        result.settle()
    except (pa.ArrowException, OSError) as exc:
        raise InputFileError(f"{source.name}: cannot read the Parquet file ({exc})") from None
    read.bar.advance(source.size_bytes)
    result.sha256 = sha256_file(source.path)
    return result


def _to_canonical(source: Source, table: pa.Table) -> pa.Table:
    columns = []
    for target in CANONICAL_SCHEMA:
        if target.name not in table.column_names:  # A, B, C, D of an older file
            columns.append(pa.nulls(table.num_rows, target.type))
            continue
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
