"""The inputs of a run: the files and datasets given, what each is (``InputFile``: its path,
content hash, layout and rows read, as run.json records them), the rows and ledger a dataset
read in place of its files contributes, and the error of a read that left no position.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pyarrow as pa

from ..errors import InputFileError, NoDataError
from ..progress import ProgressSink
from ..query import Query
from .dimension_reports import cleaned_reports
from .layouts import check_format
from .ledger import EXAMPLE_CHARS, RejectsLedger
from .sources import Source, inspect_source
from .time_sources import ingest_params

if TYPE_CHECKING:
    from .dataset_scan import Dataset


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


def open_inputs(paths: Sequence[Path], query: Query, fmt: str | None) -> list[Source | Dataset]:
    """The inputs of a run opened, files (their compression told) or datasets (directories),
    once the query's ``[ingest]`` table and ``fmt`` are checked."""
    ingest_params(query)
    check_format(fmt)
    if not paths:
        raise InputFileError("no AIS input files given; name at least one file")
    return [_open_input(Path(p)) for p in paths]


def dataset_alone(sources: Sequence[Source | Dataset]) -> bool:
    """One dataset whose inputs share no partition: ingest dropped the duplicates of each,
    so its rows hold none (and need not be read whole to find them)."""
    return len(sources) == 1 and not isinstance(sources[0], Source) and sources[0].duplicate_free


def _open_input(path: Path) -> Source | Dataset:
    if not path.is_dir():
        return inspect_source(path)
    from .dataset_scan import Dataset  # pyarrow.dataset: only for runs that read one

    return Dataset.open(path)


def read_dataset(
    dataset: Dataset,
    query: Query,
    columns: Sequence[str],
    ledger: RejectsLedger,
    keep: Callable[[pa.Table], None],
    bar: ProgressSink,
) -> tuple[InputFile, ...]:
    """Hand a dataset's positions in the query to ``keep``, with the query pushed down into
    the scan (``dataset_scan.position_filter``); the ledger as ``dataset_inputs`` has it."""
    from .dataset_scan import position_filter, positions_in_query

    kept = 0
    for table in positions_in_query(dataset, query, columns, position_filter(query)):
        keep(table)
        kept += table.num_rows
    bar.advance(dataset.size_bytes)
    return dataset_inputs(dataset, kept, ledger)


def dataset_inputs(dataset: Dataset, kept: int, ledger: RejectsLedger) -> tuple[InputFile, ...]:
    """The inputs of ``dataset``, whose ledger goes into ``ledger``: the inputs' own (what
    reading the files themselves counted), with the dataset's rows, all used at ingest,
    shared out again. The static reports are used, as in a file; the ``kept`` positions of
    the query are used (less duplicates across inputs, found in load.py's
    ``_Collected.finish``); the
    others, skipped by the pushdown or by the query's tests, are outside the query."""
    part = dataset.ingest_ledger()
    part.rows_used = dataset.static_rows
    part.outside_query(dataset.rows - dataset.static_rows - kept)
    ledger.merge(part)
    return InputFile.of_dataset(dataset)


def dataset_reports(dataset: Dataset, vessels: Sequence[int]) -> pa.Table:
    """The dimension reports of ``vessels`` over the whole dataset, cleaned."""
    from .dataset_count import count_reports

    return cleaned_reports(count_reports(dataset, vessels))


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
    if len(example) > EXAMPLE_CHARS:
        example = example[:EXAMPLE_CHARS] + "…"
    return f"; the first {reason} row: {example}"
