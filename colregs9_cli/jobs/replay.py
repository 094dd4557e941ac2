"""``colregs9 replay``: historical AIS, pair by pair, through G_a and G_d (DESIGN §5).

The pipeline, slab by slab in time (``replay_input.py`` reads the AIS through the query one
slab at a time, ``slabs.py`` segments and evaluates them): the run's local frame (the
query's region, or the extent of the data when the query has none) → per-vessel tracks
(``tracks.py``; reports dropped as same-second duplicates or speed jumps go into the rejects
ledger) → encounters (``encounters.py``) → for each triggered pair, evaluated once for both seats:

- **G_a** (``colregs.py``) classifies the pair at the trigger. That situation and both roles
  are held until the pair is past (rule 13(d)); the time series also records the
  instantaneous geometry of every step (``situation_now``).
- **G_d** (``rule9.py``) runs in both seats at every step, and ``decide_pair`` combines them
  with rules 13 and 18 into the pair's final roles. The verdict is the one at the trigger.
- **Manoeuvrability** (event d3) is estimated for both vessels at the trigger (it is the
  verdict and the figure), and later for each vessel that does not report a restricted
  status, at most every ``reassess_every_s``; otherwise the last estimate is carried
  forward. The give-way vessel's estimate is G_d's d3; the stand-on vessel's tells whether
  both are restricted (``rule9.decide_pair``). No chart, or a vessel outside the chart's
  coverage, gives ``unknown``: ¬d3 for the automaton, recorded as ``unknown``.
- **Dimensions** a vessel does not report take the defaults of ``vessel_defaults.py`` (by
  Class A/B and ship type); a verdict in which the estimator's answer for such a vessel
  entered G_d is flagged ``verdict_rests_on_defaults``.
- **Audit facts** (``audit.py``) over the pair's data from the trigger: the series follows
  both tracks past the end of the candidate run, to the pass or for at most TCPA +
  ``tcpa_act_s`` after the trigger, and stops at the first step where either track stops.

Each pair gives one ``PairOutcome`` (pairs.csv) and one ``EncounterOutcome`` per reported
seat (encounters.csv and the per-encounter files); both seats of a pair carry the same
situation, final roles and audit facts.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..ais.ledger import RejectReason, RejectsLedger
from ..ais.load import InputFile
from ..charts.chart import Chart, ChartSource, project_charts, read_charts
from ..core.audit import (
    INSUFFICIENT_CONDUCT,
    Conduct,
    ConductParams,
    all_of,
    conduct,
    negated,
    passage,
)
from ..core.colregs import (
    ColregsEvaluation,
    Kinematics,
    Role,
    colregs_params_from_table,
    evaluate_colregs,
)
from ..core.encounters import Encounter, encounter_series, velocity_mps
from ..core.manoeuvrability import (
    ManoeuvrabilityAssessment,
    ManoeuvrabilityParams,
    Restriction,
    assess_manoeuvrability,
    unplaced_assessment,
)
from ..core.replay_params import ReplayParams, replay_params_from_table
from ..core.replay_results import (
    SERIES_COLUMNS,
    SERIES_VESSEL_FIELDS,
    EncounterOutcome,
    EncounterSummary,
    PairOutcome,
    PairSummary,
    ReplayCounts,
    ReplayResult,
    ReplayRunParams,
    VesselAtTrigger,
)
from ..core.rule9 import Finding, PairVerdict, decide_pair, nav_status_finding
from ..core.tracks import REQUIRED_COLUMNS, STATIC_COLUMNS, Tracks, TrackStats, context_s
from ..core.vessel_defaults import VesselDimensions, vessel_dimensions
from ..errors import ChartError, NoDataError, ParameterError
from ..geo import LocalFrame, sail
from ..outputs import check_out_dir
from ..progress import progress_bar, progress_enabled
from ..provenance import charts_manifest, inputs_manifest, jsonable, query_manifest, run_header
from ..query import Query, everything_query, load_query
from ..report.replay_report import format_summary, write_replay_reports
from .replay_input import open_replay_input, segment_input_part
from .slabs import (
    Extent,
    Segmentation,
    SlabContext,
    SlabResult,
    run_slabs,
)

# The canonical columns a replay reads: those of the reports and the static data.
REPLAY_COLUMNS: tuple[str, ...] = (*REQUIRED_COLUMNS, *STATIC_COLUMNS)


def default_out_dir(query_name: str) -> Path:
    return Path("reports") / f"replay-{query_name}"


def run_params(
    query: Query,
    own_mmsi: Sequence[int] = (),
    overrides: dict[str, dict[str, Any]] | None = None,
) -> ReplayRunParams:
    """The run's parameters: the query's tables, then the CLI overrides (``None`` = not given).

    ``overrides`` maps a table name (``replay``, ``colregs``, ``manoeuvrability``) to the
    values given on the command line; each is validated by its dataclass.
    """
    where = f"{query.source if query.source is not None else 'query'}"
    tables = query.tables
    replay = replay_params_from_table(dict(tables.get("replay", {})), f"{where} [replay]")
    colregs = colregs_params_from_table(dict(tables.get("colregs", {})), f"{where} [colregs]")
    manoeuvrability = ManoeuvrabilityParams.from_table(
        dict(tables.get("manoeuvrability", {})), f"{where} [manoeuvrability]"
    )
    given = {
        table: {k: v for k, v in values.items() if v is not None}
        for table, values in (overrides or {}).items()
    }
    replay = dataclasses.replace(replay, **given.get("replay", {}))
    colregs = dataclasses.replace(colregs, **given.get("colregs", {}))
    manoeuvrability = dataclasses.replace(manoeuvrability, **given.get("manoeuvrability", {}))
    return ReplayRunParams(
        replay=replay,
        colregs=colregs,
        manoeuvrability=manoeuvrability,
        own_mmsi=tuple(sorted({int(m) for m in own_mmsi})),
    )


# Charts farther than this from every AIS position are left out of a run (``ChartSource.near``);
# a ship domain reaches a few kilometres at most.
CHART_MARGIN_DEG = 0.25


def run_frame(query: Query, extent: Extent, chart: ChartSource | None = None) -> LocalFrame:
    """A frame centred on the charts, where the manoeuvrability estimate is made; without
    charts, on the query region, else on the data (``slabs.Extent.frame``).

    The frame carries the chart, the manoeuvrability estimate and the figures; the geometry
    between vessels never uses it (``encounters.py``), and the tracks are resampled on the
    Earth, so a position beyond its reach only loses its frame coordinates. The charts come
    first because a national query's centre may lie hundreds of kilometres from a harbour
    cell, where the frame's scale would bend the ship domains.
    """
    if chart is not None:
        return LocalFrame.centred_on(*chart.bounds_wgs84())
    frame = query.frame()
    if frame is not None:
        return frame
    return extent.frame()


def _ledger_with_tracks(ledger: RejectsLedger, stats: TrackStats) -> RejectsLedger:
    """The loader's ledger plus the reports that segmentation dropped."""
    result = copy.deepcopy(ledger)
    dropped = stats.same_time_dropped + stats.speed_jump_dropped
    result.rows_used -= dropped
    result.reject(RejectReason.DUPLICATE, stats.same_time_dropped)
    result.reject(RejectReason.SPEED_JUMP, stats.speed_jump_dropped)
    return result


