"""Encounters: the pair search's candidate runs made into encounters, one per passing, from
either seat (docs/design.md §5).

- ``find_encounters``: at each step, the pairs of moving vessels (SOG ≥ ``min_sog_kn``) within
  ``candidate_range_m`` and their candidate runs (``pair_search.py``: a *candidate run* is a
  maximal run of consecutive steps in which a pair stays a candidate; a step *fires* when
  ``0 <= TCPA <= tcpa_act_s`` and ``CPA < cpa_req_m``), searched batch by batch of steps,
  then the encounters of those runs, from each own-ship seat.
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

Ranges, CPA and TCPA come from the vessels' WGS84 positions, as in the pair search
(``pair_search.py``), never from the run's map frame.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from itertools import pairwise

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..errors import NoDataError
from ..geo import ecef_m, in_tangent_plane, velocity_ecef_mps
from .pair_search import (
    EncounterParams,
    candidate_pairs_nd,
    candidate_runs,
    cpa_tcpa_vectors,
    join_runs,
    trigger_mask,
)
from .passing import horizon_steps, passing
from .tracks import STATE_COLUMNS, Tracks

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
            batch_runs, batch_firings = candidate_runs(
                i, j, step, vessel, position, velocity, params
            )
            runs.append(batch_runs)
            firings.append(batch_firings)
    passings = _passings(join_runs(runs), firings, vessel_ids, tracks, params)
    return EncounterSearch(
        encounters=_encounters(passings, vessel_ids, own, tracks),
        candidate_pair_steps=pair_steps,
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
    ``range_m``, ``cpa_m``, ``tcpa_s``, ``rel_speed_mps``.
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
    series["rel_speed_mps"] = np.linalg.norm(rel_velocity, axis=-1)
    return series.reset_index(drop=True)


def series_fires(series: pd.DataFrame, params: EncounterParams) -> NDArray[np.bool_]:
    """The rows of an ``encounter_series`` at which the trigger holds, as the pair search
    tests it (``pair_search.trigger_mask``)."""
    with np.errstate(invalid="ignore"):
        return trigger_mask(series["cpa_m"], series["tcpa_s"], series["rel_speed_mps"], params)
