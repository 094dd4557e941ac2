"""One triggered pair, evaluated once (docs/design.md §5, Replay).

A pair is evaluated in vessel order (a, b), a with the lower MMSI, whichever seat's run the
pair search found: ``evaluate_pair`` gives a ``PairEvaluation`` (``pair_model.py``, which also
gives the ``Seat`` of either vessel); ``PairParams`` is everything it reads.

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
- **The passing** (``passing.py``): from the trigger until the range has opened clearly past
  its least value, following both tracks past the end of the candidate run for at most TCPA
  + ``passing_follow_s``, and stopping at the first step where either track stops. G_a and
  G_d run to its end; the audit facts (``audit.py``) are judged up to its closest approach.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from ..charts.channel_facts import ChannelRelation
from ..charts.channels import Channels
from ..charts.water import Chart
from ..geo import sail
from .ais_claims import NavStatus, NavStatusBelief, NavStatusParams, nav_status_belief
from .audit import ConductParams, Fact, course_drawn_through_a_turn
from .channel_audit import (
    ChannelAuditParams,
    VesselInChannel,
    meeting_along_a_channel,
    vessel_in_channel,
)
from .colregs import (
    ColregsEvaluation,
    ColregsParams,
    Kinematics,
    Role,
    Situation,
    SituationBasis,
    evaluate_colregs,
)
from .confinement import DraughtOnChart
from .encounters import Encounter, encounter_series, series_fires
from .interactions import (
    Interaction,
    InteractionKind,
    InteractionParams,
    VesselFacts,
    approach_steps,
    classify_interaction,
    under_way_from,
    window_steps,
)
from .manoeuvrability import (
    ManoeuvrabilityAssessment,
    ManoeuvrabilityParams,
    Restriction,
    VesselState,
    assess_manoeuvrability,
    unplaced_assessment,
)
from .pair_audit import PREFIXES, PairAudit, audit_pair, hull_offsets, over_land
from .pair_model import PairEvaluation, PairSteps, VesselAtTrigger, nav_status
from .pair_search import EncounterParams
from .passing import PassingParams, horizon_steps, passing
from .rule9 import (
    RULE_9B_LENGTH_M,
    ChannelStanding,
    Finding,
    PairVerdict,
    Rule9Params,
    decide_pair,
)
from .rule9 import nav_status_finding as _finding
from .tracks import Tracks
from .vessel_defaults import DimensionDefaults, VesselDimensions, vessel_dimensions


@dataclass(frozen=True)
class PairParams:
    """Every parameter the evaluation of one pair reads, each stage's own."""

    colregs: ColregsParams
    manoeuvrability: ManoeuvrabilityParams
    encounters: EncounterParams
    conduct: ConductParams
    rule9: Rule9Params
    dimensions: DimensionDefaults
    passing: PassingParams
    interactions: InteractionParams
    claims: NavStatusParams
    channels: ChannelAuditParams


@dataclass(frozen=True)
class _Claims:
    """Judges a vessel's navigational status claims against what else AIS says of her."""

    ship_type: str | None
    length_m: float | None
    draught_m: float | None
    params: NavStatusParams

    @classmethod
    def of(
        cls, static: dict[str, Any], dimensions: VesselDimensions, params: NavStatusParams
    ) -> _Claims:
        """From her static AIS; a dimension the table defaulted is unknown here."""

        def reported(name: str) -> float | None:
            return None if name in dimensions.defaulted else getattr(dimensions, name)

        ship_type = static.get("ship_type")
        return cls(
            None if ship_type is None else str(ship_type),
            reported("length_m"),
            reported("draught_m"),
            params,
        )

    def belief(self, status: int | None) -> NavStatusBelief:
        return nav_status_belief(status, self.ship_type, self.length_m, self.draught_m, self.params)

    def used(self, status: int | None) -> int | None:
        """``status`` where believed, else None: an implausible claim decides nothing."""
        return status if self.belief(status).believed else None


def _used_statuses(judge: _Claims, column: pd.Series) -> list[int | None]:
    """A series' statuses as rules 9 and 18 use them, each distinct claim judged once (a
    vessel reports the same status for hours)."""
    reported = [nav_status(v) for v in column.tolist()]
    used = {status: judge.used(status) for status in set(reported)}
    return [used[status] for status in reported]


def text_or_none(value: Any) -> str | None:
    return None if value is None or (isinstance(value, float) and math.isnan(value)) else str(value)