def _text_or_none(value: Any) -> str | None:
    return None if value is None or (isinstance(value, float) and math.isnan(value)) else str(value)


def _static(vessels: pd.DataFrame, mmsi: int) -> dict[str, Any]:
    """A vessel's static AIS fields (empty when she sent none)."""
    if mmsi not in vessels.index:
        return {}
    return {name: value for name, value in vessels.loc[mmsi].items() if not _missing(value)}


def _missing(value: Any) -> bool:
    return value is None or (not isinstance(value, str) and bool(pd.isna(value)))


def _nav_status(value: Any) -> int | None:
    return None if pd.isna(value) else int(value)


@dataclass
class _Estimator:
    """A vessel's manoeuvrability estimate, made when needed and carried forward."""

    chart: Chart | None
    params: ManoeuvrabilityParams
    dimensions: VesselDimensions
    reassess_steps: int
    assessed_row: int = -1
    assessment: ManoeuvrabilityAssessment | None = None

    def at(self, state: dict[str, np.ndarray], row: int, needed: bool) -> ManoeuvrabilityAssessment:
        """The estimate for ``row`` of the vessel's state arrays (made anew when due)."""
        stale = self.assessment is None or row - self.assessed_row >= self.reassess_steps
        if self.assessment is None or (needed and stale):
            dims = self.dimensions
            placed = all(math.isfinite(state[name][row]) for name in ("north_m", "east_m"))
            if placed and math.isfinite(state["course_deg"][row]):
                self.assessment = assess_manoeuvrability(
                    self.chart,
                    float(state["north_m"][row]),
                    float(state["east_m"][row]),
                    float(state["course_deg"][row]),
                    float(state["speed_mps"][row]),
                    dims.length_m,
                    dims.breadth_m,
                    dims.draught_m,
                    self.params,
                )
            else:
                self.assessment = unplaced_assessment(
                    dims.length_m, dims.breadth_m, dims.draught_m, self.params
                )
            self.assessed_row = row
        return self.assessment


def pair_tracks(tracks: Tracks, mmsis: tuple[int, int]) -> Tracks:
    """The two vessels' tracks only: ``encounter_series`` then scans two tracks, not all.

    Relies on ``Tracks.samples`` being sorted by MMSI.
    """
    vessel = tracks.samples["mmsi"].to_numpy()
    parts = [
        tracks.samples.iloc[
            np.searchsorted(vessel, mmsi, "left") : np.searchsorted(vessel, mmsi, "right")
        ]
        for mmsi in mmsis
    ]
    return dataclasses.replace(tracks, samples=pd.concat(parts))


def _contiguous_rows(steps: np.ndarray) -> int:
    """How many rows from the first run on consecutive steps (both tracks present)."""
    gaps = np.flatnonzero(np.diff(steps) != 1)
    return int(gaps[0]) + 1 if len(gaps) else len(steps)


def _state(series: pd.DataFrame, prefix: str) -> dict[str, np.ndarray]:
    """A vessel's state arrays for the estimator: the chart lives in the local frame, so the
    arcs start from the grid course."""
    return {
        name: series[f"{prefix}{column}"].to_numpy(dtype=float)
        for name, column in (
            ("north_m", "north_m"),
            ("east_m", "east_m"),
            ("course_deg", "course_grid_deg"),
            ("speed_mps", "speed_mps"),
        )
    }


def _mmsi_list(mmsis: Sequence[int]) -> str:
    return ";".join(str(m) for m in mmsis)


def _joined(values: Sequence[Any]) -> str:
    return ";".join(str(v) for v in values)


@dataclass(frozen=True)
class _PairSteps:
    """Per-step results of one pair in vessel order (a, b): the evaluation behind its rows."""

    series: pd.DataFrame  # from the trigger to the pass, columns own_* = a, target_* = b
    g_a: ColregsEvaluation
    held: ColregsEvaluation  # the trigger's situation, repeated
    verdicts: list[PairVerdict]
    estimates: tuple[list[Restriction], list[Restriction]]
    assessed_row: tuple[list[int], list[int]]
    trigger_assessments: tuple[ManoeuvrabilityAssessment, ManoeuvrabilityAssessment]


