"""Replay through time in slabs, in bounded memory, with the results of one go (docs/design.md §6).

**Stage 1, segmentation** (``segment_part``, one pass in time order): the positions of each
slab are segmented (``tracks.segment_reports``, which carries each vessel's last kept report
from slab to slab, so every report is decided as in one go) and the decided reports are
spilled to one Parquet file per slab in a scratch directory. On the way it gathers the
vessels' static data, the extent of the data (for the run's frame), a position per 0.01°
cell (to check that a chart covers the AIS) and the counts. Segmentation is a matter of
each vessel alone, so the vessels may be cut into parts (``replay_input.ReplayInput.parts``)
segmented apart, in any process: ``merge_parts`` makes of the parts' results what one part
gives (sums, unions, minima and maxima; nothing depends on the order positions come in).

**Stage 2, the slabs** (``replay_slab``, a pure function of its ``SlabJob``: slabs run in any
order and in any process): a slab owns the encounters that start in its core, ``[k·slab_s,
(k+1)·slab_s)``. It reads the decided reports of a window around the core from the spill
(``Spill.read``, with ``pyarrow.dataset``'s filters), resamples only the vessels under way
there (``tracks.resample_reports``), searches the pairs, and evaluates its triggered pairs
(``replay.evaluate_pair`` is handed in by the caller). The window reaches before the core by
``lead_steps``: the longest follow window of a passing (``EncounterParams.chain_steps``), so
that every firing step that could keep an earlier passing open at a run starting in the core
is seen, and at least the interaction's window plus one step, so that an encounter that
started earlier is seen to have started earlier. After the core it reaches by a tail that
holds most encounters whole.

Whether a step starts an encounter depends on the pair's passings before it
(``encounters.py``): a run that starts while a passing is open joins it, and an open passing
splits its run where it has opened and the pair fires again. That history can be longer than
any window (two vessels in company for hours, passing and passing again). So a pair is taken
as the window shows it only where its encounters there are settled (``_needs``): each that
reaches into the core comes from a chain that starts inside the window's reach
(``Encounter.chain_start_step``), or the pair fires nowhere in the window and its runs through
the core end in it; and each that starts in the core, or that opened in it and may yet split
there, is whole. The other pairs are searched again for their two vessels alone, in windows
that double before the core, after it, or both, until they are settled or the data ends.

What is exact: every sample a slab uses is the sample one go would make (same reports, same
neighbours), so the encounters, verdicts and counts do not depend on the slab length or on
the number of workers. Memory is set by the slab length and the traffic, not by the run's
duration.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.dataset as ds
import pyarrow.parquet as pq
from numpy.typing import NDArray

from ..charts.water import Chart
from ..core.encounters import Encounter, find_encounters
from ..core.interactions import window_steps
from ..core.passing import horizon_steps
from ..core.replay_results import PairOutcome
from ..core.tracks import (
    KEPT_COLUMNS,
    NO_TRACK_STATS,
    CourseSource,
    Tracks,
    TrackStats,
    context_s,
    empty_carry,
    latest_statics,
    report_table,
    resample_reports,
    segment_reports,
    vessel_statics,
)
from ..geo import LocalFrame
from ..progress import ProgressSink
from ..timebase import DISPLAY_TIME_FORMAT
from .replay_params import ReplayParams

# Sums of sines and cosines of longitudes in fixed point, so that the frame's centre does
# not depend on the order in which slabs add them up.
_FIXED_POINT = float(2**30)
# One position per cell of this size (degrees) is kept for the chart-overlap check.
_POINT_CELL_DEG = 0.01


@dataclass(frozen=True)
class SpillFile:
    path: Path
    t_min_s: float
    t_max_s: float


@dataclass(frozen=True)
class Spill:
    """The decided reports of stage 1, a Parquet file per slab and part of the vessels
    (``KEPT_COLUMNS``)."""

    files: tuple[SpillFile, ...]

    def read(
        self, t_from_s: float, t_to_s: float, mmsis: Sequence[int] | None = None
    ) -> pd.DataFrame:
        """The decided reports with ``t_from_s <= t_s <= t_to_s`` (of ``mmsis``), sorted by
        MMSI and time."""
        paths = [str(f.path) for f in self.files if f.t_max_s >= t_from_s and f.t_min_s <= t_to_s]
        if not paths:
            return _empty_kept()
        wanted = (ds.field("t_s") >= t_from_s) & (ds.field("t_s") <= t_to_s)
        if mmsis is not None:
            wanted &= ds.field("mmsi").isin(pa.array(list(mmsis), type=pa.int64()))
        frame = ds.dataset(paths, format="parquet").to_table(filter=wanted).to_pandas()
        order = np.lexsort((frame["t_s"].to_numpy(), frame["mmsi"].to_numpy()))
        return frame.iloc[order].reset_index(drop=True)


# A vessel track (``track_vertices``) keeps one decided report in each slot of this many
# seconds of the UTC grid, and each piece's first and last: Class A ships report every
# 2–10 s under way, and in 10 s a 20 kn ship makes 100 m, a straight line on any chart.
TRACK_VERTEX_SLOT_S = 10.0
TRACK_VERTEX_COLUMNS: tuple[str, ...] = ("mmsi", "piece", "t_s", "lat_deg", "lon_deg", "reports")


def _vertex_choice(
    t_s: NDArray[np.float64], starts: NDArray[np.bool_], slot_s: float
) -> NDArray[np.bool_]:
    """Of reports sorted by vessel and time, cut into pieces at ``starts`` (each vessel's
    first included): the first of each piece in each slot of ``slot_s`` seconds, and each
    piece's last."""
    slot = np.floor(t_s / slot_s)
    first = starts.copy()
    first[1:] |= slot[1:] != slot[:-1]
    return first | np.r_[starts[1:], True]