def _static(vessels: pd.DataFrame, mmsi: int) -> dict[str, Any]:
    """A vessel's static AIS fields (empty when she sent none)."""
    if mmsi not in vessels.index:
        return {}
    return {name: value for name, value in vessels.loc[mmsi].items() if not _missing(value)}


def _missing(value: Any) -> bool:
    return value is None or (not isinstance(value, str) and bool(pd.isna(value)))


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
            placed = all(math.isfinite(state[name][row]) for name in ("north_m", "east_m"))
            if placed and math.isfinite(state["course_deg"][row]):
                vessel = VesselState(
                    north_m=float(state["north_m"][row]),
                    east_m=float(state["east_m"][row]),
                    course_deg=float(state["course_deg"][row]),
                    speed_mps=float(state["speed_mps"][row]),
                )
                self.assessment = assess_manoeuvrability(
                    self.chart, vessel, self.dimensions, self.params
                )
            else:
                self.assessment = unplaced_assessment(self.dimensions, self.params)
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


def _situation_row(
    g_a: ColregsEvaluation, drawn: np.ndarray, at_risk: np.ndarray, last_row: int
) -> int:
    """The step the situation is read at: the trigger (row 0), unless a vessel's course
    there is drawn through a turn between two of her reports (``_course_drawn_across_a_turn``);
    then the first step, no later than ``last_row`` (the closest approach the trigger
    predicts), at which neither course is and the trigger's conditions still hold
    (``at_risk``: ``encounters.series_fires``; San Diego:
    SHELTER ISLAND reported 087° and, three minutes later, 126°; at the later report she and
    WHITE NIGHTS met end on, where the 113° drawn between read a crossing). Row 0 when there
    is none: the situation stays the trigger's, flagged ambiguous."""
    if not drawn[0]:
        return 0
    readable = ~drawn & at_risk & (g_a.situation != Situation.NONE)
    seen = np.flatnonzero(readable[: last_row + 1])
    return int(seen[0]) if len(seen) else 0


def _held(
    g_a: ColregsEvaluation, meeting_in_channel: bool = False, row: int = 0
) -> ColregsEvaluation:
    """The situation and roles read at step ``row`` (``_situation_row``) held at every step
    (rule 13(d)); the bearings and closing flags stay those of each step. Two vessels
    meeting along a charted channel (``channel_audit.meeting_along_a_channel``) that G_a
    reads as crossing, as a bend makes their courses cross, are head-on."""
    rows = len(g_a.situation)
    read = slice(row, row + 1)
    held = ColregsEvaluation(
        **{
            name: np.repeat(getattr(g_a, name)[read], rows)
            for name in ("situation", "own_role", "target_role", "own_overtaking", "ambiguous")
        },
        basis=np.repeat(g_a.basis[read], rows),
        beta_deg=g_a.beta_deg,
        beta_prime_deg=g_a.beta_prime_deg,
        closing=g_a.closing,
    )
    if not (meeting_in_channel and g_a.situation[row] is Situation.CROSSING):
        return held
    return dataclasses.replace(
        held,
        situation=np.repeat(np.array([Situation.HEAD_ON], dtype=object), rows),
        own_role=np.repeat(np.array([Role.GIVE_WAY], dtype=object), rows),
        target_role=np.repeat(np.array([Role.GIVE_WAY], dtype=object), rows),
        ambiguous=np.zeros(rows, dtype=bool),
        basis=np.repeat(np.array([SituationBasis.CHANNEL], dtype=object), rows),
    )


def _course_drawn_across_a_turn(series: pd.DataFrame, conduct: ConductParams) -> np.ndarray:
    """Steps where either vessel's course is drawn through a turn
    (``audit.course_drawn_through_a_turn``)."""
    return np.logical_or.reduce(
        [
            course_drawn_through_a_turn(
                series[f"{prefix}report_gap_s"], series[f"{prefix}gap_turn_deg"], conduct
            )
            for prefix in PREFIXES
        ]
    )