def _pair_steps(
    series: pd.DataFrame,
    dimensions: tuple[VesselDimensions, VesselDimensions],
    chart: Chart | None,
    params: ReplayRunParams,
    step_s: float,
) -> _PairSteps:
    """G_a, the estimates and G_d of both seats at every step of ``series`` (a = own_)."""
    g_a = evaluate_colregs(
        *Kinematics.pair_from_series(series),
        params.colregs,
        course_judged_above_kn=params.replay.course_judged_above_kn,
    )
    rows = len(series)
    held = ColregsEvaluation(
        **{
            name: np.repeat(getattr(g_a, name)[:1], rows)
            for name in ("situation", "own_role", "target_role", "own_overtaking", "ambiguous")
        },
        basis=np.repeat(g_a.basis[:1], rows),
        beta_deg=g_a.beta_deg,
        beta_prime_deg=g_a.beta_prime_deg,
        closing=g_a.closing,
    )
    situation = held.situation[0]
    roles = (held.own_role[0], held.target_role[0])
    statuses = params.replay.restricted_nav_statuses
    reassess = max(1, round(params.replay.reassess_every_s / step_s))
    estimators = tuple(
        _Estimator(chart, params.manoeuvrability, dims, reassess) for dims in dimensions
    )
    states = (_state(series, "own_"), _state(series, "target_"))
    nav = (
        [_nav_status(v) for v in series["own_nav_status"].tolist()],
        [_nav_status(v) for v in series["target_nav_status"].tolist()],
    )
    estimates: tuple[list[Restriction], list[Restriction]] = ([], [])
    assessed_row: tuple[list[int], list[int]] = ([], [])
    verdicts: list[PairVerdict] = []
    cache: dict[tuple[Any, ...], PairVerdict] = {}
    trigger: list[ManoeuvrabilityAssessment] = []
    for row in range(rows):
        for vessel in (0, 1):
            # Every vessel's estimate counts (decide_pair): the give-way vessel's for G_d,
            # the stand-on vessel's for "both restricted". A reported status makes it moot.
            needed = nav_status_finding(nav[vessel][row], statuses) is not Finding.TRUE
            assessment = estimators[vessel].at(states[vessel], row, needed=needed)
            if row == 0:
                trigger.append(assessment)
            estimates[vessel].append(assessment.restriction)
            assessed_row[vessel].append(estimators[vessel].assessed_row)
        key = (nav[0][row], nav[1][row], estimates[0][row], estimates[1][row])
        if key not in cache:
            cache[key] = decide_pair(situation, roles, (key[0], key[1]), (key[2], key[3]), statuses)
        verdicts.append(cache[key])
    return _PairSteps(
        series=series,
        g_a=g_a,
        held=held,
        verdicts=verdicts,
        estimates=estimates,
        assessed_row=assessed_row,
        trigger_assessments=(trigger[0], trigger[1]),
    )


def rests_on_defaults(
    verdict: PairVerdict,
    dimensions: tuple[VesselDimensions, VesselDimensions],
    estimates: tuple[Restriction, Restriction],
    nav_status: tuple[int | None, int | None],
    restricted_nav_statuses: frozenset[int],
) -> bool:
    """True when an estimate made from defaulted dimensions decided the verdict: the other
    answer about that vessel would give other final roles or another deciding rule. This
    covers G_d's d3 about the give-way vessel and the stand-on vessel's "clear" that let rule
    9 choose between them. "Unknown" (off the chart) rests on no dimension."""
    other_answer = {
        Restriction.RESTRICTED: Restriction.NOT_RESTRICTED,
        Restriction.NOT_RESTRICTED: Restriction.RESTRICTED,
    }
    for vessel in (0, 1):
        estimate = estimates[vessel]
        if estimate not in other_answer or not bool(dimensions[vessel].defaulted):
            continue
        changed = list(estimates)
        changed[vessel] = other_answer[estimate]
        alternative = decide_pair(
            verdict.situation,
            verdict.role_colregs,
            nav_status,
            (changed[0], changed[1]),
            restricted_nav_statuses,
        )
        if (alternative.role_final, alternative.deciding_rule) != (
            verdict.role_final,
            verdict.deciding_rule,
        ):
            return True
    return False


@dataclass(frozen=True)
class _Audit:
    """The pass and both vessels' conduct up to the closest approach (vessel order a, b)."""

    covers_cpa: bool
    min_separation_m: float | None
    cpa_utc: pd.Timestamp | None
    conducts: tuple[Conduct, Conduct]
    before_cpa_s: tuple[float | None, float | None]


def _audit(window: pd.DataFrame, params: ReplayParams, step_s: float) -> _Audit:
    seen = passage(window["range_m"].to_numpy(), window["tcpa_s"].to_numpy())
    if not seen.covers_cpa or seen.cpa_row is None:
        return _Audit(False, None, None, (INSUFFICIENT_CONDUCT, INSUFFICIENT_CONDUCT), (None, None))
    until = window.iloc[: seen.cpa_row + 1]
    conduct_params = ConductParams(
        params.course_change_deg,
        params.speed_change_frac,
        params.speed_change_min_kn,
        params.course_judged_above_kn,
    )
    conducts = tuple(
        conduct(
            until[f"{prefix}course_deg"].to_numpy(dtype=float),
            until[f"{prefix}sog_kn"].to_numpy(dtype=float),
            conduct_params,
        )
        for prefix in ("own_", "target_")
    )
    before = tuple(
        None if c.action_row is None else (seen.cpa_row - c.action_row) * step_s for c in conducts
    )
    return _Audit(
        covers_cpa=True,
        min_separation_m=seen.min_separation_m,
        cpa_utc=window["timestamp"].iloc[seen.cpa_row],
        conducts=(conducts[0], conducts[1]),
        before_cpa_s=(before[0], before[1]),
    )


