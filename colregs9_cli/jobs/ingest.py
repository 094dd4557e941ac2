"""``colregs9 ingest``: AIS files into a Parquet dataset (reading windows of one back is
``ais/dataset_window.py``'s, given here too).

Layout (``OUT`` is the dataset directory)::

    OUT/colregs9-dataset.json                       the manifest
    OUT/date=YYYY-MM-DD/part-<sha16>-<n>.parquet    one or more files per input and date
    OUT/date=__HIVE_DEFAULT_PARTITION__/...         static reports whose time does not parse
    OUT/_dimension_reports/part-<sha16>.parquet     dimension reports outside the query

``<sha16>`` is the first 16 hex digits of the input file's sha256, ``<n>`` counts the input's
files in that partition (a new file starts, at an hour boundary, past ``FILE_ROWS``). The
files hold the canonical schema (``schema.CANONICAL_SCHEMA``, format version 3; the
partition gives ``date``), zstd-compressed, in row groups of ``ROW_GROUP_ROWS``. An ingest
into an older dataset (version 1: files without A, B, C, D; 2: no dimension reports outside
the query) adds its inputs so, and records each input's version in the manifest, then of
version 3 (dataset_scan.py reads all three). Within a
file the positions come first, sorted by (hour of timestamp, floor(lat_deg), floor(lon_deg),
mmsi, timestamp), so that each row group covers about one hour and a band of latitudes: the
statistics on timestamp, lat_deg and lon_deg let a time and region query skip most row
groups. Then the static reports (rows without a position that carry static fields, load.py
step 4, with null lat/lon), in their own row groups, sorted by (hour, mmsi, timestamp):
``stats`` counts their dimensions as it does in the files.

The rows are those ``load_ais`` would use under the ingest query (everything by default):
cleaned the same way, exact duplicates dropped, with the same rejects ledger. The rows the
query leaves out are not written, but their dimension reports are (every vessel's, counted
by MMSI, length, breadth and draught as ``load_ais`` counts them: the file's reports less
those of the rows written), in ``_dimension_reports/``: ``stats`` counts a vessel's reports
over the whole files, so it finds hers there. Reading the dataset with a query gives the
positions and ``stats`` that reading the files with that query (and the ingest query) gives;
the README ("`colregs9 ingest`: datasets") says where they differ.

Ingest streams: each input is read block by block (``load.stream_ais``; NMEA is decoded
whole) and its rows are spilled to per-hour Arrow files in a staging directory inside
``OUT``; once every input is read, each input's hours are sorted, cleared of duplicates and
appended to their date's file in turn, so that memory holds about one hour of an input (and
the staging directories hold every input of the ingest). The positions of NMEA inputs first
take the static fields they lack from the static reports of every NMEA input of the ingest
(``static_join``: a log split by day). An input's files are moved into place and the
manifest rewritten (atomically) only once the whole input is written: an input is in the
dataset whole, or not at all. An input whose sha256 the manifest already lists is skipped.
"""

from __future__ import annotations

import dataclasses
import fcntl
import os
import secrets
import shutil
import sys
from collections import defaultdict
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from .. import __version__
from ..ais.counting import PARTS_BEFORE_MERGE
from ..ais.dataset_scan import (
    DATASET_FORMAT,
    FORMAT_VERSION,
    MANIFEST_NAME,
    REPORTS_DIR,
    UNDATED,
    Dataset,
    DatasetInput,
    is_dataset,
    manifest_schema,
    ms_date,
    read_manifest,
)
from ..ais.dataset_window import (
    dataset_time_range,
    drop_duplicates,
    read_dataset_window,
    read_window_counted,
)
from ..ais.dimension_reports import NO_REPORTS, rows_reports, sum_counts
from ..ais.inputs import InputFile, no_positions_error
from ..ais.layouts import NMEA as NMEA_LAYOUT
from ..ais.layouts import check_format
from ..ais.ledger import RejectReason, RejectsLedger
from ..ais.load import StreamedInput, stream_ais
from ..ais.schema import CANONICAL_SCHEMA
from ..ais.sources import Source, inspect_source, sha256_file
from ..ais.static_join import STATIC_COLUMNS, fill_statics
from ..ais.time_sources import ingest_params
from ..errors import Colregs9Error, InputFileError, OutputError, ParameterError
from ..outputs import report_manifest, write_json
from ..progress import ProgressSink, progress_bar, progress_enabled
from ..provenance import query_manifest
from ..query import Query, everything_query, load_query