def _pair_steps(
    series: pd.DataFrame,
    dimensions: tuple[VesselDimensions, VesselDimensions],
    claims: tuple[_Claims, _Claims],
    chart: Chart | None,
    params: PairParams,
    step_s: float,
    meeting_in_channel: bool = False,
    standings: tuple[ChannelStanding, ChannelStanding] | None = None,
) -> PairSteps:
    """G_a, the estimates and G_d of both seats at every step of ``series`` (a = own_)."""
    g_a = evaluate_colregs(
        *Kinematics.pair_from_series(series),
        params.colregs,
        course_judged_above_kn=params.conduct.course_judged_above_kn,
    )
    drawn = _course_drawn_across_a_turn(series, params.conduct)
    g_a = dataclasses.replace(
        g_a, ambiguous=g_a.ambiguous | (drawn & (g_a.situation != Situation.NONE))
    )
    predicted_cpa_row = math.ceil(max(float(series["tcpa_s"].iloc[0]), 0.0) / step_s)
    at_risk = series_fires(series, params.encounters)
    situation_row = _situation_row(g_a, drawn, at_risk, predicted_cpa_row)
    held = _held(g_a, meeting_in_channel, situation_row)
    situation = held.situation[0]
    roles = (held.own_role[0], held.target_role[0])
    statuses = params.rule9.restricted_nav_statuses
    reassess = max(1, round(params.rule9.reassess_every_s / step_s))
    estimators = tuple(
        _Estimator(chart, params.manoeuvrability, dims, reassess) for dims in dimensions
    )
    states = tuple(_state(series, prefix) for prefix in PREFIXES)
    nav = tuple(
        _used_statuses(judge, series[f"{p}nav_status"])
        for judge, p in zip(claims, PREFIXES, strict=True)
    )
    estimates: tuple[list[Restriction], list[Restriction]] = ([], [])
    assessed_row: tuple[list[int], list[int]] = ([], [])
    verdicts: list[PairVerdict] = []
    cache: dict[tuple[Any, ...], PairVerdict] = {}
    trigger: list[ManoeuvrabilityAssessment] = []
    for row in range(len(series)):
        for vessel in (0, 1):
            # Every vessel's estimate counts (decide_pair): the give-way vessel's for G_d,
            # the stand-on vessel's for "both restricted". A reported status makes it moot.
            needed = _finding(nav[vessel][row], statuses) is not Finding.TRUE
            assessment = estimators[vessel].at(states[vessel], row, needed=needed)
            if row == 0:
                trigger.append(assessment)
            estimates[vessel].append(assessment.restriction)
            assessed_row[vessel].append(estimators[vessel].assessed_row)
        key = (nav[0][row], nav[1][row], estimates[0][row], estimates[1][row])
        if key not in cache:
            cache[key] = decide_pair(
                situation, roles, (key[0], key[1]), (key[2], key[3]), statuses, standings
            )
        verdicts.append(cache[key])
    return PairSteps(
        series=series,
        g_a=g_a,
        held=held,
        situation_row=situation_row,
        course_drawn=drawn,
        verdicts=verdicts,
        estimates=estimates,
        assessed_row=assessed_row,
        trigger_assessments=(trigger[0], trigger[1]),
    )