def evaluate_pair(
    tracks: Tracks,
    encounter: Encounter,
    seats: Sequence[int],
    chart: Chart | None,
    params: ReplayRunParams,
) -> PairOutcome:
    """One triggered pair, evaluated once: its pairs.csv row and the rows of ``seats`` (the
    own-ship MMSIs to report). ``encounter`` may be either seat's."""
    if encounter.trigger_step is None or encounter.tcpa_s_at_trigger is None:
        raise ValueError(f"encounter {encounter.encounter_id} never triggered")
    a, b = sorted((encounter.own_mmsi, encounter.target_mmsi))
    oriented = dataclasses.replace(encounter, own_mmsi=a, target_mmsi=b)
    step_s = tracks.step_s
    horizon = math.ceil((encounter.tcpa_s_at_trigger + params.replay.tcpa_act_s) / step_s)
    both = pair_tracks(tracks, (a, b))
    full = encounter_series(
        both, oriented, to_step=max(encounter.end_step, encounter.trigger_step + horizon)
    )
    full = full.iloc[: _contiguous_rows(full["step"].to_numpy())].reset_index(drop=True)
    window = full[full["step"] >= encounter.trigger_step].reset_index(drop=True)
    audit = _audit(window, params.replay, step_s)
    # G_a and G_d run until the pair is past: to the pass, the first step at which it opens,
    # which is also the last step the audit looks at (its closest approach may lie there).
    opening = np.flatnonzero(window["tcpa_s"].to_numpy()[1:] < 0.0)
    series = window.iloc[: int(opening[0]) + 2 if len(opening) else len(window)]

    dimensions = (
        vessel_dimensions(_static(tracks.vessels, a), params.replay.dimension_overrides),
        vessel_dimensions(_static(tracks.vessels, b), params.replay.dimension_overrides),
    )
    steps = _pair_steps(series, dimensions, chart, params, step_s)
    names = tuple(
        _text_or_none(tracks.vessels["name"].get(m)) if "name" in tracks.vessels.columns else None
        for m in (a, b)
    )
    trigger = series.iloc[0]
    at_cpa = {
        prefix: sail(
            trigger[f"{prefix}lat_deg"],
            trigger[f"{prefix}lon_deg"],
            trigger[f"{prefix}cog_deg"],
            trigger[f"{prefix}speed_mps"] * trigger["tcpa_s"],
        )
        for prefix in ("own_", "target_")
    }
    vessels = tuple(
        VesselAtTrigger(
            mmsi=mmsi,
            name=names[i],
            dimensions=dimensions[i],
            nav_status=_nav_status(trigger[f"{prefix}nav_status"]),
            course_deg=float(trigger[f"{prefix}course_deg"]),
            speed_kn=float(trigger[f"{prefix}sog_kn"]),
            lat_deg=float(trigger[f"{prefix}lat_deg"]),
            lon_deg=float(trigger[f"{prefix}lon_deg"]),
            lat_deg_at_cpa=float(at_cpa[prefix][0]),
            lon_deg_at_cpa=float(at_cpa[prefix][1]),
            estimated_restricted=steps.estimates[i][0],
            conduct=audit.conducts[i],
            action_before_cpa_s=audit.before_cpa_s[i],
        )
        for i, (mmsi, prefix) in enumerate(((a, "own_"), (b, "target_")))
    )
    pair_summary = _pair_summary(
        encounter,
        (vessels[0], vessels[1]),
        steps,
        audit,
        seats,
        params.replay.restricted_nav_statuses,
    )
    outcomes = []
    for own in sorted(set(seats)):
        flip = own == b
        outcomes.append(
            _seat_outcome(
                pair_summary,
                steps,
                (vessels[0], vessels[1]),
                full,
                flip,
                encounter,
                params,
                tracks.frame,
            )
        )
    return PairOutcome(summary=pair_summary, seats=tuple(outcomes))


def _pair_summary(
    encounter: Encounter,
    vessels: tuple[VesselAtTrigger, VesselAtTrigger],
    steps: _PairSteps,
    audit: _Audit,
    seats: Sequence[int],
    restricted_nav_statuses: frozenset[int],
) -> PairSummary:
    verdict = steps.verdicts[0]
    trigger = steps.series.iloc[0]
    a, b = vessels
    give_way = _with_role(vessels, verdict, Role.GIVE_WAY)
    stand_on = _with_role(vessels, verdict, Role.STAND_ON)
    return PairSummary(
        pair_id=f"{encounter.start:%Y%m%dT%H%M%S}-{a.mmsi}+{b.mmsi}",
        mmsi_a=a.mmsi,
        mmsi_b=b.mmsi,
        name_a=a.name,
        name_b=b.name,
        seats_reported=_mmsi_list(sorted(set(seats))),
        start_utc=encounter.start,
        trigger_utc=trigger["timestamp"],
        end_utc=encounter.end,
        situation=verdict.situation,
        situation_ambiguous=bool(steps.held.ambiguous[0]),
        situation_basis=steps.held.basis[0],
        role_colregs_a=verdict.role_colregs[0],
        role_colregs_b=verdict.role_colregs[1],
        nav_status_a=a.nav_status,
        nav_status_b=b.nav_status,
        estimated_restricted_a=a.estimated_restricted,
        estimated_restricted_b=b.estimated_restricted,
        automaton_path_a=verdict.seat_a.path_text,
        automaton_path_b=verdict.seat_b.path_text,
        rule9_applied=verdict.rule9_applied,
        deciding_rule=verdict.deciding_rule,
        both_restricted=verdict.both_restricted,
        role_final_a=verdict.role_final[0],
        role_final_b=verdict.role_final[1],
        give_way_vessels=_mmsi_list([v.mmsi for v in give_way]),
        verdict_rests_on_defaults=rests_on_defaults(
            verdict,
            (a.dimensions, b.dimensions),
            (a.estimated_restricted, b.estimated_restricted),
            (a.nav_status, b.nav_status),
            restricted_nav_statuses,
        ),
        range_m_at_trigger=float(trigger["range_m"]),
        cpa_m=float(trigger["cpa_m"]),
        tcpa_s=float(trigger["tcpa_s"]),
        lat_deg_at_trigger_a=a.lat_deg,
        lon_deg_at_trigger_a=a.lon_deg,
        lat_deg_at_trigger_b=b.lat_deg,
        lon_deg_at_trigger_b=b.lon_deg,
        lat_deg_at_cpa_a=a.lat_deg_at_cpa,
        lon_deg_at_cpa_a=a.lon_deg_at_cpa,
        lat_deg_at_cpa_b=b.lat_deg_at_cpa,
        lon_deg_at_cpa_b=b.lon_deg_at_cpa,
        data_covers_cpa=audit.covers_cpa,
        actual_min_separation_m=audit.min_separation_m,
        actual_min_separation_utc=audit.cpa_utc,
        give_way_vessel_acted=all_of(v.conduct.changed for v in give_way) if give_way else None,
        give_way_action=_joined([v.conduct.action.value for v in give_way]),
        action_before_cpa_s=_joined([_seconds(v.action_before_cpa_s) for v in give_way]),
        stand_on_vessel_kept_course=(
            all_of(negated(v.conduct.changed) for v in stand_on) if stand_on else None
        ),
        action_a=a.conduct.action,
        action_b=b.conduct.action,
        length_m_a=a.dimensions.length_m,
        breadth_m_a=a.dimensions.breadth_m,
        draught_m_a=a.dimensions.draught_m,
        defaulted_dimensions_a=a.dimensions.defaulted_text,
        length_m_b=b.dimensions.length_m,
        breadth_m_b=b.dimensions.breadth_m,
        draught_m_b=b.dimensions.draught_m,
        defaulted_dimensions_b=b.dimensions.defaulted_text,
    )