__all__ = [
    "IngestResult",
    "IngestedInput",
    "dataset_time_range",
    "ingest",
    "ingest_with_query",
    "is_dataset",
    "read_dataset_window",
    "read_window_counted",
]

ROW_GROUP_ROWS = 64 * 1024
FILE_ROWS = 64 * ROW_GROUP_ROWS
COMPRESSION = "zstd"
SORT_ORDER = ("hour of timestamp", "floor(lat_deg)", "floor(lon_deg)", "mmsi", "timestamp")
_HOUR_MS = 3_600_000
_UNDATED_HOUR = -1
# Spill files: fast to write and read back, and lz4 halves the staging's disk use.
# Held by the ingest writing the dataset (hidden, so no Parquet engine reads it).
LOCK_NAME = ".colregs9-ingest.lock"
_SPILL_OPTIONS = pa.ipc.IpcWriteOptions(compression="lz4")


@dataclass(frozen=True)
class IngestedInput:
    """One input of an ingest: written now, or found in the manifest (``already``)."""

    path: Path
    sha256: str
    layout: str
    already: bool
    ledger: RejectsLedger
    partitions: dict[str, int]  # date (or UNDATED) -> rows written
    files: tuple[str, ...]  # relative to the dataset
    rows_written: int


@dataclass(frozen=True)
class IngestResult:
    out_dir: Path
    inputs: tuple[IngestedInput, ...]
    text: str


def ingest(
    paths: Sequence[Path],
    out_dir: Path,
    query_path: Path | None = None,
    fmt: str | None = None,
    quiet: bool = True,
    row_group_rows: int = ROW_GROUP_ROWS,
) -> IngestResult:
    """Ingest AIS files into the dataset ``out_dir`` (created if needed; see the module
    docstring). ``query_path``: keep only the rows in that query. ``fmt`` forces the layout
    of every file. ``row_group_rows``: rows per Parquet row group.

    Raises ``OutputError`` for an ``out_dir`` that is a file or a non-empty directory that
    is not a dataset, ``InputFileError`` for unreadable inputs, an input without any usable
    AIS position (as ``load_ais`` refuses one, naming it; its rows are then not written,
    those of the inputs before it are), or a dataset that ``Dataset.open`` refuses (a broken
    manifest, a Parquet file it does not list, a file of another schema), checked before
    any input is read.
    """
    query = load_query(query_path) if query_path is not None else everything_query()
    if query.has_replay_tables:
        from .replay_params import stage_tables

        stage_tables(query)
    return ingest_with_query(paths, out_dir, query, fmt, quiet, row_group_rows, refuse_empty=True)


def ingest_with_query(
    paths: Sequence[Path],
    out_dir: Path,
    query: Query,
    fmt: str | None = None,
    quiet: bool = True,
    row_group_rows: int = ROW_GROUP_ROWS,
    refuse_empty: bool = False,
) -> IngestResult:
    """``ingest`` with the query already loaded (replay ingests its files this way).
    ``refuse_empty``: refuse an input without any usable AIS position (``ingest`` does;
    replay refuses its inputs together, as ``load_ais`` does)."""
    check_format(fmt)
    if row_group_rows < 1:
        raise ParameterError(f"row_group_rows {row_group_rows}: give 1 or more")
    if not paths:
        raise InputFileError("no AIS input files given; name at least one file")
    out_dir = Path(out_dir)
    # Refuse a bad --out, query or input before creating anything.
    _dataset_inputs(out_dir)
    ingest_params(query)
    sources = [inspect_source(Path(p)) for p in paths]
    created = not out_dir.exists()
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _output_error(out_dir, exc) from None
    try:
        with _ingest_lock(out_dir, quiet):
            return _ingest_locked(sources, out_dir, query, fmt, quiet, row_group_rows, refuse_empty)
    except BaseException:
        if created and not (out_dir / MANIFEST_NAME).exists():
            shutil.rmtree(out_dir, ignore_errors=True)  # nothing ingested: leave no directory
        raise