def evaluate_pair(
    tracks: Tracks,
    encounter: Encounter,
    chart: Chart | None,
    params: PairParams,
    channels: Channels | None = None,
) -> PairEvaluation:
    """One triggered pair, evaluated once (see the module docstring). ``encounter`` may be
    either seat's; ``chart`` and its ``channels`` are in ``tracks.frame``."""
    if encounter.trigger_step is None or encounter.tcpa_s_at_trigger is None:
        raise ValueError(f"encounter {encounter.encounter_id} never triggered")
    a, b = sorted((encounter.own_mmsi, encounter.target_mmsi))
    oriented = dataclasses.replace(encounter, own_mmsi=a, target_mmsi=b)
    step_s = tracks.step_s
    horizon = horizon_steps(encounter.tcpa_s_at_trigger, params.passing, step_s)
    full = encounter_series(
        pair_tracks(tracks, (a, b)),
        oriented,
        to_step=max(encounter.end_step, encounter.trigger_step + horizon),
    )
    full = full.iloc[: _contiguous_rows(full["step"].to_numpy())].reset_index(drop=True)
    trigger_step, interaction = _judged_trigger(tracks, oriented, full, params)
    window = full[full["step"] >= trigger_step].reset_index(drop=True)
    seen = passing(window["range_m"].to_numpy(), params.passing)
    # G_a and G_d run until the pair is past: until the range has opened clearly past its
    # least value (core/passing.py), or the data ends.
    series = window.iloc[: seen.end_row + 1]
    statics = (_static(tracks.vessels, a), _static(tracks.vessels, b))
    dimensions = (
        vessel_dimensions(statics[0], params.dimensions),
        vessel_dimensions(statics[1], params.dimensions),
    )
    claims = (
        _Claims.of(statics[0], dimensions[0], params.claims),
        _Claims.of(statics[1], dimensions[1], params.claims),
    )
    hulls = (hull_offsets(dimensions[0], statics[0]), hull_offsets(dimensions[1], statics[1]))
    lengths_m = (dimensions[0].length_m, dimensions[1].length_m)
    in_channel = tuple(
        vessel_in_channel(
            window.iloc[: seen.end_row + 1],
            prefix,
            channels,
            seen.cpa_row,
            seen.covers_cpa,
            step_s,
            params.channels,
            DraughtOnChart(chart, dimensions[i], params.manoeuvrability.ukc_m),
        )
        for i, prefix in enumerate(PREFIXES)
    )
    bends = (in_channel[0].bend_deg, in_channel[1].bend_deg)
    audit = dataclasses.replace(
        audit_pair(window, seen, hulls, lengths_m, params.conduct, step_s, bends),
        min_separation_over_land=over_land(
            None if chart is None else chart.land, window, seen.cpa_row
        ),
    )
    meeting = meeting_along_a_channel(
        (in_channel[0], in_channel[1]),
        (float(series["own_cog_deg"].iloc[0]), float(series["target_cog_deg"].iloc[0])),
    )
    at_trigger = [nav_status(series[f"{prefix}nav_status"].iloc[0]) for prefix in PREFIXES]
    standings = (
        None
        if channels is None or not any(c.is_area for c in channels)
        else (
            channel_standing(in_channel[0], dimensions[0], statics[0], claims[0], at_trigger[0]),
            channel_standing(in_channel[1], dimensions[1], statics[1], claims[1], at_trigger[1]),
        )
    )
    steps = _pair_steps(
        series,
        dimensions,
        claims,
        chart,
        params,
        step_s,
        meeting,
        standings,
    )
    trigger = series.iloc[0]
    vessels = tuple(
        _vessel_at_trigger(tracks, mmsi, prefix, trigger, dimensions[i], claims[i], steps, audit, i)
        for i, (mmsi, prefix) in enumerate(zip((a, b), PREFIXES, strict=True))
    )
    return PairEvaluation(
        encounter=encounter,
        vessels=(vessels[0], vessels[1]),
        steps=steps,
        audit=audit,
        full=full,
        restricted_nav_statuses=params.rule9.restricted_nav_statuses,
        interaction=interaction,
        swing_model=params.manoeuvrability.swing_model,
        conduct_params=params.conduct,
        in_channel=(in_channel[0], in_channel[1]),
        standings=standings,
    )


def _judged_trigger(
    tracks: Tracks, pair: Encounter, full: pd.DataFrame, params: PairParams
) -> tuple[int, Interaction]:
    """The step the pair is judged at, and its interaction there: the search's trigger,
    unless a vessel was not making way there and, later in the same passing, both are under
    way (``interactions.under_way_from``) at a step where the trigger's conditions hold
    (0 <= TCPA <= ``tcpa_act_s``, CPA < ``cpa_req_m``) and the pair, judged from when both
    made way, is no longer not making way: then that step, where the rules first bind. A
    ferry leaving her berth is judged on her meeting under way, not on her berth. ``full``
    is the pair's series up to the last step the evaluation reads, so that the step found
    is the same whatever slab or worker evaluates the pair."""
    assert pair.trigger_step is not None
    interaction = _interaction(tracks, pair, pair.trigger_step, params.interactions)
    if interaction.kind is not InteractionKind.NOT_MAKING_WAY:
        return pair.trigger_step, interaction
    window = full[full["step"] >= pair.trigger_step].reset_index(drop=True)
    facts = _facts(tracks, pair)
    under_way = under_way_from(window, facts, params.interactions, tracks.step_s)
    if under_way is None:
        return pair.trigger_step, interaction
    first, held = under_way
    seen = passing(window["range_m"].to_numpy(), params.passing)
    rows = np.arange(len(window))
    fires = (rows >= held) & (rows <= seen.end_row) & series_fires(window, params.encounters)
    if not fires.any():
        return pair.trigger_step, interaction
    row = int(np.flatnonzero(fires)[0])
    later = classify_interaction(
        window.iloc[first:].reset_index(drop=True),
        row - first,
        facts,
        params.interactions,
        tracks.step_s,
        float(window["tcpa_s"].iloc[row]),
    )
    if later.kind is InteractionKind.NOT_MAKING_WAY:
        return pair.trigger_step, interaction
    basis = (
        f"judged from {window['timestamp'].iloc[row]:%H:%M:%S}, both under way "
        f"(at {window['timestamp'].iloc[0]:%H:%M:%S} {interaction.basis}): {later.basis}"
    )
    return int(window["step"].iloc[row]), dataclasses.replace(later, basis=basis)


