"""Reading a Parquet dataset made by ``colregs9 ingest``: its manifest, its files, its scans.

A dataset is a directory holding ``colregs9-dataset.json`` (the manifest) and Parquet files
in the canonical schema under hive partitions ``date=YYYY-MM-DD/`` (``date=__HIVE_DEFAULT_
PARTITION__/`` for static reports whose time does not parse). See ``dataset.py`` for how it
is written. Opening one (``Dataset.open``) checks it whole against its manifest, from the
manifest and the files' footers only: every listed file is there with the canonical schema
(of its input's format version) and the row count listed, and no other Parquet file lies in
it. The scans are ``pyarrow.dataset`` scans with the query pushed down: the time window
prunes partitions and, with the region, row groups by their statistics; only the columns
asked for are decoded. ``Dataset.row_groups`` reads whole row groups instead, told apart by
their statistics (``Positions``), with Parquet's own reader.

Format versions: 3 adds to each input ingested through a query the dimension reports of its
rows that the query left out (``_dimension_reports/part-<sha16>.parquet``, listed in the
manifest as ``outside_query_reports``: counts by MMSI, length, breadth and draught, as
``dimension_reports`` counts them), which ``stats`` adds to those of the rows the dataset
holds, so that a vessel's dimensions do not depend on the ingest query; 2 has the canonical
schema with AIS's A, B, C, D (``to_bow_m`` ...); 1, from before, lacks those four columns. An
input of version 1 or 2 has no such reports (re-ingest it to have them). A version 1
dataset, or a later one holding inputs ingested as version 1 (an ingest into an older
dataset upgrades its manifest), is read with the four null for those inputs' rows: the
scans fill a column a file lacks with nulls. Re-ingesting its inputs gives them their A, B,
C, D.

Used by ``load.load_ais`` (so a dataset is accepted wherever AIS files are) and by
``dataset.py``; it imports neither.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from datetime import UTC, date, datetime, timedelta
from enum import Enum
from functools import partial
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.dataset as ds
import pyarrow.parquet as pq

from ..errors import InputFileError
from ..query import Query, ms_at_or_after
from .dimension_reports import NO_REPORTS
from .ledger import RejectsLedger
from .query_rows import rows_in_query
from .schema import ANTENNA_OFFSETS, CANONICAL_COLUMNS, CANONICAL_SCHEMA

MANIFEST_NAME = "colregs9-dataset.json"
DATASET_FORMAT = "colregs9-dataset"
FORMAT_VERSION = 3
# The schema of the files of each format version: 1 had no A, B, C, D; 3 added the
# dimension reports outside the ingest query, in files of their own.
FILE_SCHEMAS: dict[int, pa.Schema] = {
    1: pa.schema([f for f in CANONICAL_SCHEMA if f.name not in ANTENNA_OFFSETS]),
    2: CANONICAL_SCHEMA,
    FORMAT_VERSION: CANONICAL_SCHEMA,
}
# Where an input's dimension reports outside its ingest query go, and their schema.
REPORTS_DIR = "_dimension_reports"
REPORTS_SCHEMA = NO_REPORTS.schema
PARTITION_FIELD = pa.field("date", pa.date32())
# The hive convention for a null partition value (Spark, DuckDB and polars read it so too).
UNDATED = "__HIVE_DEFAULT_PARTITION__"
DATASET_SCHEMA = CANONICAL_SCHEMA.append(PARTITION_FIELD)
_PARTITIONING = ds.HivePartitioning(pa.schema([PARTITION_FIELD]), null_fallback=UNDATED)
_EPOCH = datetime(1970, 1, 1, tzinfo=UTC)
_REMEDY = "re-create the dataset with colregs9 ingest"
# A scan reads ahead this many batches of one file at a time: pyarrow's default (16 batches of
# 4 files) held much more memory and was no faster (tests/benchmarks/README.md, "Figures
# moved from code comments").
_BATCH_READAHEAD = 4
_FRAGMENT_READAHEAD = 1
# Row groups read at once by ``Dataset.row_groups`` (ingest's hold 65,536 rows): fewer or
# more were slower (tests/benchmarks/README.md, "the counts read without the coordinates").
_ROW_GROUPS_READ = 4


def is_dataset(path: Path) -> bool:
    """A directory with a dataset manifest (it may still prove broken when opened)."""
    return Path(path).is_dir() and (Path(path) / MANIFEST_NAME).is_file()


def manifest_schema(version: int = FORMAT_VERSION) -> list[dict[str, str]]:
    """The files' schema of a format version (default: this colregs9's, the canonical schema)
    as the manifest records it."""
    return [{"name": f.name, "type": str(f.type)} for f in FILE_SCHEMAS[version]]


def utc_ms(moment: datetime) -> int:
    """Milliseconds since the epoch, the schema's unit: the first at or after ``moment``
    (``query.ms_at_or_after``, as ``query_rows`` tests a window)."""
    return ms_at_or_after(moment)


def ms_date(milliseconds: int) -> date:
    return (_EPOCH + timedelta(milliseconds=milliseconds)).date()


@dataclass(frozen=True)
class DatasetFile:
    """One Parquet file: its path relative to the dataset, partition date (None: undated)
    and rows."""

    path: str
    date: str | None
    rows: int


@dataclass(frozen=True)
class DatasetInput:
    """One ingested input as the manifest records it (``entry``: the whole record, with its
    ``format_version``, which a version 1 manifest leaves out)."""

    path: str
    sha256: str
    layout: str
    rows_read: int
    ledger: RejectsLedger
    files: tuple[DatasetFile, ...]
    entry: dict[str, Any]
    format_version: int = FORMAT_VERSION
    # The file of its dimension reports outside the ingest query (``REPORTS_DIR``), if any.
    outside_query_reports: DatasetFile | None = None


def read_manifest(directory: Path) -> list[DatasetInput]:
    """The inputs the dataset manifest in ``directory`` lists, checked; ``InputFileError``
    for a missing, unreadable or malformed manifest."""
    path = Path(directory) / MANIFEST_NAME
    if path.exists() and not path.is_file():  # a pipe's read would block
        raise InputFileError(f"{path}: not a file; restore the dataset manifest, or {_REMEDY}")
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputFileError(
            f"{directory}: a directory without {MANIFEST_NAME}, so not a colregs9 dataset; "
            "give AIS files, or a dataset directory made by colregs9 ingest"
        ) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputFileError(
            f"{path}: cannot read the dataset manifest ({exc}); {_REMEDY}"
        ) from None
    try:
        manifest = json.loads(text)
    except ValueError as exc:
        raise InputFileError(
            f"{path}: the dataset manifest is not valid JSON ({exc}); restore it, or {_REMEDY}"
        ) from None
    except RecursionError:  # JSON nested thousands deep, which no manifest is
        raise InputFileError(
            f"{path}: the manifest is nested too deeply to be one; restore it, or {_REMEDY}"
        ) from None
    if not isinstance(manifest, dict) or manifest.get("format") != DATASET_FORMAT:
        raise InputFileError(f"{path}: not a colregs9 dataset manifest; {_REMEDY}")
    version = manifest.get("format_version")
    if version not in FILE_SCHEMAS:
        raise InputFileError(
            f"{path}: dataset format version {version!r}, this colregs9 reads versions "
            f"{', '.join(map(str, FILE_SCHEMAS))}; use the colregs9 that wrote it, or {_REMEDY}"
        )
    if manifest.get("schema") != manifest_schema(version):
        raise InputFileError(
            f"{path}: the manifest's schema is not the canonical schema of format version "
            f"{version}; {_REMEDY}"
        )
    entries = manifest.get("inputs")
    if not isinstance(entries, list):
        raise InputFileError(f"{path}: the manifest has no list of inputs; {_REMEDY}")
    inputs = []
    for number, entry in enumerate(entries, start=1):
        try:
            inputs.append(_input(entry, version))
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise InputFileError(
                f"{path}: input {number} of the manifest is malformed ({exc!r}); {_REMEDY}"
            ) from None
    return inputs


def _input(entry: dict[str, Any], manifest_version: int) -> DatasetInput:
    if manifest_version == 1:  # its inputs are all of version 1, which wrote no such key
        entry = {**entry, "format_version": 1}
    version = entry["format_version"]
    if version not in FILE_SCHEMAS or version > manifest_version:
        raise ValueError(f"format_version {version!r} is not a version of its manifest's")
    files = tuple(
        DatasetFile(str(f["path"]), None if f["date"] is None else str(f["date"]), int(f["rows"]))
        for f in entry["files"]
    )
    ledger = RejectsLedger.from_dict(entry["ledger"])
    written = int(entry["rows_written"])
    if written != sum(f.rows for f in files) or written != ledger.rows_used:
        raise ValueError("rows_written does not match its files and its ledger")
    partitions = {str(day): int(rows) for day, rows in entry["partitions"].items()}
    if sum(partitions.values()) != written:
        raise ValueError("partitions do not add up to rows_written")
    if not isinstance(entry["sha256"], str) or not re.fullmatch(r"[0-9a-f]{64}", entry["sha256"]):
        raise ValueError(f"sha256 {entry['sha256']!r} is not a SHA-256 in hex")
    return DatasetInput(
        path=str(entry["path"]),
        sha256=str(entry["sha256"]),
        layout=str(entry["layout"]),
        rows_read=ledger.rows_read,
        ledger=ledger,
        files=files,
        entry=entry,
        format_version=version,
        outside_query_reports=_listed_reports(entry, version),
    )


def _listed_reports(entry: dict[str, Any], version: int) -> DatasetFile | None:
    """The file of an input's dimension reports outside its ingest query, as its manifest
    entry lists it (format version 3 on; null where the query left none out)."""
    listed = entry["outside_query_reports"] if version >= 3 else None
    if listed is None:
        return None
    return DatasetFile(str(listed["path"]), None, int(listed["rows"]))


class Positions(Enum):
    """Row groups told apart by the null counts of latitude and longitude in their
    statistics (the footers: nothing decoded). A row has a position when it has both, as
    the pushdown has it (``position_filter``). ``colregs9 ingest`` writes positions and
    static reports in row groups of their own, so a read that only needs to tell them apart
    need not decode the coordinates (``Dataset.row_groups``)."""

    ALL = "all"  # every row has a position
    NONE = "none"  # no row has one
    SOME = "some"  # the others, and those whose statistics lack null counts


@dataclass(frozen=True)
class Dataset:
    """An opened, checked dataset (see the module docstring)."""

    directory: Path
    inputs: tuple[DatasetInput, ...]
    arrow: ds.FileSystemDataset
    static_rows: int  # rows without a position (static reports), from the footers

    @classmethod
    def open(cls, directory: Path, leftovers: Sequence[str] = ()) -> Dataset:
        """Open and check the dataset ``directory``: ``InputFileError`` naming the first
        file that does not agree with the manifest. ``leftovers``: file name prefixes
        (``part-<sha16>-``) of inputs an ingest is about to write again, whose unlisted files
        an interrupted ingest may have left (the ingest replaces them)."""
        directory = Path(directory)
        inputs = tuple(read_manifest(directory))
        listed = [f for item in inputs for f in item.files]
        versions = [item.format_version for item in inputs for _ in item.files]
        names = {f.path for f in listed}
        for found in sorted(directory.rglob("*.parquet")):
            relative = found.relative_to(directory)
            if (
                relative.as_posix() not in names
                and not _hidden(relative)
                and not found.name.startswith(tuple(leftovers))
            ):
                raise InputFileError(
                    f"{found}: a Parquet file the dataset manifest does not list (a dataset "
                    "holds only what colregs9 ingest wrote); move it out of the dataset, or "
                    "ingest its source"
                )
        for listed_file in listed:
            if not (directory / listed_file.path).is_file():
                raise InputFileError(
                    f"{directory / listed_file.path}: listed in the dataset manifest but "
                    f"missing; restore it, or {_REMEDY}"
                )
        try:
            arrow = ds.dataset(
                [str(directory / f.path) for f in listed],
                schema=DATASET_SCHEMA,
                format="parquet",
                partitioning=_PARTITIONING,
                partition_base_dir=str(directory),
            )
        except (pa.ArrowException, OSError) as exc:
            raise InputFileError(
                f"{directory}: cannot open the dataset ({exc}); {_REMEDY}"
            ) from None
        static_rows = sum(
            _check_fragment(fragment, listed_file, directory / listed_file.path, version)
            for fragment, listed_file, version in zip(
                arrow.get_fragments(), listed, versions, strict=True
            )
        )
        for item in inputs:
            if item.outside_query_reports is not None:
                _check_reports(directory, item.outside_query_reports)
        return cls(directory, inputs, arrow, static_rows)

    @property
    def rows(self) -> int:
        return sum(f.rows for item in self.inputs for f in item.files)

    @property
    def size_bytes(self) -> int:
        return sum((self.directory / f.path).stat().st_size for f in self.files)

    @property
    def files(self) -> tuple[DatasetFile, ...]:
        return tuple(f for item in self.inputs for f in item.files)

    @property
    def duplicate_free(self) -> bool:
        """No two inputs share a partition: ingest dropped each input's exact duplicates,
        and duplicates share their timestamp, hence their partition."""
        dates = [{f.date for f in item.files if f.date is not None} for item in self.inputs]
        return sum(len(d) for d in dates) == len(set().union(*dates))

    def outside_query_reports(self, vessels: Sequence[int]) -> pa.Table:
        """The dimension reports of ``vessels`` that the inputs' ingest queries left out of
        the dataset (``REPORTS_SCHEMA``: counts by MMSI and dimensions, not yet summed
        across inputs); none from inputs of format version 1 or 2."""
        tables = [NO_REPORTS]
        for item in self.inputs:
            if item.outside_query_reports is not None and len(vessels):
                path = self.directory / item.outside_query_reports.path
                try:
                    tables.append(pq.read_table(path, filters=reports_filter(vessels)))
                except (pa.ArrowException, OSError) as exc:
                    raise InputFileError(
                        f"{path}: cannot read the dimension reports ({exc}); {_REMEDY}"
                    ) from None
        return pa.concat_tables(tables)

    def ingest_ledger(self) -> RejectsLedger:
        """The ledgers of the inputs, merged: what reading the files themselves counted."""
        ledger = RejectsLedger()
        for item in self.inputs:
            ledger.merge(item.ledger)
        return ledger

    def scan(self, expression: ds.Expression, columns: Sequence[str]) -> Iterator[pa.Table]:
        """The rows ``expression`` selects, with ``columns``, batch by batch in file order."""
        try:
            for batch in self.arrow.to_batches(
                filter=expression,
                columns=list(columns),
                batch_readahead=_BATCH_READAHEAD,
                fragment_readahead=_FRAGMENT_READAHEAD,
            ):
                if batch.num_rows:
                    yield pa.Table.from_batches([batch])
        except (pa.ArrowException, OSError) as exc:
            raise InputFileError(
                f"{self.directory}: cannot read the dataset ({exc}); {_REMEDY}"
            ) from None

    def row_groups(
        self, positions: Positions, columns: Sequence[str], dictionaries: Sequence[str] = ()
    ) -> Iterator[pa.Table]:
        """Every row of the row groups of the kind ``positions``, with ``columns`` (columns
        that every format version has), a few row groups at a time in file order.
        ``dictionaries``: string columns read as Arrow dictionaries of the Parquet
        dictionaries' values, not as strings. Without a filter, Parquet's own reader
        decodes with less work than a scan; the next row groups are read while the caller
        works on these."""
        try:
            yield from _read_ahead(_row_group_reads(self, positions, columns, dictionaries))
        except (pa.ArrowException, OSError) as exc:
            raise InputFileError(
                f"{self.directory}: cannot read the dataset ({exc}); {_REMEDY}"
            ) from None

    def time_range(self) -> tuple[datetime, datetime] | None:
        """The first and last timestamps of the position rows, from the row groups'
        statistics (row groups of static reports left out); None without positions."""
        spans = self.position_spans_ms()
        if not spans:
            return None
        return _utc(min(s for s, _ in spans)), _utc(max(e for _, e in spans))

    def position_spans_ms(self) -> list[tuple[int, int]]:
        """The first and last timestamps (ms since the epoch) of each row group that holds
        positions, from the statistics alone: where in time the dataset has data."""
        spans = []
        for fragment in self.arrow.get_fragments():
            metadata = fragment.metadata
            # By name: another tool may have written the columns in another order.
            lat = fragment.physical_schema.get_field_index("lat_deg")
            stamp = fragment.physical_schema.get_field_index("timestamp")
            for index in range(metadata.num_row_groups):
                group = metadata.row_group(index)
                lat_stats = group.column(lat).statistics
                stats = group.column(stamp).statistics
                if lat_stats is not None and lat_stats.null_count == group.num_rows:
                    continue
                if stats is None or not stats.has_min_max:
                    raise InputFileError(
                        f"{fragment.path}: row group {index} has no timestamp statistics; {_REMEDY}"
                    )
                spans.append((utc_ms(stats.min), utc_ms(stats.max)))
        return spans


def _utc(milliseconds: int) -> datetime:
    return datetime.fromtimestamp(milliseconds / 1000, UTC)


def _hidden(relative: Path) -> bool:
    """Paths pyarrow's discovery would skip too: an ingest's staging directory."""
    return any(part.startswith((".", "_")) for part in relative.parts)


def _row_group_reads(
    dataset: Dataset, positions: Positions, columns: Sequence[str], dictionaries: Sequence[str]
) -> Iterator[Callable[[], pa.Table]]:
    """The reads of ``Dataset.row_groups``, a few row groups each."""
    for fragment in dataset.arrow.get_fragments():
        kinds = _row_group_positions(fragment)
        wanted = [index for index, kind in enumerate(kinds) if kind is positions]
        for start in range(0, len(wanted), _ROW_GROUPS_READ):
            some = wanted[start : start + _ROW_GROUPS_READ]
            yield partial(_read_row_groups, fragment, some, columns, dictionaries)


def _read_row_groups(
    fragment: ds.ParquetFileFragment,
    groups: Sequence[int],
    columns: Sequence[str],
    dictionaries: Sequence[str],
) -> pa.Table:
    with pq.ParquetFile(
        fragment.path, metadata=fragment.metadata, read_dictionary=dictionaries
    ) as parquet:
        return parquet.read_row_groups(groups, columns=list(columns))


def _read_ahead(reads: Iterator[Callable[[], pa.Table]]) -> Iterator[pa.Table]:
    """The tables of ``reads``, each read on a thread while the caller works on the one
    before."""
    with ThreadPoolExecutor(1) as reader:
        ahead: Future[pa.Table] | None = None
        for read in reads:
            following = reader.submit(read)
            if ahead is not None:
                yield ahead.result()
            ahead = following
        if ahead is not None:
            yield ahead.result()


def _row_group_positions(fragment: ds.ParquetFileFragment) -> list[Positions]:
    """The kind of each row group of ``fragment`` (footer read when the dataset opened)."""
    metadata = fragment.metadata
    # By name: another tool may have written the columns in another order.
    lat = fragment.physical_schema.get_field_index("lat_deg")
    lon = fragment.physical_schema.get_field_index("lon_deg")
    kinds = []
    for index in range(metadata.num_row_groups):
        group = metadata.row_group(index)
        nulls = [group.column(column).statistics for column in (lat, lon)]
        if any(stats is None or not stats.has_null_count for stats in nulls):
            kinds.append(Positions.SOME)
        elif all(stats.null_count == 0 for stats in nulls):
            kinds.append(Positions.ALL)
        elif any(stats.null_count == group.num_rows for stats in nulls):
            kinds.append(Positions.NONE)
        else:
            kinds.append(Positions.SOME)
    return kinds


def _check_fragment(
    fragment: ds.ParquetFileFragment, listed: DatasetFile, path: Path, version: int
) -> int:
    """Read the file's footer (kept for the scans), check it against the manifest and the
    schema of its input's format ``version`` (``FILE_SCHEMAS``), and give its number of
    static rows (null latitudes)."""
    try:
        fragment.ensure_complete_metadata()
        schema = fragment.physical_schema
        metadata = fragment.metadata
    except (pa.ArrowException, OSError) as exc:
        raise InputFileError(f"{path}: not a readable Parquet file ({exc}); {_REMEDY}") from None
    expected_schema = FILE_SCHEMAS[version]
    named = "the canonical schema"
    if version != FORMAT_VERSION:
        named = f"the schema of format version {version}"
    twice = next((name for name in schema.names if schema.names.count(name) > 1), None)
    if twice is not None:
        raise InputFileError(
            f"{path}: has the column {twice!r} {schema.names.count(twice)} times; not a file "
            f"of this dataset: move it out, or {_REMEDY}"
        )
    for expected in expected_schema:
        if expected.name not in schema.names:
            raise InputFileError(
                f"{path}: lacks the column {expected.name!r} of {named}; not a file of this "
                f"dataset: move it out, or {_REMEDY}"
            )
        found = schema.field(expected.name).type
        if found != expected.type:
            raise InputFileError(
                f"{path}: column {expected.name!r} is {found}, {named} has "
                f"{expected.type}; not a file of this dataset: move it out, or {_REMEDY}"
            )
    if len(schema) != len(expected_schema):
        extra = next(name for name in schema.names if name not in expected_schema.names)
        raise InputFileError(
            f"{path}: has the column {extra!r}, which {named} has not; not a "
            f"file of this dataset: move it out, or {_REMEDY}"
        )
    if metadata.num_rows != listed.rows:
        raise InputFileError(
            f"{path}: holds {metadata.num_rows} rows, the manifest lists {listed.rows}; {_REMEDY}"
        )
    lat = schema.get_field_index("lat_deg")
    static = 0
    for index in range(metadata.num_row_groups):
        stats = metadata.row_group(index).column(lat).statistics
        if stats is None:  # a writer without statistics: count them
            return int(fragment.count_rows(filter=ds.field("lat_deg").is_null()))
        static += stats.null_count
    return static


def _check_reports(directory: Path, listed: DatasetFile) -> None:
    """An input's dimension reports outside its ingest query: there, with their schema and
    the rows the manifest lists (from the footer)."""
    path = directory / listed.path
    if not path.is_file():
        raise InputFileError(f"{path}: listed in the dataset manifest but missing; {_REMEDY}")
    try:
        metadata = pq.read_metadata(path)
    except (pa.ArrowException, OSError) as exc:
        raise InputFileError(f"{path}: not a readable Parquet file ({exc}); {_REMEDY}") from None
    if not metadata.schema.to_arrow_schema().equals(REPORTS_SCHEMA):
        raise InputFileError(
            f"{path}: not the dimension reports of this dataset (columns "
            f"{', '.join(REPORTS_SCHEMA.names)}); move it out, or {_REMEDY}"
        )
    if metadata.num_rows != listed.rows:
        raise InputFileError(
            f"{path}: holds {metadata.num_rows} rows, the manifest lists {listed.rows}; {_REMEDY}"
        )


def scan_columns(wanted: Sequence[str], query: Query, ordered: bool = True) -> tuple[str, ...]:
    """The columns to read for ``wanted`` columns of the positions in ``query``: also those
    the query tests, and the sort keys (mmsi, timestamp) when the rows are to be ``ordered``."""
    needed = {*wanted, "mmsi"}
    if ordered or not query.time.unbounded:
        needed.add("timestamp")
    if query.region is not None:
        needed |= {"lat_deg", "lon_deg"}
    if not query.vessels.selects_all:
        needed |= {"mobile_type", "ship_type", "length_m"}
    return tuple(c for c in CANONICAL_COLUMNS if c in needed)


def position_filter(
    query: Query, start_ms: int | None = None, end_ms: int | None = None
) -> ds.Expression:
    """The pushdown of ``query`` (and of ``[start_ms, end_ms)``) for the position rows:
    partitions by date, row groups by the statistics of timestamp, lat_deg, lon_deg, mmsi
    and length_m. Exact for the box, the window and the vessel filter but its ship types;
    the caller still tests the polygon and the ship types."""
    lat, lon = ds.field("lat_deg"), ds.field("lon_deg")
    expression = lat.is_valid() & lon.is_valid()
    region = query.region
    if region is not None:
        expression &= (lat >= region.lat_min) & (lat <= region.lat_max)
        expression &= (lon >= region.lon_min) & (lon <= region.lon_max)
    window = query.time
    starts = [start_ms, None if window.start is None else utc_ms(window.start)]
    ends = [end_ms, None if window.end is None else utc_ms(window.end)]
    stamp, day = ds.field("timestamp"), ds.field("date")
    if any(m is not None for m in starts):
        start = max(m for m in starts if m is not None)
        expression &= (day >= ms_date(start)) & (stamp >= _timestamp(start))
    if any(m is not None for m in ends):
        end = min(m for m in ends if m is not None)
        expression &= (day <= ms_date(end - 1)) & (stamp < _timestamp(end))
    vessels = query.vessels
    mmsi = ds.field("mmsi")
    if vessels.mmsi_include is not None:
        expression &= mmsi.isin(sorted(vessels.mmsi_include))
    if vessels.mmsi_exclude:
        expression &= ~mmsi.isin(sorted(vessels.mmsi_exclude))
    if vessels.mobile_types is not None:
        expression &= ds.field("mobile_type").isin(sorted(vessels.mobile_types))
    if vessels.length_min_m is not None:
        expression &= ds.field("length_m") >= vessels.length_min_m
    if vessels.length_max_m is not None:
        expression &= ds.field("length_m") <= vessels.length_max_m
    return expression


def positions_in_query(
    dataset: Dataset, query: Query, columns: Sequence[str], expression: ds.Expression
) -> Iterator[pa.Table]:
    """The position rows of ``query`` that the scan with ``expression`` (the query's
    pushdown, ``position_filter``, or narrower) selects, batch by batch: the rows of each
    batch outside the query (its polygon, its ship types) are dropped."""
    for table in dataset.scan(expression, columns):
        inside = rows_in_query(table, query)
        yield table if inside.all() else table.filter(pa.array(inside))


def reports_filter(vessels: Sequence[int]) -> ds.Expression:
    """Every row (positions and static reports, any time and place) of these vessels."""
    return ds.field("mmsi").isin(pa.array(vessels, pa.int64()))


def _timestamp(milliseconds: int) -> pa.Scalar:
    return pa.scalar(milliseconds, type=CANONICAL_SCHEMA.field("timestamp").type)
