"""Encounters: candidate pairs per replay step, CPA/TCPA, and the trigger (docs/design.md §5).

- ``cpa_tcpa``: closest point of approach under constant velocities.
- ``find_encounters``: at each step, the pairs of moving vessels (SOG ≥ ``min_sog_kn``) within
  ``candidate_range_m``, found with a grid of cubic cells of that size on the Earth-centred
  positions (each vessel is compared only with vessels in its own and the neighbouring
  cells), so the work grows with the number of close pairs, not with the square of the
  number of vessels, and nothing depends on a map projection: it works at any latitude and
  across the antimeridian. A *candidate run* is a maximal run of consecutive steps in which
  a pair stays a candidate; a step *fires* when ``0 <= TCPA <= tcpa_act_s`` and
  ``CPA < cpa_req_m``.
- One encounter per passing, and every passing judged (``_chain_encounters``): an encounter
  starts with a candidate run and *triggers* at its first firing step. Its passing is over
  once the range has *opened* (``passing.py``: it exceeds its least value since the trigger
  by the larger of ``open_m`` and ``open_frac`` of it). Until then a new candidate run of the
  pair that starts within the passing's follow window (trigger + TCPA + ``follow_s``; a speed
  dip of one vessel, or a moment past ``candidate_range_m``) is *joined* to the encounter: it
  triggers nothing and the encounter ends with it. After the opening, the next firing step
  of the same run (or of a run joined to it) starts a new encounter, from the step after the
  opening, with its own trigger and id: two vessels that pass, open and meet again are judged
  twice. A run that starts after the opening, or past the follow window, is an encounter of
  its own, as before.
- ``encounter_series``: one encounter's steps, own ship and target side by side, for the
  COLREGs evaluation, the rule 9 automaton and the reports.

Ranges, CPA and TCPA come from the vessels' WGS84 positions and their true COG and SOG
(``geo.ecef_m``, ``geo.velocity_ecef_mps``), never from the run's map frame: they agree with a
geodesic computation to well under a millimetre at 2 nm, anywhere on Earth.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from itertools import pairwise

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from ..errors import NoDataError
from ..geo import ecef_m, in_tangent_plane, velocity_ecef_mps
from ..units import METRES_PER_NAUTICAL_MILE
from .passing import PassingParams, horizon_steps, passing
from .tracks import STATE_COLUMNS, Tracks

# Below this relative speed (m/s) the vessels keep their distance: TCPA 0, CPA = range. One
# centimetre per second is a fifth of AIS's SOG resolution (0.1 kn): two vessels on the same
# course and speed side by side differ by more than that only through the meridians'
# convergence, which is not an approach.
_STILL_MPS = 0.01
# Vessel positions per batch of the pair search: bounds memory, keeps the work vectorised.
_POINTS_PER_BATCH = 20_000


def check_own_mmsi(own_mmsi: Iterable[int], vessels: NDArray[np.int64]) -> None:
    """A ``NoDataError`` naming the first own MMSI that is not among ``vessels``."""
    absent = sorted(set(own_mmsi) - set(vessels.tolist()))
    if absent:
        raise NoDataError(
            f"own MMSI {absent[0]} is not in the AIS data after cleaning; check --own-mmsi "
            "against the vessels in the input and the query's region and time window"
        )


@dataclass(frozen=True)
class EncounterParams:
    """What the pair search needs (the ``[replay]`` keys of the same names).

    - ``min_sog_kn``: vessels slower than this are not under way and form no candidate pairs.
    - ``candidate_range_m``: pairs closer than this (inclusive) are candidates (2 nm).
    - ``tcpa_act_s``, ``cpa_req_m``: an encounter triggers at the first step with
      ``0 <= TCPA <= tcpa_act_s`` and ``CPA < cpa_req_m`` (the paper's TCPA_act and CPA_req).
    - ``passing``: when a triggered passing is over (``passing.py``, the ``[replay]`` keys
      ``passing_*``), so that a new candidate run before that joins it and a firing after it
      starts a new encounter.
    """

    min_sog_kn: float = 0.5
    candidate_range_m: float = 2.0 * METRES_PER_NAUTICAL_MILE
    tcpa_act_s: float = 180.0
    cpa_req_m: float = 150.0
    passing: PassingParams = field(default_factory=PassingParams)

    def chain_steps(self, step_s: float) -> int:
        """The longest follow window of a passing, in steps (TCPA at its most, TCPA_act):
        a candidate run that starts with no firing step this far before it joins no
        earlier passing, so nothing before it changes its encounters."""
        return horizon_steps(self.tcpa_act_s, self.passing, step_s)


def cpa_tcpa(
    rel_north_m: ArrayLike,
    rel_east_m: ArrayLike,
    rel_vn_mps: ArrayLike,
    rel_ve_mps: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """CPA (m) and TCPA (s) of the target relative to own ship, both at constant velocity.

    ``rel_*`` are the target's position minus own ship's and the target's velocity minus own
    ship's (north, east). ``TCPA = −(p·v)/|v|²`` and ``CPA = |p + v·TCPA|``. TCPA is negative
    when the vessels are opening (the closest point is past). With no relative motion
    (|v| < 1 cm/s) the range never changes: TCPA is 0 and CPA is the current range.
    """
    rel_position = np.stack(np.broadcast_arrays(rel_north_m, rel_east_m), axis=-1).astype(float)
    rel_velocity = np.stack(np.broadcast_arrays(rel_vn_mps, rel_ve_mps), axis=-1).astype(float)
    _, cpa_m, tcpa_s = cpa_tcpa_vectors(rel_position, rel_velocity)
    return cpa_m, tcpa_s


def cpa_tcpa_vectors(
    rel_position_m: NDArray[np.float64], rel_velocity_mps: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """(range, CPA, TCPA) from relative positions and velocities of any dimension (last axis).

    The same formulas as ``cpa_tcpa``; used on Earth-centred 3-D vectors.
    """
    speed_sq = np.sum(rel_velocity_mps * rel_velocity_mps, axis=-1)
    moving = speed_sq >= _STILL_MPS * _STILL_MPS
    dot = np.sum(rel_position_m * rel_velocity_mps, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        tcpa_s = np.where(moving, -dot / np.where(moving, speed_sq, 1.0), 0.0)
    tcpa_s = np.where(np.isnan(speed_sq), np.nan, tcpa_s)
    closest = rel_position_m + rel_velocity_mps * tcpa_s[..., None]
    return (
        np.linalg.norm(rel_position_m, axis=-1),
        np.linalg.norm(closest, axis=-1),
        tcpa_s,
    )


def trigger_mask(
    cpa_m: ArrayLike, tcpa_s: ArrayLike, rel_speed_mps: ArrayLike, params: EncounterParams
) -> NDArray[np.bool_]:
    """The paper's trigger ``0 <= TCPA <= tcpa_act_s and CPA < cpa_req_m``.

    A pair with no relative motion (relative speed < 1 cm/s, e.g. parallel courses at equal
    speed) never triggers: nothing approaches, even if it sails within ``cpa_req_m``.
    """
    tcpa = np.asarray(tcpa_s, dtype=float)
    return (
        (tcpa >= 0.0)
        & (tcpa <= params.tcpa_act_s)
        & (np.asarray(cpa_m, dtype=float) < params.cpa_req_m)
        & (np.asarray(rel_speed_mps, dtype=float) >= _STILL_MPS)
    )


@dataclass(frozen=True)
class Encounter:
    """One encounter seen from the own-ship seat.

    ``start_step``..``end_step`` (inclusive, grid steps of ``Tracks``) is a candidate run, the
    runs joined to it while its passing was open, and no more than up to the opening where a
    later firing splits the run (see the module docstring); within that span the pair is a
    candidate except in the gaps between joined runs. ``trigger_step`` is None when it never
    triggered; the ``*_at_trigger`` values are then None too. ``min_range_m`` is the least
    range at its candidate steps. ``opened_step`` is the step at which its passing had opened
    (``passing.py``) when that came by ``max(end_step, trigger + TCPA + follow_s)``, the span
    the pair evaluation follows; else None. ``chain_start_step`` is the start of its *chain*:
    the latest candidate run, at or before it, with no firing step within
    ``EncounterParams.chain_steps`` before it. Nothing before that step changes the encounter.
    """

    encounter_id: str
    own_mmsi: int
    target_mmsi: int
    start_step: int
    end_step: int
    start: pd.Timestamp
    end: pd.Timestamp
    trigger_step: int | None
    trigger: pd.Timestamp | None
    range_m_at_trigger: float | None
    cpa_m_at_trigger: float | None
    tcpa_s_at_trigger: float | None
    min_range_m: float
    opened_step: int | None
    chain_start_step: int

    @property
    def triggered(self) -> bool:
        return self.trigger_step is not None


@dataclass(frozen=True)
class EncounterSearch:
    """The result of ``find_encounters``: encounters sorted by start, own MMSI, target MMSI."""

    encounters: tuple[Encounter, ...]
    candidate_pair_steps: int  # (pair, step) candidates evaluated, each pair counted once

    @property
    def triggered(self) -> tuple[Encounter, ...]:
        return tuple(e for e in self.encounters if e.triggered)


def candidate_pairs(
    step: NDArray[np.int64],
    north_m: NDArray[np.float64],
    east_m: NDArray[np.float64],
    range_m: float,
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Index pairs (i, j), i ≠ j, of points at the same step within ``range_m`` (inclusive),
    in a plane; see ``candidate_pairs_nd``."""
    return candidate_pairs_nd(step, (north_m, east_m), range_m)


# The cell keys (step, then the cell in each dimension) must fit an int64.
_KEY_LIMIT = 2.0**62


def _cell_side_m(range_m: float, extents_m: list[float], steps: int) -> float:
    """The grid's cell side: ``range_m``, doubled until every (step, cell) has a key that fits
    an int64. A cell wider than the range only brings more pairs to the exact distance test;
    a very short range over a wide extent would otherwise overflow the keys."""
    side_m = range_m
    while steps * math.prod(extent / side_m + 3.0 for extent in extents_m) >= _KEY_LIMIT:
        side_m *= 2.0
    return side_m


def candidate_pairs_nd(
    step: NDArray[np.int64],
    coordinates: tuple[NDArray[np.float64], ...],
    range_m: float,
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Index pairs (i, j), i ≠ j, of points at the same step within ``range_m`` (inclusive).

    Each unordered pair appears once. Points are hashed into cells of side ``range_m`` in
    as many dimensions as ``coordinates`` has; a point is compared with the points of its
    own cell and of half of its neighbours (the other half see it from their side).
    """
    if len(step) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    lows = [float(values.min()) for values in coordinates]
    side_m = _cell_side_m(
        range_m,
        [float(values.max()) - low for values, low in zip(coordinates, lows, strict=True)],
        int(step.max()) - int(step.min()) + 1,
    )
    cells = [
        np.floor((values - low) / side_m).astype(np.int64) + 1
        for values, low in zip(coordinates, lows, strict=True)
    ]
    sizes = [int(cell.max()) + 2 for cell in cells]
    key = step - step.min()
    for cell, size in zip(cells, sizes, strict=True):
        key = key * size + cell
    strides = [int(np.prod(sizes[i + 1 :], dtype=np.int64)) for i in range(len(sizes))]
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    # The occupied cells, each a run of sorted points: neighbours are looked up per cell.
    cell_keys, cell_first, cell_count = np.unique(sorted_key, return_index=True, return_counts=True)
    point_cell = np.repeat(np.arange(len(cell_keys)), cell_count)
    points = np.arange(len(sorted_key))
    firsts: list[NDArray[np.intp]] = []
    seconds: list[NDArray[np.intp]] = []
    for offset in itertools.product((-1, 0, 1), repeat=len(cells)):
        if offset < (0,) * len(cells):
            continue  # the mirrored neighbour finds this pair
        if not any(offset):
            lo = points + 1  # the same cell: only later points
            counts = (cell_first + cell_count)[point_cell] - lo
        else:
            wanted = cell_keys + sum(o * stride for o, stride in zip(offset, strides, strict=True))
            found_at = np.minimum(np.searchsorted(cell_keys, wanted), len(cell_keys) - 1)
            found = cell_keys[found_at] == wanted
            lo = np.where(found, cell_first[found_at], 0)[point_cell]
            counts = np.where(found, cell_count[found_at], 0)[point_cell]
        total = int(counts.sum())
        if total == 0:
            continue
        position = np.repeat(points, counts)
        start = np.cumsum(counts) - counts
        partner = lo[position] + (np.arange(total) - start[position])
        firsts.append(order[position])
        seconds.append(order[partner])
    if not firsts:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    first = np.concatenate(firsts)
    second = np.concatenate(seconds)
    distance_sq = sum((values[first] - values[second]) ** 2 for values in coordinates)
    near = distance_sq <= range_m * range_m
    return first[near], second[near]


def find_encounters(
    tracks: Tracks,
    params: EncounterParams,
    own_mmsi: Iterable[int] | None = None,
    counted_steps: tuple[int, int] | None = None,
    require_own: bool = True,
) -> EncounterSearch:
    """All encounters in ``tracks``.

    With ``own_mmsi`` given, only those vessels take the own-ship seat (a pair of two of them
    is reported from both sides); otherwise every vessel does, so each pair appears twice.
    An own MMSI with no samples is a ``NoDataError`` when ``require_own``.
    ``candidate_pair_steps`` counts the steps in ``counted_steps`` (inclusive; default all).
    """
    samples = tracks.samples
    own = None if own_mmsi is None else frozenset(int(m) for m in own_mmsi)
    if own is not None and require_own:
        check_own_mmsi(own, samples["mmsi"].unique())
    moving = samples["sog_kn"].to_numpy() >= params.min_sog_kn
    rows = np.flatnonzero(moving)
    step = samples["step"].to_numpy()[rows]
    by_step = np.argsort(step, kind="stable")
    rows, step = rows[by_step], step[by_step]
    lat = samples["lat_deg"].to_numpy()[rows]
    lon = samples["lon_deg"].to_numpy()[rows]
    position = ecef_m(lat, lon)
    velocity = velocity_ecef_mps(
        lat, lon, samples["speed_mps"].to_numpy()[rows], samples["cog_deg"].to_numpy()[rows]
    )
    vessel_ids, vessel = np.unique(samples["mmsi"].to_numpy()[rows], return_inverse=True)

    runs: list[pd.DataFrame] = []
    firings: list[pd.DataFrame] = []
    pair_steps = 0
    if len(step):
        busiest_step = int(np.bincount(step - step[0]).max())
        steps_per_batch = max(1, _POINTS_PER_BATCH // busiest_step)
        batch_edges = np.r_[
            np.searchsorted(step, np.arange(step[0], step[-1] + 1, steps_per_batch)), len(step)
        ]
        for lo, hi in pairwise(batch_edges):
            if hi <= lo:
                continue
            part = slice(lo, hi)
            i, j = candidate_pairs_nd(step[part], tuple(position[part].T), params.candidate_range_m)
            i, j = i + lo, j + lo
            if counted_steps is None:
                pair_steps += len(i)
            else:
                pair_steps += int(
                    ((step[i] >= counted_steps[0]) & (step[i] <= counted_steps[1])).sum()
                )
            batch_runs, batch_firings = _batch_runs(i, j, step, vessel, position, velocity, params)
            runs.append(batch_runs)
            firings.append(batch_firings)
    passings = _passings(_join_runs(runs), firings, vessel_ids, tracks, params)
    return EncounterSearch(
        encounters=_encounters(passings, vessel_ids, own, tracks),
        candidate_pair_steps=pair_steps,
    )


def _batch_runs(
    i: NDArray[np.intp],
    j: NDArray[np.intp],
    step: NDArray[np.int64],
    vessel: NDArray[np.intp],
    position: NDArray[np.float64],
    velocity: NDArray[np.float64],
    params: EncounterParams,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Runs of consecutive candidate steps per pair within one batch of steps, and the
    firing steps (``_FIRING_COLUMNS``)."""
    swap = vessel[i] > vessel[j]
    a = np.where(swap, j, i)
    b = np.where(swap, i, j)
    # One integer key orders the rows by (vessel_a, vessel_b, step), faster than a lexsort.
    batch_steps = int(step[a].max() - step[a].min()) + 1 if len(a) else 1
    pair_code = vessel[a].astype(np.int64) * (int(vessel.max()) + 1) + vessel[b]
    order = np.argsort(pair_code * batch_steps + (step[a] - step[a].min(initial=0)), kind="stable")
    a, b = a[order], b[order]
    rel_velocity = velocity[b] - velocity[a]
    range_m, cpa_m, tcpa_s = cpa_tcpa_vectors(position[b] - position[a], rel_velocity)
    rel_speed_mps = np.linalg.norm(rel_velocity, axis=-1)
    fires = trigger_mask(cpa_m, tcpa_s, rel_speed_mps, params)
    columns = (vessel[a], vessel[b], step[a], range_m, cpa_m, tcpa_s)
    firing = pd.DataFrame(
        {name: values[fires] for name, values in zip(_FIRING_COLUMNS, columns, strict=True)}
    )
    return _runs(vessel[a], vessel[b], step[a], range_m, cpa_m, tcpa_s, fires), firing


# A firing step: the pair (vessel indices, a < b), the step, and range, CPA and TCPA there.
_FIRING_COLUMNS = ("vessel_a", "vessel_b", "step", "range_m", "cpa_m", "tcpa_s")


def _runs(
    vessel_a: NDArray[np.intp],
    vessel_b: NDArray[np.intp],
    step: NDArray[np.int64],
    range_m: NDArray[np.float64],
    cpa_m: NDArray[np.float64],
    tcpa_s: NDArray[np.float64],
    fires: NDArray[np.bool_],
) -> pd.DataFrame:
    """Collapse rows sorted by (vessel_a, vessel_b, step) into runs of consecutive steps,
    each with its first firing step (the trigger) and its last one."""
    new_run = np.ones(len(step), dtype=bool)
    new_run[1:] = (
        (vessel_a[1:] != vessel_a[:-1])
        | (vessel_b[1:] != vessel_b[:-1])
        | (step[1:] != step[:-1] + 1)
    )
    starts = np.flatnonzero(new_run)
    ends = np.r_[starts[1:], len(step)][: len(starts)] - 1
    run = np.cumsum(new_run) - 1
    fired = np.flatnonzero(fires)
    fired_runs, first = np.unique(run[fired], return_index=True)
    trigger_row = np.zeros(len(starts), dtype=np.intp)
    trigger_row[fired_runs] = fired[first]
    triggered = np.zeros(len(starts), dtype=bool)
    triggered[fired_runs] = True
    trigger_step = pd.array(step[trigger_row], dtype="Int64")
    trigger_step[~triggered] = pd.NA
    last_fire_step = trigger_step.copy()
    last_fire_step[fired_runs] = step[fired[np.r_[first[1:], len(fired)][: len(first)] - 1]]

    def at_trigger(values: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.where(triggered, values[trigger_row], np.nan)

    return pd.DataFrame(
        {
            "vessel_a": vessel_a[starts],
            "vessel_b": vessel_b[starts],
            "start_step": step[starts],
            "end_step": step[ends],
            "min_range_m": np.minimum.reduceat(range_m, starts) if len(starts) else range_m,
            "trigger_step": trigger_step,
            "range_m_at_trigger": at_trigger(range_m),
            "cpa_m_at_trigger": at_trigger(cpa_m),
            "tcpa_s_at_trigger": at_trigger(tcpa_s),
            "last_fire_step": last_fire_step,
        }
    )


def _join_runs(runs: list[pd.DataFrame]) -> pd.DataFrame:
    """Join runs that continue across a batch boundary."""
    if not runs:
        return pd.DataFrame()
    table = pd.concat(runs, ignore_index=True).sort_values(
        ["vessel_a", "vessel_b", "start_step"], kind="stable"
    )
    same_pair = (table["vessel_a"].diff() == 0) & (table["vessel_b"].diff() == 0)
    continues = same_pair & (table["start_step"] == table["end_step"].shift() + 1)
    group = (~continues).cumsum().to_numpy()
    # "first" skips nulls, so the trigger is the first one in time among the joined pieces.
    return (
        table.groupby(group, sort=True)
        .agg(
            vessel_a=("vessel_a", "first"),
            vessel_b=("vessel_b", "first"),
            start_step=("start_step", "min"),
            end_step=("end_step", "max"),
            min_range_m=("min_range_m", "min"),
            trigger_step=("trigger_step", "first"),
            range_m_at_trigger=("range_m_at_trigger", "first"),
            cpa_m_at_trigger=("cpa_m_at_trigger", "first"),
            tcpa_s_at_trigger=("tcpa_s_at_trigger", "first"),
            last_fire_step=("last_fire_step", "last"),
        )
        .reset_index(drop=True)
    )


class _Positions:
    """Every sample's vessel, step and position (``Tracks.samples`` order: by MMSI, then
    step), whatever its speed: the range of a pair through a speed dip."""

    def __init__(self, samples: pd.DataFrame) -> None:
        self.mmsi = samples["mmsi"].to_numpy(dtype=np.int64)
        self.step = samples["step"].to_numpy(dtype=np.int64)
        self.lat_deg = samples["lat_deg"].to_numpy(dtype=float)
        self.lon_deg = samples["lon_deg"].to_numpy(dtype=float)

    def ecef_m(self, mmsi: int, first: int, last: int) -> NDArray[np.float64]:
        """The vessel's Earth-centred position at each step ``first``..``last``; NaN where
        she has no sample."""
        lo, hi = np.searchsorted(self.mmsi, mmsi, "left"), np.searchsorted(self.mmsi, mmsi, "right")
        steps = self.step[lo:hi]
        begin = lo + int(np.searchsorted(steps, first, "left"))
        stop = lo + int(np.searchsorted(steps, last, "right"))
        positions = np.full((last - first + 1, 3), np.nan)
        positions[self.step[begin:stop] - first] = ecef_m(
            self.lat_deg[begin:stop], self.lon_deg[begin:stop]
        )
        return positions

    def range_m(self, mmsis: tuple[int, int], first: int, last: int) -> NDArray[np.float64]:
        """The range (m) between two vessels at each step ``first``..``last``, computed as the
        pair search does (b minus a); NaN where either has no sample."""
        own, other = (self.ecef_m(m, first, last) for m in mmsis)
        return np.linalg.norm(other - own, axis=-1)


def _passings(
    runs: pd.DataFrame,
    firings: list[pd.DataFrame],
    vessel_ids: NDArray[np.int64],
    tracks: Tracks,
    params: EncounterParams,
) -> pd.DataFrame:
    """The encounters of the candidate runs (sorted by pair and start): one per passing.

    Runs are cut into chains where a run starts with no firing step within
    ``params.chain_steps`` before it (no earlier passing can be open there). A chain with no
    firing step is its runs, each an encounter that never triggered; the others are scanned
    run by run (``_chain_encounters``), in Python, one chain at a time.
    """
    if runs.empty:
        return runs
    chain_steps = params.chain_steps(tracks.step_s)
    a = runs["vessel_a"].to_numpy()
    b = runs["vessel_b"].to_numpy()
    start = runs["start_step"].to_numpy(dtype=np.int64)
    last_fire = runs["last_fire_step"].to_numpy(dtype=float, na_value=np.nan)
    new_pair = np.r_[True, (a[1:] != a[:-1]) | (b[1:] != b[:-1])]
    # The latest firing step of the pair's earlier runs (-inf: none).
    fired_so_far = (
        pd.Series(np.where(np.isnan(last_fire), -np.inf, last_fire))
        .groupby(np.cumsum(new_pair))
        .cummax()
        .to_numpy()
    )
    before = np.where(new_pair, -np.inf, np.r_[-np.inf, fired_so_far[:-1]])
    chain = np.cumsum(new_pair | (before < start - chain_steps)) - 1
    chain_first = np.r_[0, np.flatnonzero(np.diff(chain)) + 1]
    table = runs.drop(columns="last_fire_step").assign(
        opened_step=pd.array([pd.NA] * len(runs), dtype="Int64"),
        chain_start_step=start[chain_first][chain],
    )
    fired_chains = np.flatnonzero(np.bincount(chain, weights=~np.isnan(last_fire)) > 0)
    if len(fired_chains) == 0:
        return table
    fire = pd.concat(firings, ignore_index=True).sort_values(
        ["vessel_a", "vessel_b", "step"], kind="stable"
    )
    fire_pair = fire["vessel_a"].to_numpy(np.int64) * len(vessel_ids) + fire["vessel_b"].to_numpy()
    fire_step = fire["step"].to_numpy(dtype=np.int64)
    values = fire[["range_m", "cpa_m", "tcpa_s"]].to_numpy(dtype=float)
    positions = _Positions(tracks.samples)
    scanned: list[pd.DataFrame] = []
    chain_last = np.r_[chain_first[1:], len(runs)] - 1
    end = runs["end_step"].to_numpy(dtype=np.int64)
    for c in fired_chains.tolist():
        rows = slice(chain_first[c], chain_last[c] + 1)
        pair = int(a[chain_first[c]]) * len(vessel_ids) + int(b[chain_first[c]])
        mine = slice(
            np.searchsorted(fire_pair, pair, "left"), np.searchsorted(fire_pair, pair, "right")
        )
        in_chain = (fire_step[mine] >= start[chain_first[c]]) & (
            fire_step[mine] <= end[chain_last[c]]
        )
        vessels = (int(a[chain_first[c]]), int(b[chain_first[c]]))
        scanned.append(
            _chain_encounters(
                runs.iloc[rows],
                _Firings(fire_step[mine][in_chain], values[mine][in_chain]),
                positions,
                (vessels, (int(vessel_ids[vessels[0]]), int(vessel_ids[vessels[1]]))),
                params,
                tracks.step_s,
            )
        )
    plain = ~np.isin(chain, fired_chains)
    return pd.concat([table[plain], *scanned], ignore_index=True).sort_values(
        ["vessel_a", "vessel_b", "start_step"], kind="stable", ignore_index=True
    )


@dataclass(frozen=True)
class _Firings:
    """A chain's firing steps, in order, and (range, CPA, TCPA) at each."""

    step: NDArray[np.int64]
    values: NDArray[np.float64]

    def first(self, from_step: int, to_step: int) -> int | None:
        """The index of the first firing step in ``from_step``..``to_step``, if any."""
        k = int(np.searchsorted(self.step, from_step, "left"))
        return k if k < len(self.step) and self.step[k] <= to_step else None


@dataclass
class _Open:
    """An encounter of a chain being scanned: its span, its trigger (index of ``_Firings``)
    and, once triggered, the end of its follow window and its opening step (None: not seen)."""

    start: int
    end: int
    trigger: int | None = None
    follow_end: int = 0
    opened: int | None = None

    def is_open_at(self, step: int) -> bool:
        """True when its passing is still open at ``step``: triggered, within its follow
        window, and not yet opened."""
        return (
            self.trigger is not None
            and step <= self.follow_end
            and (self.opened is None or step <= self.opened)
        )


def _chain_encounters(
    runs: pd.DataFrame,
    fires: _Firings,
    positions: _Positions,
    pair: tuple[tuple[int, int], tuple[int, int]],
    params: EncounterParams,
    step_s: float,
) -> pd.DataFrame:
    """The encounters of one chain of runs of ``pair`` (its vessel indices and MMSIs; see
    the module docstring): a run that starts while the current passing is open joins it; the
    first firing step after its opening, in the same run, starts a new encounter from the
    step after the opening."""
    vessels, mmsis = pair
    starts = runs["start_step"].to_numpy(dtype=np.int64)
    ends = runs["end_step"].to_numpy(dtype=np.int64)
    first = int(starts[0])
    # The ranges the openings are judged on reach past the last run by a follow window.
    last = max(int(ends[-1]), int(fires.step[-1]) + params.chain_steps(step_s))
    range_m = positions.range_m(mmsis, first, last)
    found: list[_Open] = []
    for run_start, run_end in zip(starts.tolist(), ends.tolist(), strict=True):
        if found and found[-1].is_open_at(run_start):
            found[-1].end = run_end  # joined: the passing goes on through the gap
        else:
            found.append(_Open(run_start, run_end))
        current = found[-1]
        while True:
            if current.trigger is None:
                k = fires.first(max(current.start, run_start), run_end)
                if k is None:
                    break
                trigger = int(fires.step[k])
                current.trigger = k
                current.follow_end = trigger + horizon_steps(
                    float(fires.values[k, 2]), params.passing, step_s
                )
                seen = passing(range_m[trigger - first :], params.passing)
                current.opened = trigger + seen.end_row if seen.covers_cpa else None
            opened = current.opened
            if opened is None or opened >= run_end or fires.first(opened + 1, run_end) is None:
                break
            current.end = opened  # passed: the next firing is a new passing
            current = _Open(opened + 1, run_end)
            found.append(current)
    candidate = np.zeros(len(range_m), dtype=bool)
    for run_start, run_end in zip(starts.tolist(), ends.tolist(), strict=True):
        candidate[run_start - first : run_end - first + 1] = True
    rows = [_chain_row(e, fires, range_m, candidate, first) for e in found]
    return pd.DataFrame(rows).assign(
        vessel_a=vessels[0],
        vessel_b=vessels[1],
        opened_step=lambda t: t["opened_step"].astype("Int64"),
    )


def _chain_row(
    encounter: _Open,
    fires: _Firings,
    range_m: NDArray[np.float64],
    candidate: NDArray[np.bool_],
    first: int,
) -> dict[str, object]:
    """One row of the encounters' table for an encounter of a chain that starts at
    ``first``."""
    span = slice(encounter.start - first, encounter.end - first + 1)
    k = encounter.trigger
    opened = encounter.opened
    reported = (
        opened
        if k is not None
        and opened is not None
        and opened <= max(encounter.end, encounter.follow_end)
        else None
    )
    return {
        "start_step": encounter.start,
        "end_step": encounter.end,
        "min_range_m": float(np.nanmin(np.where(candidate[span], range_m[span], np.nan))),
        "trigger_step": None if k is None else int(fires.step[k]),
        "range_m_at_trigger": np.nan if k is None else float(fires.values[k, 0]),
        "cpa_m_at_trigger": np.nan if k is None else float(fires.values[k, 1]),
        "tcpa_s_at_trigger": np.nan if k is None else float(fires.values[k, 2]),
        "opened_step": reported,
        "chain_start_step": first,
    }


def _encounters(
    runs: pd.DataFrame,
    vessel_ids: NDArray[np.int64],
    own: frozenset[int] | None,
    tracks: Tracks,
) -> tuple[Encounter, ...]:
    result: list[Encounter] = []
    for run in runs.itertuples(index=False):
        mmsi_a = int(vessel_ids[run.vessel_a])
        mmsi_b = int(vessel_ids[run.vessel_b])
        for own_mmsi, target_mmsi in ((mmsi_a, mmsi_b), (mmsi_b, mmsi_a)):
            if own is not None and own_mmsi not in own:
                continue
            result.append(_encounter(run, own_mmsi, target_mmsi, tracks))
    result.sort(key=lambda e: (e.start_step, e.own_mmsi, e.target_mmsi))
    return tuple(result)


def _optional_float(value: object) -> float | None:
    return None if pd.isna(value) else float(value)  # type: ignore[arg-type]


def _optional_int(value: object) -> int | None:
    return None if pd.isna(value) else int(value)  # type: ignore[call-overload]


def _encounter(run: object, own_mmsi: int, target_mmsi: int, tracks: Tracks) -> Encounter:
    start = tracks.step_to_timestamp(int(run.start_step))  # type: ignore[attr-defined]
    trigger_step = _optional_int(run.trigger_step)  # type: ignore[attr-defined]
    return Encounter(
        encounter_id=f"{start:%Y%m%dT%H%M%S}-{own_mmsi}-{target_mmsi}",
        own_mmsi=own_mmsi,
        target_mmsi=target_mmsi,
        start_step=int(run.start_step),  # type: ignore[attr-defined]
        end_step=int(run.end_step),  # type: ignore[attr-defined]
        start=start,
        end=tracks.step_to_timestamp(int(run.end_step)),  # type: ignore[attr-defined]
        trigger_step=trigger_step,
        trigger=None if trigger_step is None else tracks.step_to_timestamp(trigger_step),
        range_m_at_trigger=_optional_float(run.range_m_at_trigger),  # type: ignore[attr-defined]
        cpa_m_at_trigger=_optional_float(run.cpa_m_at_trigger),  # type: ignore[attr-defined]
        tcpa_s_at_trigger=_optional_float(run.tcpa_s_at_trigger),  # type: ignore[attr-defined]
        min_range_m=float(run.min_range_m),  # type: ignore[attr-defined]
        opened_step=_optional_int(run.opened_step),  # type: ignore[attr-defined]
        chain_start_step=int(run.chain_start_step),  # type: ignore[attr-defined]
    )


SERIES_VESSEL_COLUMNS: tuple[str, ...] = STATE_COLUMNS


def encounter_series(
    tracks: Tracks,
    encounter: Encounter,
    from_step: int | None = None,
    to_step: int | None = None,
) -> pd.DataFrame:
    """The encounter's steps at which both vessels have samples, from ``from_step`` (default
    its start) to ``to_step`` (default its end; a later step follows the tracks past it).

    Columns: ``step``, ``timestamp``, ``own_<c>`` and ``target_<c>`` for each ``c`` in
    ``SERIES_VESSEL_COLUMNS``, then ``rel_north_m``, ``rel_east_m`` (target minus own),
    ``range_m``, ``cpa_m``, ``tcpa_s``.
    """
    first = encounter.start_step if from_step is None else from_step
    last = encounter.end_step if to_step is None else to_step
    samples = tracks.samples
    in_window = samples["step"].between(first, last)
    columns = ["step", *SERIES_VESSEL_COLUMNS]

    def side(mmsi: int, prefix: str) -> pd.DataFrame:
        rows = samples.loc[in_window & (samples["mmsi"] == mmsi), columns]
        return rows.rename(columns={c: f"{prefix}{c}" for c in SERIES_VESSEL_COLUMNS})

    series = side(encounter.own_mmsi, "own_").merge(
        side(encounter.target_mmsi, "target_"), on="step", how="inner"
    )
    series.insert(
        1, "timestamp", pd.to_datetime(series["step"] * tracks.step_s, unit="s", utc=True)
    )
    own_lat, own_lon = series["own_lat_deg"].to_numpy(), series["own_lon_deg"].to_numpy()
    tgt_lat, tgt_lon = series["target_lat_deg"].to_numpy(), series["target_lon_deg"].to_numpy()
    rel_position = ecef_m(tgt_lat, tgt_lon) - ecef_m(own_lat, own_lon)
    rel_velocity = velocity_ecef_mps(
        tgt_lat, tgt_lon, series["target_speed_mps"], series["target_cog_deg"]
    ) - velocity_ecef_mps(own_lat, own_lon, series["own_speed_mps"], series["own_cog_deg"])
    # the target's offset in own ship's tangent plane (true north, east)
    series["rel_north_m"], series["rel_east_m"] = in_tangent_plane(rel_position, own_lat, own_lon)
    range_m, cpa_m, tcpa_s = cpa_tcpa_vectors(rel_position, rel_velocity)
    series["range_m"] = range_m
    series["cpa_m"] = cpa_m
    series["tcpa_s"] = tcpa_s
    return series.reset_index(drop=True)
