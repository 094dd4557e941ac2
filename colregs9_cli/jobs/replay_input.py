"""The AIS of a replay, one slab at a time, in bounded memory (docs/design.md §6).

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

A dataset's vessels may be cut into parts by MMSI (``ReplayInput.parts``), each read and
segmented on its own, in any process (``segment_input_part``, stage 1 of ``slabs.py``);
``ReplayInput.merge`` takes their results and counts back. A duplicate is a copy of a row
of its vessel, so every part counts its own; the counts add up to those of one part.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.compute as pc

from ..ais.dataset_scan import Dataset, is_dataset, position_filter
from ..ais.inputs import InputFile, no_positions_error
from ..ais.ledger import RejectReason, RejectsLedger
from ..ais.load import canonical_frame, load_ais
from ..errors import InputFileError
from ..progress import ProgressSink
from ..query import Query
from .ingest import ingest_with_query, read_window_counted
from .replay_params import ReplayParams
from .slabs import Segmentation, SegmentedPart, merge_parts, segment_part, slab_of, slabs_of_frame

__all__ = [
    "ReadCounts",
    "ReplayInput",
    "SegmentedInputPart",
    "open_replay_input",
    "segment_input_part",
]


@dataclass(frozen=True)
class ReadCounts:
    """What reading positions counted, for the ledger: the positions kept, the duplicates
    dropped with the first of them as an example (and its slab), the vessels.

    The counts of the slabs, in slab order, or of parts of the vessels, in increasing MMSI
    order, add up (``+``) to those of reading them all at once: of two examples the one
    of the earlier slab is kept, the left one in a tie.
    """

    kept: int = 0
    duplicates: int = 0
    duplicate_example: tuple[int, str] | None = None
    vessels: frozenset[int] = frozenset()

    def __add__(self, other: ReadCounts) -> ReadCounts:
        examples = [e for e in (self.duplicate_example, other.duplicate_example) if e]
        return ReadCounts(
            kept=self.kept + other.kept,
            duplicates=self.duplicates + other.duplicates,
            duplicate_example=min(examples, key=lambda example: example[0], default=None),
            vessels=self.vessels | other.vessels,
        )


@dataclass
class ReplayInput:
    """The positions of a replay by slab (``positions``), and what reading them counted.

    ``slabs``: the indices of the slabs that may hold positions, increasing. ``mmsis``: the
    range of MMSIs (inclusive) read, for a part of the vessels (``parts``); None for all.
    ``counts``, ``ledger`` and ``vessels`` are complete once ``positions`` has been read to
    the end, or once ``merge`` has taken back the parts' results.
    """

    inputs: tuple[InputFile, ...]
    slabs: tuple[int, ...]
    slab_s: float
    columns: tuple[str, ...]
    query: Query
    dataset: Dataset | None = None
    in_memory: pd.DataFrame | None = None
    base_ledger: RejectsLedger = field(default_factory=RejectsLedger)
    mmsis: tuple[int, int] | None = None
    counts: ReadCounts = ReadCounts()

    @property
    def vessels(self) -> frozenset[int]:
        """The MMSIs of the positions read so far."""
        return self.counts.vessels

    def positions(self) -> Iterator[tuple[int, pd.DataFrame]]:
        """Each slab's positions (canonical ``columns``, sorted by MMSI and time) in turn;
        slabs without a position are left out."""
        if self.in_memory is not None:
            frame = self.in_memory
            self.in_memory = None
            for index, part in slabs_of_frame(frame, self.slab_s):
                self.counts += ReadCounts(len(part), vessels=_mmsis_of(part))
                yield index, part
            return
        assert self.dataset is not None
        for index in self.slabs:
            start = datetime.fromtimestamp(index * self.slab_s, UTC)
            end = datetime.fromtimestamp((index + 1) * self.slab_s, UTC)
            table, dropped = read_window_counted(
                self.dataset, self.query, start, end, self.columns, self.mmsis
            )
            example = None
            if dropped.num_rows:
                mmsi, stamp = dropped["mmsi"][0].as_py(), dropped["timestamp"][0].as_py()
                example = (index, f"MMSI {mmsi} at {stamp}: repeated row")
            part = canonical_frame(table) if table.num_rows else None
            vessels = frozenset() if part is None else _mmsis_of(part)
            self.counts += ReadCounts(table.num_rows, dropped.num_rows, example, vessels)
            if part is not None:
                yield index, part

    def parts(self, number: int) -> tuple[ReplayInput, ...]:
        """The input cut by vessel into at most ``number`` parts, ranges of MMSIs in
        increasing order, to be read and segmented each on its own, in any process
        (``segment_input_part``; ``merge`` takes their results back). Any cut gives the
        same results: the ranges hold about as many positions each, for balance. An input
        in memory is not cut (its one part is the input itself), nor is one cut in one."""
        if self.dataset is None or number < 2:
            return (self,)
        ranges = _mmsi_ranges(self.dataset, self.query, number)
        if len(ranges) < 2:
            return (self,)
        return tuple(
            dataclasses.replace(self, mmsis=mmsis, counts=ReadCounts()) for mmsis in ranges
        )

    def merge(self, parts: Sequence[SegmentedInputPart]) -> Segmentation:
        """Stage 1's result from those of the parts (in the order of ``parts``), whose
        counts become the input's."""
        self.counts = sum((part.counts for part in parts), ReadCounts())
        return merge_parts([part.segmented for part in parts])

    @property
    def ledger(self) -> RejectsLedger:
        """The rejects ledger of the positions read so far (all of them, at the end)."""
        ledger = RejectsLedger()
        ledger.merge(self.base_ledger)
        if self.dataset is None:
            return ledger
        dataset = self.dataset
        counts = self.counts
        ledger.rows_used = dataset.static_rows + counts.kept
        ledger.rows_outside_query += dataset.rows - dataset.static_rows - counts.kept
        ledger.rows_outside_query -= counts.duplicates
        if counts.duplicates:
            example = None if counts.duplicate_example is None else counts.duplicate_example[1]
            ledger.reject(RejectReason.DUPLICATE, counts.duplicates, example)
        return ledger

    def check_positions(self) -> None:
        """After ``positions``: the error ``load_ais`` raises when no position is left."""
        if self.counts.kept == 0:
            raise no_positions_error(self.inputs, self.ledger, self.query)