@contextmanager
def _ingest_lock(out_dir: Path, quiet: bool) -> Iterator[None]:
    """One ingest at a time into a dataset: each rewrites the manifest from the one it read,
    so two at once would lose an input. A second ingest waits for the first."""
    try:
        handle = (out_dir / LOCK_NAME).open("a")
    except OSError as exc:
        raise _output_error(out_dir, exc) from None
    with handle:
        try:
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                if not quiet:
                    print(
                        f"Waiting for another colregs9 ingest into {out_dir} ...", file=sys.stderr
                    )
                fcntl.flock(handle, fcntl.LOCK_EX)
        except OSError as exc:
            raise OutputError(
                f"{out_dir}: cannot lock the dataset for the ingest ({exc.strerror or exc}); "
                "give a dataset on a file system that supports locks"
            ) from None
        # Staging left by an ingest that was killed: no other ingest can be running now.
        for stale in out_dir.glob(".ingest-*"):
            shutil.rmtree(stale, ignore_errors=True)
        yield


def _ingest_locked(
    sources: Sequence[Source],
    out_dir: Path,
    query: Query,
    fmt: str | None,
    quiet: bool,
    row_group_rows: int,
    refuse_empty: bool,
) -> IngestResult:
    entries = [item.entry for item in _dataset_inputs(out_dir)]
    known = {entry["sha256"]: entry for entry in entries}
    hashes = [sha256_file(source.path) for source in sources]
    for source, sha256 in zip(sources, hashes, strict=True):
        if sha256 in known:
            _check_same_query(source.path, known[sha256], query)
    new: dict[str, Source] = {}
    for source, sha256 in zip(sources, hashes, strict=True):
        if sha256 not in known:
            new.setdefault(sha256, source)
    if is_dataset(out_dir):  # as stats and replay check it: no file it does not list
        Dataset.open(out_dir, leftovers=[f"{_prefix(h)}-" for h in new])
    staged: list[_Staged] = []
    try:
        try:
            total = float(sum(s.size_bytes for s in new.values()))
            with progress_bar("Reading AIS", total, progress_enabled(quiet), in_bytes=True) as bar:
                for sha256, source in new.items():
                    staged.append(_stage(source, sha256, out_dir, query, fmt, bar, refuse_empty))
        except Colregs9Error:
            # The inputs before a bad one are ingested, as they would be without it.
            _install_staged(staged, out_dir, query, entries, row_group_rows, quiet)
            raise
        _install_staged(staged, out_dir, query, entries, row_group_rows, quiet)
    finally:
        for item in staged:
            shutil.rmtree(item.staging, ignore_errors=True)
    by_hash = {entry["sha256"]: entry for entry in entries}
    results = []
    for source, sha256 in zip(sources, hashes, strict=True):
        first = new.pop(sha256, None) is not None  # a file given twice is ingested once
        entry = by_hash[sha256]
        results.append(_ingested(entry) if first else _already(source.path, entry))
    inputs = tuple(results)
    return IngestResult(out_dir, inputs, _summary(out_dir, inputs, entries))


def _check_same_query(path: Path, entry: dict[str, Any], query: Query) -> None:
    """A dataset holds each input once, under the query it was ingested with."""
    kept = ("region", "time", "vessels")
    stored = entry.get("query") or {}
    wanted = query_manifest(query)
    if any(stored.get(key) != wanted[key] for key in kept):
        raise ParameterError(
            f"{path}: already in the dataset (sha256 {entry['sha256'][:16]}…), ingested under "
            f"the query {stored.get('name')!r}, not {query.name!r}; a dataset holds each input "
            "once: ingest into another dataset for another query"
        )


def _dataset_inputs(out_dir: Path) -> list[DatasetInput]:
    """The inputs of the dataset ``out_dir``, or none for a new or empty directory."""
    if out_dir.exists() and not out_dir.is_dir():
        raise OutputError(
            f"{out_dir}: --out is a file, not a directory; give a new directory or a dataset"
        )
    if (out_dir / MANIFEST_NAME).exists():
        return read_manifest(out_dir)
    ours = (LOCK_NAME, ".ingest-")  # the lock, and staging a killed ingest left
    report = report_manifest(out_dir) if out_dir.is_dir() else None
    if report is not None:  # a dataset is added to, never mixed with a report
        raise OutputError(
            f"{out_dir}: --out holds a colregs9 {report.get('command')} report, not a dataset; "
            "give a new or empty directory, or a dataset made by colregs9 ingest"
        )
    if out_dir.is_dir() and any(not p.name.startswith(ours) for p in out_dir.iterdir()):
        raise OutputError(
            f"{out_dir}: --out holds files but no {MANIFEST_NAME}, so it is not a colregs9 "
            "dataset; give a new or empty directory, or a dataset made by colregs9 ingest"
        )
    return []