def _with_role(
    vessels: tuple[VesselAtTrigger, VesselAtTrigger], verdict: PairVerdict, role: Role
) -> list[VesselAtTrigger]:
    return [v for v, final in zip(vessels, verdict.role_final, strict=True) if final is role]


def _seconds(value: float | None) -> str:
    return "" if value is None else f"{value:g}"


def _seat_series(steps: _PairSteps, flip: bool, statuses: frozenset[int]) -> pd.DataFrame:
    """The time series seen from one seat: own_* is vessel b when ``flip``, else vessel a."""
    series = steps.series
    own_prefix, target_prefix = ("target_", "own_") if flip else ("own_", "target_")
    own, target = (1, 0) if flip else (0, 1)
    timestamps = series["timestamp"].tolist()
    seats = [(v.seat_b, v.seat_a) if flip else (v.seat_a, v.seat_b) for v in steps.verdicts]
    columns: dict[str, Any] = {
        "step": series["step"].to_numpy(),
        "timestamp": series["timestamp"].to_numpy(),
    }
    for name in SERIES_VESSEL_FIELDS:
        columns[f"own_{name}"] = series[f"{own_prefix}{name}"].to_numpy()
        columns[f"target_{name}"] = series[f"{target_prefix}{name}"].to_numpy()
    for name in ("range_m", "cpa_m", "tcpa_s"):
        columns[name] = series[name].to_numpy()
    bearings = (
        (steps.g_a.beta_prime_deg, steps.g_a.beta_deg)
        if flip
        else (
            steps.g_a.beta_deg,
            steps.g_a.beta_prime_deg,
        )
    )
    columns["beta_deg"], columns["beta_prime_deg"] = bearings
    roles = (
        (steps.held.target_role, steps.held.own_role)
        if flip
        else (
            steps.held.own_role,
            steps.held.target_role,
        )
    )
    columns |= {
        "situation_now": [s.value for s in steps.g_a.situation],
        "situation_now_ambiguous": steps.g_a.ambiguous,
        "situation": [s.value for s in steps.held.situation],
        "own_role_colregs": [r.value for r in roles[0]],
        "target_role_colregs": [r.value for r in roles[1]],
    }
    for prefix, vessel in (("own_", own), ("target_", target)):
        status = series[f"{'target_' if vessel else 'own_'}nav_status"].tolist()
        columns[f"{prefix}reports_restricted"] = [
            nav_status_finding(_nav_status(v), statuses) is Finding.TRUE for v in status
        ]
        columns[f"{prefix}estimated_restricted"] = [e.value for e in steps.estimates[vessel]]
        columns[f"{prefix}assessed_utc"] = [timestamps[r] for r in steps.assessed_row[vessel]]
    columns |= {
        "automaton_state": [own_seat.final_state.value for own_seat, _ in seats],
        "automaton_path": [own_seat.path_text for own_seat, _ in seats],
        "target_seat_automaton_path": [other.path_text for _, other in seats],
        "rule9_applied": [v.rule9_applied for v in steps.verdicts],
        "deciding_rule": [v.deciding_rule.value for v in steps.verdicts],
        "own_role_final": [v.role_final[own].value for v in steps.verdicts],
        "target_role_final": [v.role_final[target].value for v in steps.verdicts],
    }
    return pd.DataFrame(columns)[list(SERIES_COLUMNS)]


def _give_way_side(own_role: Role, target_role: Role) -> str:
    sides = [
        side for side, role in (("own", own_role), ("target", target_role)) if role is Role.GIVE_WAY
    ]
    return "+".join(sides) if sides else "none"