@dataclass(frozen=True)
class SegmentedInputPart:
    """Stage 1 of a part of the vessels (``segment_input_part``): its result, and what
    reading its positions counted."""

    segmented: SegmentedPart
    counts: ReadCounts


def segment_input_part(
    part: ReplayInput,
    number: int,
    spill_dir: Path,
    params: ReplayParams,
    bar: ProgressSink | None = None,
) -> SegmentedInputPart:
    """Stage 1 of ``part``, the ``number``-th of ``ReplayInput.parts`` (``slabs.segment_part``):
    its positions read and segmented where this runs (a task on a cluster, without ``bar``),
    its decided reports spilled to ``spill_dir``."""
    segmented = segment_part(part.positions(), number, spill_dir, params, bar)
    return SegmentedInputPart(segmented, part.counts)


def _mmsis_of(positions: pd.DataFrame) -> frozenset[int]:
    return frozenset(np.unique(positions["mmsi"].to_numpy()).tolist())


def _mmsi_ranges(dataset: Dataset, query: Query, number: int) -> list[tuple[int, int]]:
    """At most ``number`` ranges of MMSIs (inclusive, increasing) that cover the dataset's
    positions in the query's box and time window, with about as many positions each (a
    vessel with more than a part's share leaves fewer ranges). The MMSIs are counted batch
    by batch: memory holds a count per vessel, not the run's positions."""
    mmsis = np.zeros(0, dtype=np.int64)
    rows = np.zeros(0, dtype=np.int64)
    for table in dataset.scan(position_filter(query), ["mmsi"]):
        values, counts = pc.value_counts(table.column("mmsi")).flatten()
        mmsis, vessel = np.unique(np.r_[mmsis, values.to_numpy()], return_inverse=True)
        rows = np.bincount(vessel, np.r_[rows, counts.to_numpy()]).astype(np.int64)
    if len(mmsis) == 0:
        return []
    before = np.cumsum(rows) - rows
    part = (before * number // rows.sum()).astype(np.int64)
    starts = mmsis[np.r_[True, part[1:] != part[:-1]]]
    ends = np.r_[starts[1:] - 1, mmsis[-1]]
    return [(int(start), int(end)) for start, end in zip(starts, ends, strict=True)]


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
        inputs = InputFile.of_dataset(dataset)
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