def _facts(tracks: Tracks, pair: Encounter) -> tuple[VesselFacts, VesselFacts]:
    a, b = (
        VesselFacts.from_static(mmsi, _static(tracks.vessels, mmsi))
        for mmsi in (pair.own_mmsi, pair.target_mmsi)
    )
    return a, b


def _interaction(
    tracks: Tracks, pair: Encounter, trigger_step: int, params: InteractionParams
) -> Interaction:
    """What the two vessels were doing around the trigger (``interactions.py``), judged on a
    window from before the candidate run: a ferry leaving her berth is slow until then."""
    lead = window_steps(params, tracks.step_s)
    approach_s = pair.tcpa_s_at_trigger or 0.0
    around = encounter_series(
        pair_tracks(tracks, (pair.own_mmsi, pair.target_mmsi)),
        pair,
        from_step=trigger_step - lead,
        to_step=trigger_step + lead + approach_steps(approach_s, tracks.step_s),
    ).reset_index(drop=True)
    trigger_row = int(np.searchsorted(around["step"].to_numpy(), trigger_step))
    return classify_interaction(
        around, trigger_row, _facts(tracks, pair), params, tracks.step_s, approach_s
    )


def channel_standing(
    place: VesselInChannel,
    dimensions: VesselDimensions,
    static: dict[str, Any],
    claims: _Claims,
    status: int | None,
) -> ChannelStanding:
    """What rule 9's clauses read of a vessel: along or crossing a charted channel (at the
    trigger, or crossing at the least separation), under 20 m (a reported length) or
    sailing, fishing (her AIS type, or her navigational status at the trigger where it is
    believed), confined by her draught to the narrow channel she proceeds along at the
    trigger (``confinement.py``)."""
    ship_type = text_or_none(static.get("ship_type"))
    belief = claims.belief(status)
    used = status if belief.believed else None
    length_known = "length_m" not in dimensions.defaulted
    relations = (place.at_trigger.relation, place.at_least_separation.relation)
    return ChannelStanding(
        along_channel=place.at_trigger.relation is ChannelRelation.ALONG,
        crossing_channel=ChannelRelation.CROSSING in relations,
        small_or_sailing=(length_known and dimensions.length_m < RULE_9B_LENGTH_M)
        or ship_type == "Sailing"
        or used == NavStatus.UNDER_WAY_SAILING,
        fishing=ship_type == "Fishing" or used == NavStatus.ENGAGED_IN_FISHING,
        confined_to_channel=place.confined.fact is Fact.TRUE,
    )


def _vessel_at_trigger(
    tracks: Tracks,
    mmsi: int,
    prefix: str,
    trigger: pd.Series,
    dimensions: VesselDimensions,
    claims: _Claims,
    steps: PairSteps,
    audit: PairAudit,
    index: int,
) -> VesselAtTrigger:
    name = (
        text_or_none(tracks.vessels["name"].get(mmsi)) if "name" in tracks.vessels.columns else None
    )
    at_cpa = sail(
        trigger[f"{prefix}lat_deg"],
        trigger[f"{prefix}lon_deg"],
        trigger[f"{prefix}cog_deg"],
        trigger[f"{prefix}speed_mps"] * trigger["tcpa_s"],
    )
    return VesselAtTrigger(
        mmsi=mmsi,
        name=name,
        dimensions=dimensions,
        nav_status=nav_status(trigger[f"{prefix}nav_status"]),
        nav_status_belief=claims.belief(nav_status(trigger[f"{prefix}nav_status"])),
        course_deg=float(trigger[f"{prefix}course_deg"]),
        speed_kn=float(trigger[f"{prefix}sog_kn"]),
        lat_deg=float(trigger[f"{prefix}lat_deg"]),
        lon_deg=float(trigger[f"{prefix}lon_deg"]),
        lat_deg_at_cpa=float(at_cpa[0]),
        lon_deg_at_cpa=float(at_cpa[1]),
        estimated_restricted=steps.estimates[index][0],
        conduct=audit.conducts[index],
        action_before_cpa_s=audit.before_cpa_s[index],
    )