def _seat_outcome(
    pair: PairSummary,
    steps: _PairSteps,
    vessels: tuple[VesselAtTrigger, VesselAtTrigger],
    full: pd.DataFrame,
    flip: bool,
    encounter: Encounter,
    params: ReplayRunParams,
    run_frame: LocalFrame,
) -> EncounterOutcome:
    """The encounters.csv row, series and figure data of one seat of a pair."""
    own_index, target_index = (1, 0) if flip else (0, 1)
    own, target = vessels[own_index], vessels[target_index]
    verdict = steps.verdicts[0]
    own_seat, other_seat = (
        (verdict.seat_b, verdict.seat_a) if flip else (verdict.seat_a, verdict.seat_b)
    )
    own_final, target_final = verdict.role_final[own_index], verdict.role_final[target_index]
    own_prefix, target_prefix = ("target_", "own_") if flip else ("own_", "target_")
    trigger = steps.series.iloc[0]
    summary = EncounterSummary(
        encounter_id=f"{encounter.start:%Y%m%dT%H%M%S}-{own.mmsi}-{target.mmsi}",
        pair_id=pair.pair_id,
        own_mmsi=own.mmsi,
        target_mmsi=target.mmsi,
        own_name=own.name,
        target_name=target.name,
        start_utc=pair.start_utc,
        trigger_utc=pair.trigger_utc,
        end_utc=pair.end_utc,
        situation=pair.situation,
        situation_ambiguous=pair.situation_ambiguous,
        situation_basis=pair.situation_basis,
        own_role_colregs=verdict.role_colregs[own_index],
        target_role_colregs=verdict.role_colregs[target_index],
        own_nav_status=own.nav_status,
        target_nav_status=target.nav_status,
        target_reports_restricted=nav_status_finding(
            target.nav_status, params.replay.restricted_nav_statuses
        )
        is Finding.TRUE,
        target_estimated_restricted=target.estimated_restricted,
        own_estimated_restricted=own.estimated_restricted,
        automaton_path=own_seat.path_text,
        target_seat_automaton_path=other_seat.path_text,
        rule9_applied=pair.rule9_applied,
        deciding_rule=pair.deciding_rule,
        both_restricted=pair.both_restricted,
        own_role_final=own_final,
        target_role_final=target_final,
        give_way_vessel=_give_way_side(own_final, target_final),
        give_way_vessels=pair.give_way_vessels,
        verdict_rests_on_defaults=pair.verdict_rests_on_defaults,
        range_m_at_trigger=pair.range_m_at_trigger,
        cpa_m=pair.cpa_m,
        tcpa_s=pair.tcpa_s,
        own_lat_deg_at_trigger=own.lat_deg,
        own_lon_deg_at_trigger=own.lon_deg,
        target_lat_deg_at_trigger=target.lat_deg,
        target_lon_deg_at_trigger=target.lon_deg,
        own_lat_deg_at_cpa=own.lat_deg_at_cpa,
        own_lon_deg_at_cpa=own.lon_deg_at_cpa,
        target_lat_deg_at_cpa=target.lat_deg_at_cpa,
        target_lon_deg_at_cpa=target.lon_deg_at_cpa,
        data_covers_cpa=pair.data_covers_cpa,
        actual_min_separation_m=pair.actual_min_separation_m,
        actual_min_separation_utc=pair.actual_min_separation_utc,
        give_way_vessel_acted=pair.give_way_vessel_acted,
        give_way_action=pair.give_way_action,
        action_before_cpa_s=pair.action_before_cpa_s,
        stand_on_vessel_kept_course=pair.stand_on_vessel_kept_course,
        own_course_deg_at_trigger=own.course_deg,
        own_speed_kn_at_trigger=own.speed_kn,
        target_course_deg_at_trigger=target.course_deg,
        target_speed_kn_at_trigger=target.speed_kn,
        own_length_m=own.dimensions.length_m,
        own_breadth_m=own.dimensions.breadth_m,
        own_draught_m=own.dimensions.draught_m,
        own_dimensions_defaulted=own.dimensions.defaulted_text,
        target_length_m=target.dimensions.length_m,
        target_breadth_m=target.dimensions.breadth_m,
        target_draught_m=target.dimensions.draught_m,
        target_dimensions_defaulted=target.dimensions.defaulted_text,
    )
    tcpa_s = pair.tcpa_s
    metre_columns = [f"{p}{c}" for p in ("own_", "target_") for c in ("north_m", "east_m")]
    in_run_frame = bool(np.isfinite(full[metre_columns].to_numpy(dtype=float)).all())
    # A pair beyond the run frame's reach is drawn and mapped in a frame of its own.
    frame = (
        run_frame
        if in_run_frame
        else LocalFrame(float(trigger["own_lat_deg"]), float(trigger["own_lon_deg"]))
    )

    def at_trigger(prefix: str) -> tuple[float, float]:
        if in_run_frame:
            return float(trigger[f"{prefix}north_m"]), float(trigger[f"{prefix}east_m"])
        north, east = frame.to_local(trigger[f"{prefix}lat_deg"], trigger[f"{prefix}lon_deg"])
        return float(north), float(east)

    def at_tcpa(vessel: VesselAtTrigger, prefix: str) -> tuple[float, float]:
        if in_run_frame:
            v_north, v_east = velocity_mps(
                trigger[f"{prefix}speed_mps"], trigger[f"{prefix}cog_grid_deg"]
            )
            return (
                float(trigger[f"{prefix}north_m"] + v_north * tcpa_s),
                float(trigger[f"{prefix}east_m"] + v_east * tcpa_s),
            )
        north, east = frame.to_local(vessel.lat_deg_at_cpa, vessel.lon_deg_at_cpa)
        return float(north), float(east)

    def track(prefix: str) -> pd.DataFrame:
        if in_run_frame:
            metres = full[[f"{prefix}north_m", f"{prefix}east_m"]]
            return metres.set_axis(["north_m", "east_m"], axis=1)
        north, east = frame.to_local(full[f"{prefix}lat_deg"], full[f"{prefix}lon_deg"])
        return pd.DataFrame({"north_m": north, "east_m": east}, index=full.index)

    return EncounterOutcome(
        summary=summary,
        series=_seat_series(steps, flip, params.replay.restricted_nav_statuses),
        own_track=track(own_prefix),
        target_track=track(target_prefix),
        own_at_trigger_m=at_trigger(own_prefix),
        target_at_trigger_m=at_trigger(target_prefix),
        own_at_tcpa_m=at_tcpa(own, own_prefix),
        target_at_tcpa_m=at_tcpa(target, target_prefix),
        assessment=steps.trigger_assessments[target_index],
        frame=frame,
        in_run_frame=in_run_frame,
    )


def _counts(segmentation: Segmentation, results: Sequence[SlabResult]) -> ReplayCounts:
    return ReplayCounts(
        vessels=len(segmentation.vessels),
        segments=segmentation.stats.segments,
        candidate_pair_steps=sum(r.candidate_pair_steps for r in results),
        candidate_pairs=len(frozenset().union(*(r.candidate_pairs for r in results))),
        encounters=sum(r.encounters for r in results),
        triggered=sum(r.triggered for r in results),
        triggered_pairs=sum(len(r.pairs) for r in results),
    )


def _no_overlap(chart_paths: Sequence[Path], positions: pd.DataFrame) -> ChartError:
    names = ", ".join(str(p) for p in chart_paths)
    return ChartError(
        f"{names}: the chart does not cover any of the AIS positions (lat "
        f"{positions['lat_deg'].min():.4f}–{positions['lat_deg'].max():.4f}, lon "
        f"{positions['lon_deg'].min():.4f}–{positions['lon_deg'].max():.4f}); give a chart "
        "of the area the AIS covers, or leave out --chart"
    )