def _output_error(out_dir: Path, exc: OSError) -> OutputError:
    where = exc.filename if exc.filename else out_dir
    return OutputError(
        f"{out_dir}: cannot write the dataset ({exc.strerror or exc} at {where}); check the "
        "path, the free space and the permissions, or give another --out"
    )


@dataclass(frozen=True)
class _Staged:
    """A new input read into its staging directory inside the dataset, to be written."""

    source: Source
    sha256: str
    staging: Path
    spill: _Spill
    streamed: StreamedInput


def _stage(
    source: Source,
    sha256: str,
    out_dir: Path,
    query: Query,
    fmt: str | None,
    bar: ProgressSink,
    refuse_empty: bool,
) -> _Staged:
    """Read one input into a staging directory (removed again if it fails).
    ``refuse_empty``: ``InputFileError`` for an input without any usable AIS position (none
    in the query, none outside it; static reports alone are none, as ``load_ais`` tells)."""
    try:
        staging = out_dir / f".ingest-{secrets.token_hex(6)}"
        staging.mkdir()
    except OSError as exc:
        raise _output_error(out_dir, exc) from None
    try:
        spill = _Spill(staging / "spill", count_reports=not _of_everything(query))
        streamed = stream_ais(source, spill, query, fmt, bar)
        if streamed.sha256 != sha256:
            raise InputFileError(
                f"{source.name}: the file changed while it was being ingested; ingest it again "
                "once it is complete"
            )
        ledger = streamed.ledger
        if refuse_empty and not spill.position_rows and not ledger.rows_outside_query:
            read = InputFile(source.path, sha256, streamed.layout, ledger.rows_read)
            raise no_positions_error([read], ledger, query)
    except OSError as exc:
        shutil.rmtree(staging, ignore_errors=True)
        raise _output_error(out_dir, exc) from None
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return _Staged(source, sha256, staging, spill, streamed)


def _of_everything(query: Query) -> bool:
    """A query that keeps every row: nothing lies outside it."""
    return query.region is None and query.time.unbounded and query.vessels.selects_all


def _install_staged(
    staged: Sequence[_Staged],
    out_dir: Path,
    query: Query,
    entries: list[dict[str, Any]],
    row_group_rows: int,
    quiet: bool,
) -> None:
    """Write the inputs read, one after the other, each moved into the dataset and added
    to the manifest (``entries``) once whole. The positions of each NMEA input get the
    static fields they lack from the static reports of all (``static_join``)."""
    nmea = [item.streamed.layout == NMEA_LAYOUT.name for item in staged]
    statics = None
    if sum(nmea) > 1:  # one file's reports were joined to its positions as it was read
        parts = [
            item.spill.read("statics", hour).select(STATIC_COLUMNS)
            for item, is_nmea in zip(staged, nmea, strict=True)
            if is_nmea
            for hour in item.spill.hours("statics")
        ]
        statics = pa.concat_tables(parts) if parts else None
    for item, is_nmea in zip(staged, nmea, strict=True):
        joined = statics if is_nmea else None
        entries.append(_write_staged(item, out_dir, query, row_group_rows, quiet, joined))
        _write_manifest(out_dir, entries)