def _starts(mmsi: NDArray[np.int64], segment_start: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Where pieces start in decided reports sorted by vessel and time: at a segment's
    start, and at each vessel's first report here."""
    return segment_start | np.r_[True, mmsi[1:] != mmsi[:-1]]


# What a track's vertices are read from, in the spill files.
_VERTEX_SOURCE: tuple[str, ...] = ("mmsi", "t_s", "lat_deg", "lon_deg", "segment_start")


def _vertex_candidates(path: Path, slot_s: float) -> dict[str, NDArray[Any]]:
    """Of one spill file's decided reports (sorted by MMSI and time), the columns of those
    that may be a vertex of their track (``_vertex_choice`` within the file), and
    ``reports``: how many of the file's reports from each up to the next. Every vertex of
    the whole spill is among them: a piece's first report in a slot, or its last, is that
    in its file too."""
    table = pq.read_table(path, columns=list(_VERTEX_SOURCE))
    kept = {name: table.column(name).to_numpy() for name in _VERTEX_SOURCE}
    chosen = np.flatnonzero(
        _vertex_choice(kept["t_s"], _starts(kept["mmsi"], kept["segment_start"]), slot_s)
    )
    found = {name: values[chosen] for name, values in kept.items()}
    found["reports"] = np.diff(np.r_[chosen, len(kept["t_s"])])
    return found


def track_vertices(spill: Spill, slot_s: float = TRACK_VERTEX_SLOT_S) -> pd.DataFrame:
    """Every vessel's track over the run, from the decided reports of ``spill``: its
    pieces (``piece`` 0, 1, … in time order; a new piece at each segment start, where
    segmentation split the track at a gap or a confirmed jump), each thinned to its first
    decided report in each ``slot_s`` seconds of the UTC grid and its last
    (``TRACK_VERTEX_COLUMNS``, sorted by MMSI and time). ``reports``: how many decided
    reports from each vertex up to the next of its piece (their sum: all the decided
    reports). Read file by file, keeping the candidates of each (``_vertex_candidates``):
    the same vertices for any slab length and any parts of the vessels."""
    found = [_vertex_candidates(f.path, slot_s) for f in spill.files]
    if not found:
        empty = _empty_kept().assign(piece=np.zeros(0, dtype=np.int64))
        return empty.assign(reports=np.zeros(0, dtype=np.int64))[list(TRACK_VERTEX_COLUMNS)]
    # Column by column, each file's part let go once joined, then sorted: a national day
    # has millions of candidates, and a whole table more at a time would double them.
    columns = {name: np.concatenate([part.pop(name) for part in found]) for name in list(found[0])}
    order = np.lexsort((columns["t_s"], columns["mmsi"]))
    for name in columns:
        columns[name] = columns[name][order]
    mmsi = columns["mmsi"]
    starts = _starts(mmsi, columns.pop("segment_start"))
    chosen = _vertex_choice(columns["t_s"], starts, slot_s)
    # A dropped candidate's reports go to the vertex before it (in its piece: a piece's
    # first report is always a vertex).
    reports = np.bincount(np.cumsum(chosen) - 1, weights=columns.pop("reports"))
    piece = np.cumsum(starts) - 1
    first_of_vessel = np.flatnonzero(np.r_[True, mmsi[1:] != mmsi[:-1]])
    piece -= np.repeat(piece[first_of_vessel], np.diff(np.r_[first_of_vessel, len(mmsi)]))
    return pd.DataFrame(
        {
            "mmsi": mmsi[chosen],
            "piece": piece[chosen],
            **{name: columns.pop(name)[chosen] for name in ("t_s", "lat_deg", "lon_deg")},
            "reports": reports.astype(np.int64),
        },
        copy=False,  # the arrays are new: no second copy of each
    )


def _empty_kept() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "mmsi": np.zeros(0, dtype=np.int64),
            **{name: np.zeros(0) for name in KEPT_COLUMNS[1:-1]},
            "segment_start": np.zeros(0, dtype=bool),
        }
    )