def load_run_chart(
    source: ChartSource, chart_paths: Sequence[Path], frame: LocalFrame, positions: pd.DataFrame
) -> Chart:
    """The charts read (``chart.read_charts``) in the run's frame; a chart that covers none of
    the AIS is an error.

    The boxes are compared first, so that a chart far away is never projected into the frame.
    """
    lat_min, lat_max, lon_min, lon_max = source.bounds_wgs84()
    lat = positions["lat_deg"].to_numpy(dtype=float)
    lon = positions["lon_deg"].to_numpy(dtype=float)
    in_box = (lat >= lat_min) & (lat <= lat_max) & (lon >= lon_min) & (lon <= lon_max)
    if not in_box.any():
        raise _no_overlap(chart_paths, positions)
    chart = project_charts(source, frame)
    north_m, east_m = frame.to_local(lat[in_box], lon[in_box])
    if not chart.covers(north_m, east_m).any():
        raise _no_overlap(chart_paths, positions)
    return chart


def build_manifest(
    query: Query,
    inputs: Sequence[InputFile],
    ledger: RejectsLedger,
    chart: Chart | None,
    chart_paths: Sequence[Path],
    frame: LocalFrame,
    params: ReplayRunParams,
    track_stats: TrackStats,
    counts: ReplayCounts,
    pairs: tuple[PairOutcome, ...],
    accept_chart_gaps: bool = False,
) -> dict[str, Any]:
    """The content of run.json."""
    return {
        **run_header("replay"),
        "query": query_manifest(query),
        "frame": {"lat0_deg": frame.lat0_deg, "lon0_deg": frame.lon0_deg},
        "parameters": jsonable(params),
        "inputs": inputs_manifest(inputs),
        "charts": charts_manifest(chart_paths, chart.detail_order if chart is not None else ()),
        "accept_chart_gaps": accept_chart_gaps,
        "chart_cells": [jsonable(cell) for cell in (chart.cells if chart is not None else ())],
        "ledger": ledger.to_dict(),
        "ledger_balanced": ledger.balanced,
        "tracks": jsonable(track_stats),
        "counts": jsonable(counts),
        "verdicts": verdict_counts(pairs),
    }


def run_replay(
    ais_paths: Sequence[Path],
    chart_paths: Sequence[Path] = (),
    query_path: Path | None = None,
    own_mmsi: Sequence[int] = (),
    out_dir: Path | None = None,
    plots: bool = True,
    overrides: dict[str, dict[str, Any]] | None = None,
    fmt: str | None = None,
    quiet: bool = True,
    overwrite: bool = False,
    accept_chart_gaps: bool = False,
    write: bool = True,
    workers: int = 1,
    scheduler: str | None = None,
    scratch_dir: Path | None = None,
) -> ReplayResult:
    """Replay ``ais_paths`` and write the reports (see the module docstring); with
    ``write=False`` nothing is written (the result is in memory only).

    Errors: an own MMSI not in the data, fewer than two vessels (``NoDataError``, exit 3); a
    chart that covers none of the AIS (``ChartError``, exit 2); bad files or parameters. A run
    without triggered encounters is not an error: it writes a header-only encounters.csv.

    The run works through time in slabs (``slabs.py``, ``[replay] slab_s``), spilling the
    decided reports to a scratch directory in ``scratch_dir`` (default: the system's
    temporary directory). ``workers`` > 1 runs the slabs on a local Dask cluster of that many
    processes, ``scheduler`` on the Dask cluster at that address (``dask_run.py``).
    """
    if workers < 1:
        raise ParameterError(f"--workers {workers}: give 1 or more worker processes")
    if scratch_dir is not None and not Path(scratch_dir).is_dir():
        raise ParameterError(
            f"--scratch {scratch_dir}: not a directory; give an existing directory (on a "
            "multi-machine cluster, one that every worker mounts)"
        )
    with ExitStack() as stack:
        cluster = None
        if workers > 1 or scheduler is not None:
            # Before the work, so that an unreachable scheduler stops the run at once (a
            # local cluster starts beside the reading); only here, as importing Dask takes a
            # second.
            from .dask_run import dask_client_soon

            cluster = stack.enter_context(dask_client_soon(workers, scheduler))
        query = load_query(query_path) if query_path is not None else everything_query()
        params = run_params(query, own_mmsi, overrides)
        target = Path(out_dir) if out_dir is not None else default_out_dir(query.name)
        if write:
            given = [*ais_paths, *chart_paths, *([query_path] if query_path else [])]
            check_out_dir(target, overwrite, inputs=given)
        slab_s = params.replay.slab_s
        with _scratch_directory(scratch_dir) as scratch:
            spill_dir = Path(scratch) / "spill"
            spill_dir.mkdir()
            ais = open_replay_input(
                ais_paths, query, fmt, quiet, Path(scratch), slab_s, REPLAY_COLUMNS
            )
            # Stage 1 in parts of the vessels, one per worker on a cluster (the results do not
            # depend on their number); the bar counts the slabs of one part, else the parts.
            parts = ais.parts(1 if cluster is None else len(cluster().nthreads()))
            unit, units = ("slabs", len(ais.slabs)) if len(parts) == 1 else ("parts", len(parts))
            with progress_bar(f"Tracks ({unit})", units, progress_enabled(quiet)) as bar:
                if cluster is None or len(parts) == 1:
                    done = [segment_input_part(parts[0], 0, spill_dir, params.replay, bar)]
                else:
                    from .dask_run import dask_segments

                    tasks = [
                        functools.partial(segment_input_part, part, k, spill_dir, params.replay)
                        for k, part in enumerate(parts)
                    ]
                    done = dask_segments(cluster(), tasks, bar)
            segmentation = ais.merge(done)
            ais.check_positions()
            if len(ais.vessels) < 2:
                raise NoDataError(
                    f"{', '.join(str(p) for p in ais_paths)}: the AIS selected by query "
                    f"'{query.name}' holds {len(ais.vessels)} vessel(s); an encounter needs "
                    "two. Widen the query or give more AIS"
                )
            source = read_charts(chart_paths, accept_chart_gaps) if chart_paths else None
            if source is not None:
                points = segmentation.points
                near = source.near(points["lat_deg"], points["lon_deg"], CHART_MARGIN_DEG)
                source = near if near.paths else source  # none near: load_run_chart says so
            _check_own(params.own_mmsi, segmentation.vessels)
            frame = run_frame(query, segmentation.extent, source)
            chart: Chart | None = None
            if source is not None:
                chart = load_run_chart(source, chart_paths, frame, segmentation.points)
            context = slab_context(segmentation, frame, params)
            slabs = slab_range(segmentation, params.replay)
            evaluate = functools.partial(_evaluate, params=params)
            with progress_bar(
                "Pairs and verdicts (slabs)", len(slabs), progress_enabled(quiet)
            ) as bar:
                if cluster is None:
                    results = run_slabs(slabs, context, evaluate, chart, bar)
                else:
                    from .dask_run import dask_slabs

                    results, on_cluster = dask_slabs(
                        cluster(), slabs, context, evaluate, chart, bar
                    )
        outcomes = [pair for result in results for pair in result.pairs]
        ledger = _ledger_with_tracks(ais.ledger, segmentation.stats)
        track_stats = dataclasses.replace(
            segmentation.stats, samples=sum(r.samples for r in results)
        )
        counts = _counts(segmentation, results)
        manifest = build_manifest(
            query,
            ais.inputs,
            ledger,
            chart,
            chart_paths,
            frame,
            params,
            track_stats,
            counts,
            tuple(outcomes),
            accept_chart_gaps,
        )
        manifest["slabs"] = {
            "slab_s": slab_s,
            "slabs": len(slabs),
            "workers": "scheduler " + scheduler if scheduler is not None else workers,
            "pairs_followed_past_their_slab": sum(r.followed for r in results),
        }
        result = ReplayResult(
            query_name=query.name,
            out_dir=target,
            frame=frame,
            params=params,
            pairs=tuple(outcomes),
            counts=counts,
            manifest=manifest,
            files=(),
        )
        files: tuple[Path, ...] = ()
        if write:
            with progress_bar("Reports", len(result.encounters), progress_enabled(quiet)) as bar:
                if cluster is None:
                    files = write_replay_reports(result, chart, plots, bar)
                else:
                    from .dask_run import dask_drawer

                    drawer = dask_drawer(cluster())
                    files = write_replay_reports(result, chart, plots, bar, drawer, on_cluster)
        return dataclasses.replace(result, files=files, text=format_summary(result))


