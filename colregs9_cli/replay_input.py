"""The AIS of a replay, one slab at a time, in bounded memory (DESIGN §6).

AIS files are first ingested, under the replay's query, into a Parquet dataset in the
scratch directory (``ais.dataset.ingest_with_query``, which streams them block by block);
a dataset made by ``colregs9 ingest`` and given alone is read in place. The positions of
each slab are then read from the dataset alone, the slab's time window and the query
pushed down into the scan (``ais.dataset.read_window_counted``), so that memory holds one
slab whatever the run's duration. Only the slabs in which the row groups' statistics show
positions are read: a gap of months in the data costs nothing.

Several datasets, a dataset with files, or one file given twice are read whole, in memory
(``load_ais``), as before there were datasets.

The positions, and the ledger, are those ``load_ais`` gives for the same inputs: the
dataset's rows were cleaned at ingest as ``load_ais`` cleans them, its ledger is the
inputs' own, and the rows the slabs read are shared out again as ``load_ais`` does for a
dataset (the static reports used; the positions in the query used, less the duplicates
across inputs; the rest outside the query).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd

from .ais.dataset import ingest_with_query, read_window_counted
from .ais.dataset_scan import Dataset, is_dataset
from .ais.ledger import RejectReason, RejectsLedger
from .ais.load import InputFile, canonical_frame, load_ais, no_positions_error
from .errors import InputFileError
from .query import Query
from .slabs import slab_of, slabs_of_frame

__all__ = ["ReplayInput", "open_replay_input"]


@dataclass
class ReplayInput:
    """The positions of a replay by slab (``positions``), and what reading them counted.

    ``slabs``: the indices of the slabs that may hold positions, increasing. ``ledger`` and
    ``vessels`` are complete once ``positions`` has been read to the end.
    """

    inputs: tuple[InputFile, ...]
    slabs: tuple[int, ...]
    slab_s: float
    columns: tuple[str, ...]
    query: Query
    dataset: Dataset | None = None
    in_memory: pd.DataFrame | None = None
    base_ledger: RejectsLedger = field(default_factory=RejectsLedger)
    kept: int = 0
    duplicates: int = 0
    duplicate_example: str | None = None
    vessels: set[int] = field(default_factory=set)

    def positions(self) -> Iterator[tuple[int, pd.DataFrame]]:
        """Each slab's positions (canonical ``columns``, sorted by MMSI and time) in turn;
        slabs without a position are left out."""
        if self.in_memory is not None:
            frame = self.in_memory
            self.in_memory = None
            for index, part in slabs_of_frame(frame, self.slab_s):
                self.kept += len(part)
                self.vessels.update(np.unique(part["mmsi"].to_numpy()).tolist())
                yield index, part
            return
        assert self.dataset is not None
        for index in self.slabs:
            start = datetime.fromtimestamp(index * self.slab_s, UTC)
            end = datetime.fromtimestamp((index + 1) * self.slab_s, UTC)
            table, dropped = read_window_counted(self.dataset, self.query, start, end, self.columns)
            if dropped.num_rows and self.duplicate_example is None:
                mmsi, stamp = dropped["mmsi"][0].as_py(), dropped["timestamp"][0].as_py()
                self.duplicate_example = f"MMSI {mmsi} at {stamp}: repeated row"
            self.duplicates += dropped.num_rows
            if table.num_rows:
                self.kept += table.num_rows
                part = canonical_frame(table)
                self.vessels.update(np.unique(part["mmsi"].to_numpy()).tolist())
                yield index, part

    @property
    def ledger(self) -> RejectsLedger:
        """The rejects ledger of the positions read so far (all of them, at the end)."""
        ledger = RejectsLedger()
        ledger.merge(self.base_ledger)
        if self.dataset is None:
            return ledger
        dataset = self.dataset
        ledger.rows_used = dataset.static_rows + self.kept
        ledger.rows_outside_query += dataset.rows - dataset.static_rows - self.kept
        ledger.rows_outside_query -= self.duplicates
        if self.duplicates:
            ledger.reject(RejectReason.DUPLICATE, self.duplicates, self.duplicate_example)
        return ledger

    def check_positions(self) -> None:
        """After ``positions``: the error ``load_ais`` raises when no position is left."""
        if self.kept == 0:
            raise no_positions_error(self.inputs, self.ledger, self.query)


def open_replay_input(
    paths: Sequence[Path],
    query: Query,
    fmt: str | None,
    quiet: bool,
    scratch: Path,
    slab_s: float,
    columns: Sequence[str],
) -> ReplayInput:
    """The replay's AIS (see the module docstring); files are ingested into ``scratch``."""
    if not paths:
        raise InputFileError("no AIS input files given; name at least one file")
    datasets = [Path(p) for p in paths if Path(p).is_dir() and is_dataset(Path(p))]
    if len(paths) == 1 and datasets:
        dataset = Dataset.open(datasets[0])
        inputs = tuple(
            InputFile(Path(item.path), item.sha256, item.layout, item.rows_read, dataset.directory)
            for item in dataset.inputs
        )
        return _from_dataset(dataset, inputs, query, slab_s, columns)
    if not datasets and not any(Path(p).is_dir() for p in paths):
        ingested = ingest_with_query(paths, scratch / "ais-dataset", query, fmt, quiet)
        if not any(item.already for item in ingested.inputs):
            dataset = Dataset.open(ingested.out_dir)
            inputs = tuple(
                InputFile(item.path, item.sha256, item.layout, item.ledger.rows_read)
                for item in ingested.inputs
            )
            return _from_dataset(dataset, inputs, query, slab_s, columns)
    data = load_ais(paths, query=query, fmt=fmt, quiet=quiet, columns=columns)
    slabs = np.unique(slab_of(data.positions["timestamp"], slab_s))
    return ReplayInput(
        inputs=data.inputs,
        slabs=tuple(int(s) for s in slabs),
        slab_s=slab_s,
        columns=tuple(columns),
        query=query,
        in_memory=data.positions,
        base_ledger=data.ledger,
    )


def _from_dataset(
    dataset: Dataset,
    inputs: tuple[InputFile, ...],
    query: Query,
    slab_s: float,
    columns: Sequence[str],
) -> ReplayInput:
    ledger = dataset.ingest_ledger()
    ledger.rows_used = 0
    return ReplayInput(
        inputs=inputs,
        slabs=_slabs_with_data(dataset, query, slab_s),
        slab_s=slab_s,
        columns=tuple(columns),
        query=query,
        dataset=dataset,
        base_ledger=ledger,
    )


def _slabs_with_data(dataset: Dataset, query: Query, slab_s: float) -> tuple[int, ...]:
    """The slabs that the row groups' time spans reach, inside the query's time window."""
    window = query.time
    start_ms = -math.inf if window.start is None else window.start.timestamp() * 1000
    end_ms = math.inf if window.end is None else window.end.timestamp() * 1000
    slab_ms = slab_s * 1000
    slabs: set[int] = set()
    for first_ms, last_ms in dataset.position_spans_ms():
        first, last = max(first_ms, start_ms), min(last_ms, end_ms)
        if first <= last:
            slabs.update(range(math.floor(first / slab_ms), math.floor(last / slab_ms) + 1))
    return tuple(sorted(slabs))