@dataclass
class Extent:
    """Where the data lies: its latitude range and the fixed-point sums of the sines and
    cosines of its longitudes (their circular mean centres the frame)."""

    lat_min_deg: float = math.inf
    lat_max_deg: float = -math.inf
    lon_sin_sum: int = 0
    lon_cos_sum: int = 0

    def add(self, lat_deg: NDArray[np.float64], lon_deg: NDArray[np.float64]) -> None:
        if len(lat_deg) == 0:
            return
        self.lat_min_deg = min(self.lat_min_deg, float(lat_deg.min()))
        self.lat_max_deg = max(self.lat_max_deg, float(lat_deg.max()))
        lon_rad = np.radians(lon_deg)
        self.lon_sin_sum += int(np.rint(np.sin(lon_rad) * _FIXED_POINT).astype(np.int64).sum())
        self.lon_cos_sum += int(np.rint(np.cos(lon_rad) * _FIXED_POINT).astype(np.int64).sum())

    def frame(self) -> LocalFrame:
        """A frame centred on the data: the middle of its latitudes, and the circular mean
        of its longitudes (so that data across the antimeridian is centred on it)."""
        lon0 = math.degrees(math.atan2(self.lon_sin_sum, self.lon_cos_sum))
        return LocalFrame((self.lat_min_deg + self.lat_max_deg) / 2.0, lon0)

    def merge(self, other: Extent) -> None:
        """Add the data of ``other``: the same extent whatever the order they are added in."""
        self.lat_min_deg = min(self.lat_min_deg, other.lat_min_deg)
        self.lat_max_deg = max(self.lat_max_deg, other.lat_max_deg)
        self.lon_sin_sum += other.lon_sin_sum
        self.lon_cos_sum += other.lon_cos_sum


@dataclass(frozen=True)
class Points:
    """One position in each ``_POINT_CELL_DEG`` cell with data, in the order of the cells: the
    cell's smallest (lat, lon). The choice does not depend on the order positions come in,
    so that the points of parts of the vessels add up (``+``) to those of all of them."""

    lat_deg: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    lon_deg: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    @classmethod
    def of(cls, lat_deg: NDArray[np.float64], lon_deg: NDArray[np.float64]) -> Points:
        row = np.floor(lat_deg / _POINT_CELL_DEG).astype(np.int64)
        column = np.floor(lon_deg / _POINT_CELL_DEG).astype(np.int64)
        cell = row * 100_000 + column
        if len(cell) == 0:
            return cls()
        order = np.argsort(cell, kind="stable")
        cell, lat_deg, lon_deg = cell[order], lat_deg[order], lon_deg[order]
        first_of_cell = np.ones(len(cell), dtype=bool)
        first_of_cell[1:] = cell[1:] != cell[:-1]
        starts = np.flatnonzero(first_of_cell)
        lat_min = np.minimum.reduceat(lat_deg, starts)
        of_cell = np.cumsum(first_of_cell) - 1
        lon_at_lat_min = np.where(lat_deg == lat_min[of_cell], lon_deg, np.inf)
        return cls(lat_min, np.minimum.reduceat(lon_at_lat_min, starts))

    def __add__(self, other: Points) -> Points:
        return Points.of(
            np.concatenate((self.lat_deg, other.lat_deg)),
            np.concatenate((self.lon_deg, other.lon_deg)),
        )

    def frame(self) -> pd.DataFrame:
        return pd.DataFrame({"lat_deg": self.lat_deg, "lon_deg": self.lon_deg})