def _write_staged(
    item: _Staged,
    out_dir: Path,
    query: Query,
    row_group_rows: int,
    quiet: bool,
    statics: pa.Table | None,
) -> dict[str, Any]:
    """Write one input read into its partitions, move its files into the dataset; the
    manifest entry for it. ``statics``: static reports to join to its positions."""
    prefix = _prefix(item.sha256)
    ledger = item.streamed.ledger
    try:
        out = item.staging / "out"
        hours = len(item.spill.files)
        with progress_bar("Writing partitions (hours)", hours, progress_enabled(quiet)) as done:
            written = _write_partitions(
                item.spill, out, prefix, row_group_rows, ledger, done, statics
            )
        outside = item.spill.outside_reports(item.streamed.dimension_reports)
        reports = None
        if outside.num_rows:
            reports = {"path": f"{REPORTS_DIR}/{prefix}.parquet", "rows": outside.num_rows}
            (out / REPORTS_DIR).mkdir(parents=True, exist_ok=True)
            pq.write_table(outside, out / reports["path"], compression=COMPRESSION)
        _install(out, out_dir, prefix, written, reports)
    except OSError as exc:
        raise _output_error(out_dir, exc) from None
    partitions: dict[str, int] = defaultdict(int)
    for w in written:
        partitions[w.date or UNDATED] += w.rows
    return {
        "path": str(item.source.path),
        "format_version": FORMAT_VERSION,  # its files (dataset_scan.FILE_SCHEMAS)
        "sha256": item.sha256,
        "size_bytes": item.source.size_bytes,
        "layout": item.streamed.layout,
        "query": query_manifest(query),
        "rows_read": ledger.rows_read,
        "ledger": ledger.to_dict(),
        "rows_written": sum(w.rows for w in written),
        "static_rows": sum(w.static_rows for w in written),
        "partitions": dict(sorted(partitions.items())),
        "files": [
            {"path": w.path, "date": w.date, "rows": w.rows, "static_rows": w.static_rows}
            for w in written
        ],
        "outside_query_reports": reports,
        "ingested_utc": datetime.now(UTC).isoformat(timespec="seconds"),
    }


class _Spill:
    """The ``RowSink`` of an ingest: each block's rows go to Arrow files, one directory per
    (kind, hour), so that an hour can be read back alone. ``count_reports``: count the
    dimension reports of the rows handed on, to tell those of the rows the query left out
    (``outside_reports``)."""

    def __init__(self, directory: Path, count_reports: bool) -> None:
        self.directory = directory
        self.files: dict[tuple[str, int], list[Path]] = defaultdict(list)
        self.position_rows = 0
        self.count_reports = count_reports
        self._handed: list[pa.Table] = []  # their dimension reports, counted -1 each
        directory.mkdir()

    def positions(self, table: pa.Table) -> None:
        self.position_rows += table.num_rows
        self._write("positions", table)

    def statics(self, table: pa.Table) -> None:
        self._write("statics", table)

    def outside_reports(self, reports: pa.Table) -> pa.Table:
        """The file's dimension ``reports`` (``StreamedInput.dimension_reports``) less those
        of the rows handed on: the reports of the rows outside the query, sorted."""
        if not self.count_reports:
            return NO_REPORTS
        outside = sum_counts([reports, *self._handed])
        outside = outside.filter(pc.not_equal(outside.column("n_reports"), 0))
        return outside.sort_by([(name, "ascending") for name in outside.column_names])

    def _write(self, kind: str, table: pa.Table) -> None:
        if table.num_rows == 0:
            return
        if self.count_reports:
            self._handed.append(rows_reports(table, -1))
            if len(self._handed) >= PARTS_BEFORE_MERGE:
                self._handed = [sum_counts(self._handed)]
        hours = _hours(table)
        order = np.argsort(hours, kind="stable")
        bounds = np.flatnonzero(np.diff(hours[order])) + 1
        for rows in np.split(order, bounds):
            hour = int(hours[rows[0]])
            folder = self.directory / f"{kind}{hour}"
            if not self.files[(kind, hour)]:
                folder.mkdir()
            path = folder / f"{len(self.files[(kind, hour)]):08d}.arrow"
            piece = table if len(rows) == table.num_rows else table.take(pa.array(rows))
            with pa.ipc.new_file(path, CANONICAL_SCHEMA, options=_SPILL_OPTIONS) as writer:
                writer.write_table(piece)
            self.files[(kind, hour)].append(path)

    def read(self, kind: str, hour: int) -> pa.Table:
        """The rows spilled for (kind, hour), in the order they were read."""
        tables = [pa.ipc.open_file(path).read_all() for path in self.files[(kind, hour)]]
        return pa.concat_tables(tables)

    def hours(self, kind: str) -> list[int]:
        return sorted(hour for k, hour in self.files if k == kind)


