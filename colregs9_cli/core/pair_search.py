"""The pair search: candidate pairs per replay step, CPA/TCPA, the trigger and the candidate
runs (docs/design.md §5); ``encounters.py`` makes the runs into encounters.

- ``cpa_tcpa``: closest point of approach under constant velocities.
- ``candidate_pairs_nd``: at each step, the pairs of points within ``candidate_range_m``, found
  with a grid of cubic cells of that size on the Earth-centred positions (each vessel is
  compared only with vessels in its own and the neighbouring cells), so the work grows with
  the number of close pairs, not with the square of the number of vessels, and nothing
  depends on a map projection: it works at any latitude and across the antimeridian.
- ``candidate_runs``, ``join_runs``: the candidate pairs' CPA and TCPA, the steps that *fire*
  (``trigger_mask``: ``0 <= TCPA <= tcpa_act_s`` and ``CPA < cpa_req_m``), and the *candidate
  runs*: maximal runs of consecutive steps in which a pair stays a candidate, each with its
  first firing step (the trigger) and its last.
- ``EncounterParams``: the knobs of the search, and of the passings its runs are chained into.

Ranges, CPA and TCPA come from the vessels' WGS84 positions and their true COG and SOG
(``geo.ecef_m``, ``geo.velocity_ecef_mps``), never from the run's map frame: they agree with a
geodesic computation to well under a millimetre at 2 nm, anywhere on Earth.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from ..units import METRES_PER_NAUTICAL_MILE
from .passing import PassingParams, horizon_steps

# Below this relative speed (m/s) the vessels keep their distance: TCPA 0, CPA = range. One
# centimetre per second is a fifth of AIS's SOG resolution (0.1 kn): two vessels on the same
# course and speed side by side differ by more than that only through the meridians'
# convergence, which is not an approach.
_STILL_MPS = 0.01


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


def candidate_runs(
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


def join_runs(runs: list[pd.DataFrame]) -> pd.DataFrame:
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