@dataclass(frozen=True)
class Segmentation:
    """Stage 1's result: the spill, the static table, the vessels with decided reports, the
    extent, sample positions, the time span of the decided reports, and the counts."""

    spill: Spill
    statics: pd.DataFrame
    vessels: NDArray[np.int64]
    extent: Extent
    points: pd.DataFrame
    first_s: float
    last_s: float
    stats: TrackStats


def slab_of(timestamps: pd.Series, slab_s: float) -> NDArray[np.int64]:
    """The slab index ``floor(t / slab_s)`` of each timestamp (seconds since the epoch)."""
    milliseconds = pd.to_datetime(timestamps, utc=True).dt.as_unit("ms").astype("int64")
    return np.floor(milliseconds.to_numpy() / (slab_s * 1000.0)).astype(np.int64)


def slabs_of_frame(positions: pd.DataFrame, slab_s: float) -> Iterator[tuple[int, pd.DataFrame]]:
    """The positions of each slab in turn, from a frame of positions held in memory."""
    slab = slab_of(positions["timestamp"], slab_s)
    for index, part in positions.groupby(slab, sort=True):
        yield int(index), part  # type: ignore[call-overload]


def slab_label(index: int, slab_s: float) -> str:
    """The slab's start in UTC, for progress bars."""
    start = datetime.fromtimestamp(index * slab_s, UTC)
    return start.strftime(f"{DISPLAY_TIME_FORMAT} UTC")


@dataclass(frozen=True)
class SegmentedPart:
    """Stage 1's result for one part of the vessels (``segment_part``), as a ``Segmentation``
    holds it for all of them (``merge_parts``)."""

    files: tuple[SpillFile, ...]
    statics: pd.DataFrame
    vessels: NDArray[np.int64]
    extent: Extent
    points: Points
    first_s: float
    last_s: float
    stats: TrackStats


def segment_part(
    slabs: Iterable[tuple[int, pd.DataFrame]],
    part: int,
    spill_dir: Path,
    params: ReplayParams,
    bar: ProgressSink | None = None,
) -> SegmentedPart:
    """Stage 1 over the slabs' positions of part ``part`` of the vessels, given in increasing
    slab order (canonical columns, cleaned; see ``tracks.report_table``); ``bar`` advanced
    by slab. Its spill files are its own (named by slab and part): the parts may run at
    once, in any processes.

    A part skips the slabs without positions of its vessels. Segmenting such a slab would
    only drop a vessel's pending jump once no report can come in time to confirm it; its
    next report, later still, drops it all the same."""
    carry = empty_carry()
    stats = NO_TRACK_STATS
    statics: pd.DataFrame | None = None
    extent = Extent()
    points = Points()
    files: list[SpillFile] = []
    vessels: set[int] = set()
    first_s, last_s = math.inf, -math.inf
    upcoming = iter(slabs)
    current = next(upcoming, None)
    while current is not None:
        following = next(upcoming, None)
        index, positions = current
        reports = report_table(positions)
        lat = reports["lat_deg"].to_numpy()
        lon = reports["lon_deg"].to_numpy()
        extent.add(lat, lon)
        points += Points.of(lat, lon)
        statics = latest_statics(positions, statics)
        # After the part's last slab its vessels have no more reports, whatever other parts
        # have: their pending jumps are decided here, as one part decides them later.
        until_s = None if following is None else (index + 1) * params.slab_s
        segmented = segment_reports(reports, carry, params.tracks, until_s)
        carry = segmented.carry
        stats = stats + segmented.stats
        kept = segmented.kept
        if len(kept):
            path = spill_dir / f"slab-{index:012d}-{part}.parquet"
            pq.write_table(pa.Table.from_pandas(kept, preserve_index=False), path)
            t = kept["t_s"].to_numpy()
            files.append(SpillFile(path, float(t.min()), float(t.max())))
            first_s, last_s = min(first_s, float(t.min())), max(last_s, float(t.max()))
            vessels.update(np.unique(kept["mmsi"].to_numpy()).tolist())
        if bar is not None:
            bar.advance()
            bar.describe(slab_label(index, params.slab_s))
        current = following
    return SegmentedPart(
        files=tuple(files),
        statics=statics if statics is not None else pd.DataFrame(),
        vessels=np.asarray(sorted(vessels), dtype=np.int64),
        extent=extent,
        points=points,
        first_s=first_s,
        last_s=last_s,
        stats=stats,
    )