def _hours(table: pa.Table) -> np.ndarray:
    """Each row's hour since the epoch; ``_UNDATED_HOUR`` for a null timestamp."""
    stamps = table.column("timestamp")
    milliseconds = pc.fill_null(stamps.cast(pa.int64()), _UNDATED_HOUR * _HOUR_MS).to_numpy()
    return np.asarray(milliseconds // _HOUR_MS, dtype=np.int64)


def _hour_date(hour: int) -> str | None:
    return None if hour == _UNDATED_HOUR else ms_date(hour * _HOUR_MS).isoformat()


@dataclass(frozen=True)
class _Written:
    path: str  # relative to the dataset
    date: str | None
    rows: int
    static_rows: int


@dataclass
class _Duplicates:
    """The duplicates dropped, and the first of them in (mmsi, timestamp) order, as
    ``load_ais`` quotes it."""

    count: int = 0
    first: tuple[int, int] | None = None

    def add(self, dropped: pa.Table) -> None:
        if dropped.num_rows == 0:
            return
        self.count += dropped.num_rows
        keys = zip(
            dropped.column("mmsi").to_pylist(),
            dropped.column("timestamp").cast(pa.int64()).to_pylist(),
            strict=True,
        )
        low = min(keys)
        self.first = low if self.first is None else min(self.first, low)

    def record(self, ledger: RejectsLedger) -> None:
        if self.first is None:
            return
        mmsi, milliseconds = self.first
        stamp = pd.Timestamp(milliseconds, unit="ms", tz="UTC")
        ledger.reject(
            RejectReason.DUPLICATE,
            self.count,
            example=f"MMSI {mmsi} at {stamp}: repeated row",
        )


def _write_partitions(
    spill: _Spill,
    staging: Path,
    prefix: str,
    row_group_rows: int,
    ledger: RejectsLedger,
    bar: ProgressSink,
    statics: pa.Table | None = None,
) -> list[_Written]:
    """Write the spilled rows into date partitions under ``staging``, hour by hour; the
    positions written are used in ``ledger`` and their duplicates rejected. ``statics``:
    static reports whose fields the positions lacking them take (``static_join``)."""
    dates: dict[str | None, dict[str, list[int]]] = defaultdict(lambda: defaultdict(list))
    for kind in ("positions", "statics"):
        for hour in spill.hours(kind):
            dates[_hour_date(hour)][kind].append(hour)
    duplicates = _Duplicates()
    written: list[_Written] = []
    for day in sorted(dates, key=lambda d: (d is None, d or "")):
        writer = _PartitionWriter(staging, day, prefix, row_group_rows)
        for hour in dates[day]["positions"]:
            table = spill.read("positions", hour)
            if statics is not None:
                table = fill_statics(table, statics)
            table, dropped = drop_duplicates(_sort_for_pruning(table))
            duplicates.add(dropped)
            ledger.use(table.num_rows)
            writer.write(table, static=False)
            bar.advance()
        for hour in dates[day]["statics"]:
            writer.write(_sort_for_pruning(spill.read("statics", hour)), static=True)
            bar.advance()
        written.extend(writer.close())
    duplicates.record(ledger)
    return written


class _PartitionWriter:
    """The files of one input in one date partition: a new file at an hour boundary once
    the current one holds ``FILE_ROWS``."""

    def __init__(self, staging: Path, day: str | None, prefix: str, row_group_rows: int) -> None:
        self.folder = f"date={day if day is not None else UNDATED}"
        (staging / self.folder).mkdir(parents=True)
        self.staging = staging
        self.day = day
        self.prefix = prefix
        self.row_group_rows = row_group_rows
        self.written: list[_Written] = []
        self._writer: pq.ParquetWriter | None = None
        self._rows = 0
        self._static_rows = 0

    def write(self, table: pa.Table, static: bool) -> None:
        if self._writer is None or self._rows >= FILE_ROWS:
            self._close_file()
            name = f"{self.folder}/{self.prefix}-{len(self.written)}.parquet"
            self._writer = pq.ParquetWriter(
                self.staging / name, CANONICAL_SCHEMA, compression=COMPRESSION
            )
            self.written.append(_Written(name, self.day, 0, 0))
        # One write per hour: row groups never span two hours, nor positions and statics.
        self._writer.write_table(table, row_group_size=self.row_group_rows)
        self._rows += table.num_rows
        self._static_rows += table.num_rows if static else 0

    def _close_file(self) -> None:
        if self._writer is None:
            return
        self._writer.close()
        last = self.written[-1]
        self.written[-1] = _Written(last.path, last.date, self._rows, self._static_rows)
        self._writer, self._rows, self._static_rows = None, 0, 0

    def close(self) -> list[_Written]:
        self._close_file()
        return self.written


def _sort_for_pruning(table: pa.Table) -> pa.Table:
    """Rows of one hour in the files' order: floor(lat_deg), floor(lon_deg), mmsi,
    timestamp (a stable sort: rows alike keep the order they were read in)."""
    keys = pa.table(
        {
            "lat_bin": pc.floor(table.column("lat_deg")),
            "lon_bin": pc.floor(table.column("lon_deg")),
            "mmsi": table.column("mmsi"),
            "timestamp": table.column("timestamp"),
        }
    )
    # Nulls (the static reports' bins) sort last.
    order = pc.sort_indices(keys, sort_keys=[(name, "ascending") for name in keys.column_names])
    return table.take(order)


def _prefix(sha256: str) -> str:
    """The start of the names of an input's files (``part-<sha16>``)."""
    return f"part-{sha256[:16]}"


def _install(
    staging: Path,
    out_dir: Path,
    prefix: str,
    written: list[_Written],
    reports: dict[str, Any] | None,
) -> None:
    """Move the input's files (and ``reports``, its dimension reports outside the query)
    into the dataset, replacing what an interrupted ingest of the same input may have left
    (its files bear its name but are in no manifest)."""
    for leftover in out_dir.glob(f"date=*/{prefix}-*.parquet"):
        leftover.unlink()
    paths = [item.path for item in written] + ([reports["path"]] if reports else [])
    for path in paths:
        target = out_dir / path
        target.parent.mkdir(exist_ok=True)
        os.replace(staging / path, target)


def _write_manifest(out_dir: Path, entries: list[dict[str, Any]]) -> None:
    manifest = {
        "format": DATASET_FORMAT,
        "format_version": FORMAT_VERSION,
        "tool": "colregs9",
        "version": __version__,
        "schema": manifest_schema(),
        "partitioning": {"flavor": "hive", "field": "date", "type": "date32", "null": UNDATED},
        "sort_order": list(SORT_ORDER),
        "static_reports": "after the positions of each file, lat_deg and lon_deg null",
        "outside_query_reports": f"{REPORTS_DIR}/part-<sha16>.parquet: the dimension reports "
        "(mmsi, length_m, breadth_m, draught_m, n_reports) of the rows the ingest query left out",
        "compression": COMPRESSION,
        "inputs": entries,
    }
    write_json(out_dir / MANIFEST_NAME, manifest)


def _already(path: Path, entry: dict[str, Any]) -> IngestedInput:
    return dataclasses.replace(_ingested(entry), path=path, already=True)


def _ingested(entry: dict[str, Any]) -> IngestedInput:
    return IngestedInput(
        path=Path(entry["path"]),
        sha256=entry["sha256"],
        layout=entry["layout"],
        already=False,
        ledger=RejectsLedger.from_dict(entry["ledger"]),
        partitions=dict(entry["partitions"]),
        files=tuple(f["path"] for f in entry["files"]),
        rows_written=int(entry["rows_written"]),
    )


def _summary(
    out_dir: Path, inputs: tuple[IngestedInput, ...], entries: list[dict[str, Any]]
) -> str:
    lines = []
    for item in inputs:
        if item.already:
            lines.append(f"{item.path}: already ingested (sha256 {item.sha256[:16]}…), skipped")
            continue
        lines.append(f"{item.path} ({item.layout}): {item.rows_written} rows written")
        for day, rows in item.partitions.items():
            lines.append(f"  date={day}: {rows} rows")
        ledger = item.ledger
        reasons = ", ".join(f"{k} {v}" for k, v in sorted(ledger.rejects.items())) or "none"
        lines.append(
            f"  ledger: {ledger.rows_read} read, {ledger.rows_used} used, "
            f"{ledger.rows_outside_query} outside the query, {ledger.rejected_total} rejected "
            f"({reasons})"
        )
    ingested = sum(not item.already for item in inputs)
    partitions = {day for entry in entries for day in entry["partitions"]}
    rows = sum(int(entry["rows_written"]) for entry in entries)
    lines.append(
        f"{ingested} input(s) ingested, {len(inputs) - ingested} already ingested; the dataset "
        f"{out_dir} holds {len(entries)} input(s), {rows} rows in {len(partitions)} partition(s)"
    )
    return "\n".join(lines) + "\n"