@contextmanager
def _scratch_directory(parent: Path | None) -> Iterator[str]:
    """A temporary directory for the spilled reports, in ``parent`` (default: the system's)."""
    try:
        scratch = tempfile.TemporaryDirectory(prefix="colregs9-slabs-", dir=parent)
    except OSError as exc:
        where = f"--scratch {parent}" if parent is not None else "the temporary directory"
        raise ParameterError(
            f"{where}: cannot make a scratch directory there ({exc.strerror}); give a "
            "writable directory with --scratch"
        ) from None
    with scratch as path:
        yield path


def _evaluate(
    tracks: Tracks,
    encounter: Encounter,
    seats: tuple[int, ...],
    chart: Chart | None,
    params: ReplayRunParams,
) -> PairOutcome:
    return evaluate_pair(tracks, encounter, seats, chart, params)


def _check_own(own_mmsi: Sequence[int], vessels: np.ndarray) -> None:
    absent = sorted(set(own_mmsi) - set(vessels.tolist()))
    if absent:
        raise NoDataError(
            f"own MMSI {absent[0]} is not in the AIS data after cleaning; check --own-mmsi "
            "against the vessels in the input and the query's region and time window"
        )


def slab_range(segmentation: Segmentation, params: ReplayParams) -> list[int]:
    """The slabs whose core the decided reports reach, with the context resampling needs
    around them (``tracks.context_s``): a slab far from any report can start no encounter,
    so a gap of months in the data costs nothing."""
    slab_s = params.slab_s
    margin_s = context_s(params)
    first = math.floor(segmentation.first_s / slab_s) if segmentation.spill.files else 0
    last = math.floor(segmentation.last_s / slab_s) if segmentation.spill.files else -1
    slabs: set[int] = set()
    for spilled in segmentation.spill.files:
        low = max(first, math.floor((spilled.t_min_s - margin_s) / slab_s))
        high = min(last, math.floor((spilled.t_max_s + margin_s) / slab_s))
        slabs.update(range(low, high + 1))
    return sorted(slabs)


def slab_context(
    segmentation: Segmentation, frame: LocalFrame, params: ReplayRunParams
) -> SlabContext:
    return SlabContext(
        spill=segmentation.spill,
        statics=segmentation.statics,
        frame=frame,
        params=params.replay,
        course_source=params.colregs.course_source,
        own_mmsi=params.own_mmsi,
        data_end_s=segmentation.last_s,
    )


def verdict_counts(pairs: Sequence[PairOutcome]) -> dict[str, Any]:
    """The pairs' verdicts counted for run.json: by situation, deciding rule and audit fact."""

    def count(values: Sequence[Any]) -> dict[str, int]:
        texts = ["" if v is None else str(getattr(v, "value", v)).lower() for v in values]
        return {key: texts.count(key) for key in sorted(set(texts))}

    summaries = [p.summary for p in pairs]
    return {
        "pairs": len(summaries),
        "situation": count([s.situation for s in summaries]),
        "situation_ambiguous": sum(s.situation_ambiguous for s in summaries),
        "deciding_rule": count([s.deciding_rule for s in summaries]),
        "rule9_applied": sum(s.rule9_applied for s in summaries),
        "both_restricted": sum(s.both_restricted for s in summaries),
        "verdict_rests_on_defaults": sum(s.verdict_rests_on_defaults for s in summaries),
        "data_covers_cpa": sum(s.data_covers_cpa for s in summaries),
        "give_way_vessel_acted": count([s.give_way_vessel_acted for s in summaries]),
        "estimated_restricted": count(
            [e for s in summaries for e in (s.estimated_restricted_a, s.estimated_restricted_b)]
        ),
    }