def merge_parts(parts: Sequence[SegmentedPart]) -> Segmentation:
    """The ``Segmentation`` of the vessels of ``parts`` (of distinct vessels, at least one):
    the same for any cut of the vessels into parts."""
    extent = Extent()
    for part in parts:
        extent.merge(part.extent)
    statics = [part.statics for part in parts if len(part.statics)]
    return Segmentation(
        spill=Spill(tuple(sorted((f for p in parts for f in p.files), key=lambda f: f.path))),
        statics=pd.concat(statics).sort_index() if statics else pd.DataFrame(),
        vessels=np.unique(np.concatenate([part.vessels for part in parts])),
        extent=extent,
        points=sum((part.points for part in parts), Points()).frame(),
        first_s=min(part.first_s for part in parts),
        last_s=max(part.last_s for part in parts),
        stats=sum((part.stats for part in parts), NO_TRACK_STATS),
    )


# -- stage 2 --------------------------------------------------------------------------------

PairEvaluator = Callable[[Tracks, Encounter, tuple[int, ...], "Chart | None"], PairOutcome]


@dataclass(frozen=True)
class SlabContext:
    """What every slab needs, the same for all: sent once to each worker."""

    spill: Spill
    statics: pd.DataFrame
    frame: LocalFrame
    params: ReplayParams
    course_source: CourseSource
    own_mmsi: tuple[int, ...]
    data_end_s: float

    def core_steps(self, slab: int) -> tuple[int, int]:
        """The grid steps a slab owns (inclusive): those with a time in its core."""
        step_s, slab_s = self.params.step_s, self.params.slab_s
        first = math.ceil(slab * slab_s / step_s - 1e-9)
        last = math.ceil((slab + 1) * slab_s / step_s - 1e-9) - 1
        return first, last


@dataclass(frozen=True)
class SlabResult:
    """A slab's pairs (in the order of ``triggered_pairs``) and its share of the counts."""

    slab: int
    pairs: tuple[PairOutcome, ...]
    candidate_pair_steps: int
    candidate_pairs: frozenset[tuple[int, int]]
    encounters: int
    triggered: int
    samples: int
    followed: int  # pairs with an owned encounter followed past the slab's window
    looked_back: int = 0  # pairs whose history was read from before the slab's window


def tail_steps(params: ReplayParams) -> int:
    """How far past its core a slab's window reaches: a trigger at the end of the core, its
    TCPA (at most TCPA_act), the passing followed past it or the interaction's window past
    it (``interactions.approach_steps``), whichever is longer, and a minute."""
    after_s = max(params.passing_follow_s, params.interactions.interaction_window_s)
    return math.ceil((params.tcpa_act_s + after_s + 60.0) / params.step_s)


def lead_steps(params: ReplayParams) -> int:
    """How far before its core a slab's window reaches: the longest follow window of a
    passing (an earlier firing step this far back may keep a passing open at a run that
    starts in the core), and at least the interaction's window before a trigger at the
    core's start and a step (to see whether a run starts there)."""
    return max(
        params.encounters.chain_steps(params.step_s),
        window_steps(params.interactions, params.step_s) + 1,
    )


