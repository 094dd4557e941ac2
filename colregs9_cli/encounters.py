"""Encounters: candidate pairs per replay step, CPA/TCPA, and the trigger (DESIGN §5 Replay).

- ``cpa_tcpa``: closest point of approach under constant velocities.
- ``find_encounters``: at each step, the pairs of moving vessels (SOG ≥ ``min_sog_kn``) within
  ``candidate_range_m``, found with a grid of cells of that size (each vessel is compared only
  with vessels in its own and the neighbouring cells), so the work grows with the number of
  close pairs, not with the square of the number of vessels. An encounter is a maximal run of
  consecutive steps in which a pair stays a candidate. It triggers at the first step of the run
  with ``0 <= TCPA <= tcpa_act_s`` and ``CPA < cpa_req_m``.
- ``encounter_series``: one encounter's steps, own ship and target side by side, for the
  COLREGs evaluation, the rule 9 automaton and the reports.

Velocities are over ground: SOG along COG, taken as the grid COG (``cog_grid_deg``, see
``tracks``) because they are compared with positions in the frame.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from .errors import NoDataError
from .replay_params import ReplayParams
from .tracks import STATE_COLUMNS, Tracks

# Below this relative speed (m/s) the vessels keep their distance: TCPA 0, CPA = range.
_STILL_MPS = 1e-6
# Vessel positions per batch of the pair search: bounds memory, keeps the work vectorised.
_POINTS_PER_BATCH = 20_000


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
    (|v| < 1 µm/s) the range never changes: TCPA is 0 and CPA is the current range.
    """
    p_n = np.asarray(rel_north_m, dtype=float)
    p_e = np.asarray(rel_east_m, dtype=float)
    v_n = np.asarray(rel_vn_mps, dtype=float)
    v_e = np.asarray(rel_ve_mps, dtype=float)
    speed_sq = v_n * v_n + v_e * v_e
    moving = speed_sq >= _STILL_MPS * _STILL_MPS
    with np.errstate(invalid="ignore", divide="ignore"):
        tcpa_s = np.where(moving, -(p_n * v_n + p_e * v_e) / np.where(moving, speed_sq, 1.0), 0.0)
    tcpa_s = np.where(np.isnan(speed_sq), np.nan, tcpa_s)
    cpa_m = np.hypot(p_n + v_n * tcpa_s, p_e + v_e * tcpa_s)
    return cpa_m, tcpa_s


def trigger_mask(
    cpa_m: ArrayLike, tcpa_s: ArrayLike, rel_speed_mps: ArrayLike, params: ReplayParams
) -> NDArray[np.bool_]:
    """The paper's trigger ``0 <= TCPA <= tcpa_act_s and CPA < cpa_req_m``.

    A pair with no relative motion (relative speed < 1 µm/s, e.g. parallel courses at equal
    speed) never triggers: nothing approaches, even if it sails within ``cpa_req_m``.
    """
    tcpa = np.asarray(tcpa_s, dtype=float)
    return (
        (tcpa >= 0.0)
        & (tcpa <= params.tcpa_act_s)
        & (np.asarray(cpa_m, dtype=float) < params.cpa_req_m)
        & (np.asarray(rel_speed_mps, dtype=float) >= _STILL_MPS)
    )