def _tracks(job: SlabContext, steps: tuple[int, int], mmsis: Sequence[int] | None) -> Tracks:
    """Exact samples at ``steps``: of the vessels under way, or of ``mmsis`` whatever
    their speed."""
    params = job.params
    margin_s = context_s(params.tracks)
    reports = job.spill.read(
        steps[0] * params.step_s - margin_s, steps[1] * params.step_s + margin_s, mmsis
    )
    samples = resample_reports(
        reports, job.frame, params.tracks, job.course_source, steps, under_way_only=mmsis is None
    )
    return Tracks(
        samples=samples,
        vessels=vessel_statics(None, samples["mmsi"].unique(), job.statics),
        stats=NO_TRACK_STATS,
        step_s=params.step_s,
        frame=job.frame,
    )


def _last_needed_step(encounter: Encounter, params: ReplayParams) -> int:
    """The last step the encounter's evaluation reads (``replay.evaluate_pair``)."""
    if encounter.trigger_step is None or encounter.tcpa_s_at_trigger is None:
        return encounter.end_step
    horizon = horizon_steps(encounter.tcpa_s_at_trigger, params.passing, params.step_s)
    return max(encounter.end_step, encounter.trigger_step + horizon)


def _whole(encounter: Encounter, last_step: int, params: ReplayParams) -> bool:
    """True when the window up to ``last_step`` holds all the encounter's evaluation reads
    and shows where its run ends."""
    return encounter.end_step < last_step and _last_needed_step(encounter, params) <= last_step


Pair = tuple[int, int]


def _pair(encounter: Encounter) -> Pair:
    a, b = sorted((encounter.own_mmsi, encounter.target_mmsi))
    return a, b


def _by_pair(encounters: Iterable[Encounter]) -> dict[Pair, list[Encounter]]:
    found: dict[Pair, list[Encounter]] = {}
    for encounter in encounters:
        found.setdefault(_pair(encounter), []).append(encounter)
    return found


def _needs(
    encounters: Sequence[Encounter],
    core: tuple[int, int],
    steps: tuple[int, int],
    data_steps: tuple[int, int],
    params: ReplayParams,
) -> tuple[bool, bool]:
    """Whether a search over ``steps`` leaves one pair's encounters in ``core`` unsettled
    (``encounters``: all of the pair's in the search): (it needs steps before ``steps``, it
    needs steps after them). ``data_steps`` are the first and last steps with data."""
    chain_steps = params.encounters.chain_steps(params.step_s)
    from_start, to_end = steps[0] <= data_steps[0], steps[1] > data_steps[1]
    reaching = [e for e in encounters if e.start_step <= core[1] and e.end_step >= core[0]]

    def whole(encounter: Encounter) -> bool:
        return to_end or _whole(encounter, steps[1], params)

    def may_split_in_core(encounter: Encounter) -> bool:
        # its passing opened where the step after is in the core: a later firing in its run
        # starts an encounter there
        opened = encounter.opened_step
        return opened is not None and core[0] - 1 <= opened < core[1]

    later = any(
        not whole(e) and (e.start_step >= core[0] or may_split_in_core(e)) for e in reaching
    )
    if from_start or all(e.chain_start_step - chain_steps >= steps[0] for e in reaching):
        return False, later
    # A passing open from before the window changes nothing in the core where the pair
    # fires nowhere in the window (no trigger to split at, none to join) and its runs
    # through the core end in it.
    quiet = not any(e.triggered for e in encounters) and all(
        to_end or e.end_step < steps[1] for e in reaching
    )
    return not quiet, later


def _data_steps(job: SlabContext) -> tuple[int, int]:
    """The first and last grid steps the decided reports reach (bounds for ``_needs``)."""
    first_s = min((f.t_min_s for f in job.spill.files), default=job.data_end_s)
    return math.floor(first_s / job.params.step_s), math.floor(job.data_end_s / job.params.step_s)


def replay_slab(
    slab: int, job: SlabContext, evaluate: PairEvaluator, chart: Chart | None
) -> SlabResult:
    """Stage 2 for one slab (see the module docstring)."""
    params = job.params
    core = job.core_steps(slab)
    data_steps = _data_steps(job)
    window = (core[0] - lead_steps(params), core[1] + tail_steps(params))
    tracks = _tracks(job, window, None)
    own = job.own_mmsi or None
    search = find_encounters(tracks, params.encounters, own, counted_steps=core, require_own=False)
    owned: list[tuple[Encounter, Tracks]] = []
    pending: dict[Pair, tuple[bool, bool]] = {}
    for pair, mine in _by_pair(search.encounters).items():
        needs = _needs(mine, core, window, data_steps, params)
        if any(needs):
            pending[pair] = needs
        else:
            owned.extend((e, tracks) for e in mine if core[0] <= e.start_step <= core[1])
    settled = _settle(job, pending, core, window, data_steps)
    followed = 0
    for pair in pending:
        owned.extend(settled[pair])
        followed += any(
            not _whole(e, window[1], params) and window[1] <= data_steps[1]
            for e, _ in settled[pair]
        )
    owned.sort(key=lambda found: (found[0].start_step, found[0].own_mmsi, found[0].target_mmsi))
    encounters = tuple(e for e, _ in owned)
    by_id = {e.encounter_id: t for e, t in owned}
    pairs = []
    for encounter, seats in triggered_pairs(encounters):
        pairs.append(evaluate(by_id[encounter.encounter_id], encounter, seats, chart))
    return SlabResult(
        slab=slab,
        pairs=tuple(pairs),
        candidate_pair_steps=search.candidate_pair_steps,
        candidate_pairs=frozenset(_pair(e) for e in encounters),
        encounters=len(encounters),
        triggered=sum(e.triggered for e in encounters),
        samples=int(
            (
                tracks.samples["step"].between(*core)
                & (tracks.samples["sog_kn"] >= params.min_sog_kn)
            ).sum()
        ),
        followed=followed,
        looked_back=sum(earlier for earlier, _ in pending.values()),
    )


def _settle(
    job: SlabContext,
    pending: dict[Pair, tuple[bool, bool]],
    core: tuple[int, int],
    window: tuple[int, int],
    data_steps: tuple[int, int],
) -> dict[Pair, list[tuple[Encounter, Tracks]]]:
    """The encounters starting in ``core`` of each pending pair (with what ``_needs`` found
    missing in ``window``), searched again for their vessels alone in windows that double
    before the core, after it, or both, until each pair is settled. The pairs are searched
    together (one read and one search per window); a pair's encounters are a matter of its
    two vessels alone, so the others do not change them."""
    params = job.params
    steps = window
    needs = dict(pending)
    found: dict[Pair, list[tuple[Encounter, Tracks]]] = {}
    while needs:
        if any(earlier for earlier, _ in needs.values()):
            steps = (core[0] - 2 * (core[0] - steps[0]), steps[1])
        if any(later for _, later in needs.values()):
            steps = (steps[0], core[1] + 2 * (steps[1] - core[1]))
        vessels = sorted({m for pair in needs for m in pair})
        own = [m for m in job.own_mmsi if m in vessels] if job.own_mmsi else None
        tracks = _tracks(job, steps, vessels)
        search = _by_pair(
            find_encounters(tracks, params.encounters, own, require_own=False).encounters
        )
        for pair in list(needs):
            mine = search.get(pair, [])
            needs[pair] = _needs(mine, core, steps, data_steps, params)
            if not any(needs[pair]):
                found[pair] = [(e, tracks) for e in mine if core[0] <= e.start_step <= core[1]]
                del needs[pair]
    return found


def triggered_pairs(
    encounters: Iterable[Encounter],
) -> list[tuple[Encounter, tuple[int, ...]]]:
    """Each triggered pair once, with the own-ship MMSIs of its reported seats, by start."""
    seats: dict[tuple[int, int, int], list[Encounter]] = {}
    for encounter in encounters:
        if not encounter.triggered:
            continue
        seats.setdefault((encounter.start_step, *_pair(encounter)), []).append(encounter)
    return [
        (found[0], tuple(sorted(e.own_mmsi for e in found))) for _, found in sorted(seats.items())
    ]


def run_slabs(
    slabs: Sequence[int],
    context: SlabContext,
    evaluate: PairEvaluator,
    chart: Chart | None,
    bar: ProgressSink,
) -> list[SlabResult]:
    """Stage 2 over ``slabs`` in this process, in slab order."""
    results = []
    for slab in slabs:
        bar.describe(slab_label(slab, context.params.slab_s))
        results.append(replay_slab(slab, context, evaluate, chart))
        bar.advance()
    return results