def velocity_mps(
    speed_mps: ArrayLike, course_deg: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(north, east) velocity components of a speed along a course.

    The components are along the axes the course is measured from: give a grid course
    (``cog_grid_deg``) for a velocity in the ``LocalFrame``.
    """
    course_rad = np.radians(np.asarray(course_deg, dtype=float))
    speed = np.asarray(speed_mps, dtype=float)
    return speed * np.cos(course_rad), speed * np.sin(course_rad)


@dataclass(frozen=True)
class Encounter:
    """One encounter seen from the own-ship seat.

    ``start_step``..``end_step`` (inclusive, grid steps of ``Tracks``) is the maximal run in
    which the pair is a candidate. ``trigger_step`` is None when the run never triggered; the
    ``*_at_trigger`` values are then None too. ``min_range_m`` is the least range in the run.
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
    """Index pairs (i, j), i ≠ j, of points at the same step within ``range_m`` (inclusive).

    Each unordered pair appears once. Points are hashed into square cells of side
    ``range_m``; a point is compared with the points of its own cell and of four of its
    eight neighbours (the other four see it from their side).
    """
    if len(step) == 0:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    cell_n = np.floor(north_m / range_m).astype(np.int64)
    cell_e = np.floor(east_m / range_m).astype(np.int64)
    cell_n -= cell_n.min() - 1
    cell_e -= cell_e.min() - 1
    height = int(cell_e.max()) + 2
    width = int(cell_n.max()) + 2
    key = ((step - step.min()) * width + cell_n) * height + cell_e
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    firsts: list[NDArray[np.intp]] = []
    seconds: list[NDArray[np.intp]] = []
    for d_n, d_e in ((0, 0), (0, 1), (1, -1), (1, 0), (1, 1)):
        wanted = sorted_key + d_n * height + d_e
        lo = np.searchsorted(sorted_key, wanted, side="left")
        hi = np.searchsorted(sorted_key, wanted, side="right")
        if d_n == 0 and d_e == 0:
            lo = np.arange(len(sorted_key)) + 1  # the same cell: only later points
        counts = np.maximum(hi - lo, 0)
        total = int(counts.sum())
        if total == 0:
            continue
        position = np.repeat(np.arange(len(sorted_key)), counts)
        start = np.cumsum(counts) - counts
        partner = lo[position] + (np.arange(total) - start[position])
        firsts.append(order[position])
        seconds.append(order[partner])
    if not firsts:
        empty = np.zeros(0, dtype=np.intp)
        return empty, empty
    first = np.concatenate(firsts)
    second = np.concatenate(seconds)
    near = np.hypot(north_m[first] - north_m[second], east_m[first] - east_m[second]) <= range_m
    return first[near], second[near]


def find_encounters(
    tracks: Tracks,
    params: ReplayParams,
    own_mmsi: Iterable[int] | None = None,
) -> EncounterSearch:
    """All encounters in ``tracks``.

    With ``own_mmsi`` given, only those vessels take the own-ship seat (a pair of two of them
    is reported from both sides); otherwise every vessel does, so each pair appears twice.
    An own MMSI with no samples is a ``NoDataError``.
    """
    samples = tracks.samples
    own = None if own_mmsi is None else frozenset(int(m) for m in own_mmsi)
    if own is not None:
        absent = sorted(own - set(samples["mmsi"].unique().tolist()))
        if absent:
            raise NoDataError(
                f"own MMSI {absent[0]} is not in the AIS data after cleaning; check --own-mmsi "
                "against the vessels in the input and the query's region and time window"
            )
    moving = samples["sog_kn"].to_numpy() >= params.min_sog_kn
    rows = np.flatnonzero(moving)
    step = samples["step"].to_numpy()[rows]
    by_step = np.argsort(step, kind="stable")
    rows, step = rows[by_step], step[by_step]
    north = samples["north_m"].to_numpy()[rows]
    east = samples["east_m"].to_numpy()[rows]
    v_n, v_e = velocity_mps(
        samples["speed_mps"].to_numpy()[rows], samples["cog_grid_deg"].to_numpy()[rows]
    )
    vessel_ids, vessel = np.unique(samples["mmsi"].to_numpy()[rows], return_inverse=True)

    runs: list[pd.DataFrame] = []
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
            i, j = candidate_pairs(step[part], north[part], east[part], params.candidate_range_m)
            i, j = i + lo, j + lo
            pair_steps += len(i)
            runs.append(_batch_runs(i, j, step, vessel, north, east, v_n, v_e, params))
    return EncounterSearch(
        encounters=_encounters(_join_runs(runs), vessel_ids, own, tracks),
        candidate_pair_steps=pair_steps,
    )


def _batch_runs(
    i: NDArray[np.intp],
    j: NDArray[np.intp],
    step: NDArray[np.int64],
    vessel: NDArray[np.intp],
    north: NDArray[np.float64],
    east: NDArray[np.float64],
    v_n: NDArray[np.float64],
    v_e: NDArray[np.float64],
    params: ReplayParams,
) -> pd.DataFrame:
    """Runs of consecutive candidate steps per pair within one batch of steps."""
    swap = vessel[i] > vessel[j]
    a = np.where(swap, j, i)
    b = np.where(swap, i, j)
    # One integer key orders the rows by (vessel_a, vessel_b, step), faster than a lexsort.
    batch_steps = int(step[a].max() - step[a].min()) + 1 if len(a) else 1
    pair_code = vessel[a].astype(np.int64) * (int(vessel.max()) + 1) + vessel[b]
    order = np.argsort(pair_code * batch_steps + (step[a] - step[a].min(initial=0)), kind="stable")
    a, b = a[order], b[order]
    cpa_m, tcpa_s = cpa_tcpa(
        north[b] - north[a], east[b] - east[a], v_n[b] - v_n[a], v_e[b] - v_e[a]
    )
    frame = pd.DataFrame(
        {
            "vessel_a": vessel[a],
            "vessel_b": vessel[b],
            "step": step[a],
            "range_m": np.hypot(north[b] - north[a], east[b] - east[a]),
            "cpa_m": cpa_m,
            "tcpa_s": tcpa_s,
        }
    )
    rel_speed_mps = np.hypot(v_n[b] - v_n[a], v_e[b] - v_e[a])
    fires = trigger_mask(cpa_m, tcpa_s, rel_speed_mps, params)
    return _runs(frame, pd.Series(fires, index=frame.index))


def _runs(frame: pd.DataFrame, fires: pd.Series) -> pd.DataFrame:
    """Collapse rows sorted by (vessel_a, vessel_b, step) into runs of consecutive steps."""
    same_pair = (frame["vessel_a"].diff() == 0) & (frame["vessel_b"].diff() == 0)
    run = (~(same_pair & (frame["step"].diff() == 1))).cumsum()
    fired = frame[fires.to_numpy()]
    grouped = frame.groupby(run.to_numpy(), sort=True)
    summary = grouped.agg(
        vessel_a=("vessel_a", "first"),
        vessel_b=("vessel_b", "first"),
        start_step=("step", "min"),
        end_step=("step", "max"),
        min_range_m=("range_m", "min"),
    )
    trigger = fired.groupby(run.to_numpy()[fires.to_numpy()], sort=True).first()
    summary["trigger_step"] = trigger["step"].reindex(summary.index).astype("Int64")
    for name in ("range_m", "cpa_m", "tcpa_s"):
        summary[f"{name}_at_trigger"] = trigger[name].reindex(summary.index)
    return summary.reset_index(drop=True)


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
        )
        .reset_index(drop=True)
    )


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


def _encounter(run: object, own_mmsi: int, target_mmsi: int, tracks: Tracks) -> Encounter:
    start = tracks.step_to_timestamp(int(run.start_step))  # type: ignore[attr-defined]
    trigger_step = run.trigger_step  # type: ignore[attr-defined]
    trigger_step = None if pd.isna(trigger_step) else int(trigger_step)
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
    own_vn, own_ve = velocity_mps(series["own_speed_mps"], series["own_cog_grid_deg"])
    tgt_vn, tgt_ve = velocity_mps(series["target_speed_mps"], series["target_cog_grid_deg"])
    series["rel_north_m"] = series["target_north_m"] - series["own_north_m"]
    series["rel_east_m"] = series["target_east_m"] - series["own_east_m"]
    series["range_m"] = np.hypot(series["rel_north_m"], series["rel_east_m"])
    cpa_m, tcpa_s = cpa_tcpa(
        series["rel_north_m"], series["rel_east_m"], tgt_vn - own_vn, tgt_ve - own_ve
    )
    series["cpa_m"] = cpa_m
    series["tcpa_s"] = tcpa_s
    return series.reset_index(drop=True)
