"""The pair model: what ``pair.evaluate_pair`` makes of one triggered pair, and either seat of
it (docs/design.md §5, Replay).

``PairEvaluation`` holds the pair in vessel order (a, b), a with the lower MMSI: each vessel
at the trigger (``VesselAtTrigger``), G_a, the estimates and G_d at every step
(``PairSteps``), the audit, the interaction and the charted channels, and what follows from
its verdict (whether it rests on defaulted dimensions, ``rests_on_defaults``; the give-way
and stand-on actions judged against the rules). ``PairEvaluation.seen_from`` gives a
``Seat``: the same evaluation with one vessel as own ship and the other as target, and
``Seat.mine`` is the one place where a pair of values (a, b) becomes (own, target).
``nav_status`` and ``reports_restricted`` read the status cells of its series. The rows of the
outputs (``rows.py``, ``replay_results.py``) are projections of this model.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, TypeVar

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from .ais_claims import NavStatusBelief
from .audit import (
    Conduct,
    ConductParams,
    Fact,
    action_as_rule_asks,
    all_of,
    passed_port_to_port,
    stand_on_turned_to_port_for_vessel_on_port,
)
from .channel_audit import NOT_CHARTED, VesselInChannel
from .colregs import ColregsEvaluation, Role, Situation
from .encounters import Encounter
from .interactions import Interaction, InteractionKind
from .manoeuvrability import ManoeuvrabilityAssessment, Restriction, SwingModel
from .pair_audit import PREFIXES, PairAudit
from .rule9 import (
    ChannelStanding,
    Finding,
    PairVerdict,
    Rule9Assessment,
    Rule9Clause,
    decide_pair,
)
from .rule9 import nav_status_finding as _finding
from .vessel_defaults import VesselDimensions

T = TypeVar("T")


@dataclass(frozen=True)
class VesselAtTrigger:
    """One vessel of a pair: who she is, her state at the trigger and her conduct after it."""

    mmsi: int
    name: str | None
    dimensions: VesselDimensions
    nav_status: int | None
    nav_status_belief: NavStatusBelief
    course_deg: float
    speed_kn: float
    lat_deg: float
    lon_deg: float
    lat_deg_at_cpa: float  # predicted at constant velocity from the trigger to TCPA
    lon_deg_at_cpa: float
    estimated_restricted: Restriction
    conduct: Conduct
    action_before_cpa_s: float | None

    @property
    def nav_status_used(self) -> int | None:
        """Her status at the trigger as rules 9 and 18 use it: None when not believed."""
        return self.nav_status if self.nav_status_belief.believed else None


@dataclass(frozen=True)
class PairSteps:
    """Per-step results of one pair in vessel order (a, b): the evaluation behind its rows."""

    series: pd.DataFrame  # from the trigger to the pass, columns own_* = a, target_* = b
    g_a: ColregsEvaluation
    held: ColregsEvaluation  # the situation read at ``situation_row``, repeated
    situation_row: int  # the trigger (0), or the first step with both courses reported
    course_drawn: NDArray[np.bool_]  # either course drawn through a turn (pair.py), per step
    verdicts: list[PairVerdict]
    estimates: tuple[list[Restriction], list[Restriction]]
    assessed_row: tuple[list[int], list[int]]
    trigger_assessments: tuple[ManoeuvrabilityAssessment, ManoeuvrabilityAssessment]


@dataclass(frozen=True)
class PairEvaluation:
    """One triggered pair, evaluated once, in vessel order (a, b) with a the lower MMSI.

    ``encounter`` is the candidate run the pair search found (either seat's); ``full`` holds
    both tracks (``own_*`` = a, ``target_*`` = b) from the run's start to the end of the
    audit window, ``steps`` the evaluation from the trigger to the pass.
    """

    encounter: Encounter
    vessels: tuple[VesselAtTrigger, VesselAtTrigger]
    steps: PairSteps
    audit: PairAudit
    full: pd.DataFrame
    restricted_nav_statuses: frozenset[int]
    interaction: Interaction
    swing_model: SwingModel
    conduct_params: ConductParams  # what a course observed means (``audit.py``)
    # Each vessel and the charted channels (channel_audit.py), vessel order, and what rule 9's
    # clauses read of them (None: the chart charts no channel).
    in_channel: tuple[VesselInChannel, VesselInChannel] = (NOT_CHARTED, NOT_CHARTED)
    standings: tuple[ChannelStanding, ChannelStanding] | None = None

    @property
    def rule9_clause(self) -> Rule9Clause | None:
        """Where d3 found the vessel that rule 9 would make stand on restricted:
        the clause that binds the other (``rule9.decide_pair``); None where it did not."""
        return self.verdict.rule9_clause

    @property
    def is_encounter(self) -> bool:
        """Only an encounter gets a situation, roles, rules 9 and 18 and the audit facts
        (``interactions.py``); the others keep their geometry."""
        return self.interaction.kind is InteractionKind.ENCOUNTER

    @property
    def verdict(self) -> PairVerdict:
        """The pair's verdict at the trigger."""
        return self.steps.verdicts[0]

    @property
    def trigger(self) -> pd.Series:
        return self.steps.series.iloc[0]

    @property
    def pair_id(self) -> str:
        a, b = self.vessels
        return f"{self.encounter.start:%Y%m%dT%H%M%S}-{a.mmsi}+{b.mmsi}"

    @property
    def verdict_rests_on_defaults(self) -> bool:
        a, b = self.vessels
        return rests_on_defaults(
            self.verdict,
            (a.dimensions, b.dimensions),
            (a.estimated_restricted, b.estimated_restricted),
            (a.nav_status_used, b.nav_status_used),
            self.restricted_nav_statuses,
            self.standings,
        )

    @property
    def give_way_action_as_rule_asks(self) -> Fact | None:
        """Whether every give-way vessel's action is of the kind the deciding rule asks for
        (``audit.action_as_rule_asks``); None without a give-way vessel."""
        verdict = self.verdict
        cpa_m = self.steps.series["cpa_m"].to_numpy(dtype=float)
        facts = [
            action_as_rule_asks(
                verdict.situation,
                verdict.deciding_rule,
                role,
                vessel.conduct.action,
                closed_cpa=vessel.conduct.action_row is not None
                and bool(cpa_m[vessel.conduct.action_row] < cpa_m[0]),
            )
            for vessel, role in zip(self.vessels, verdict.role_final, strict=True)
        ]
        judged = [fact for fact in facts if fact is not None]
        return all_of(judged) if judged else None

    @property
    def stand_on_turned_to_port(self) -> Fact | None:
        """Rule 17(c): the stand-on vessel of a crossing turned to port for a vessel on her own
        port side (``audit.stand_on_turned_to_port_for_vessel_on_port``); None where it does
        not apply. The other vessel's bearing is the one where the situation was read, from
        her course."""
        verdict = self.verdict
        row = self.steps.situation_row
        bearings = (self.steps.g_a.beta_deg[row], self.steps.g_a.beta_prime_deg[row])
        facts = [
            stand_on_turned_to_port_for_vessel_on_port(
                verdict.situation,
                verdict.deciding_rule,
                role,
                vessel.conduct.action,
                float(bearing),
            )
            for vessel, role, bearing in zip(
                self.vessels, verdict.role_final, bearings, strict=True
            )
        ]
        judged = [fact for fact in facts if fact is not None]
        return all_of(judged) if judged else None

    @property
    def situation_utc(self) -> pd.Timestamp:
        """When the situation was read: the trigger, or the first step after it with both
        courses reported (``pair._situation_row``)."""
        return pd.Timestamp(self.steps.series["timestamp"].iloc[self.steps.situation_row])

    @property
    def passed_port_to_port(self) -> Fact | None:
        """Rule 14(a) at the least separation (``audit.passed_port_to_port``); None unless
        head-on, ``insufficient-data`` where the data stop before the closest approach."""
        situation = self.verdict.situation
        if situation is not Situation.HEAD_ON:
            return None
        times = self.steps.series["timestamp"]
        if not self.audit.covers_cpa or self.audit.cpa_utc is None:
            return Fact.INSUFFICIENT
        row = int(np.flatnonzero((times == self.audit.cpa_utc).to_numpy())[0])
        speeds_kn = self.steps.series[[f"{p}sog_kn" for p in PREFIXES]].iloc[row]
        judged = not self.steps.course_drawn[row] and bool(
            (speeds_kn >= self.conduct_params.course_judged_above_kn).all()
        )
        return passed_port_to_port(
            situation,
            (float(self.steps.g_a.beta_deg[row]), float(self.steps.g_a.beta_prime_deg[row])),
            judged,
        )

    @property
    def turn_radius_m(self) -> tuple[float | None, float | None]:
        """The radius of each vessel's projected arcs at the trigger; None where none were
        projected (no place in the run's frame)."""
        radii = tuple(
            assessment.turn_radius_m if len(assessment.north_m) else None
            for assessment in self.steps.trigger_assessments
        )
        return radii[0], radii[1]

    def with_role(self, role: Role) -> list[VesselAtTrigger]:
        """The vessels whose final role is ``role``, in vessel order."""
        finals = self.verdict.role_final
        return [v for v, final in zip(self.vessels, finals, strict=True) if final is role]

    def seen_from(self, mmsi: int) -> Seat:
        """The pair from the seat of vessel ``mmsi`` (own ship), the other as target."""
        mmsis = [v.mmsi for v in self.vessels]
        if mmsi not in mmsis:
            raise ValueError(f"MMSI {mmsi} is not in pair {self.pair_id}")
        return Seat(self, mmsis.index(mmsi))


@dataclass(frozen=True)
class Seat:
    """A pair seen from one vessel: ``own_index`` is 0 when own ship is vessel a, else 1."""

    pair: PairEvaluation
    own_index: int

    @property
    def target_index(self) -> int:
        return 1 - self.own_index

    def mine(self, values: tuple[T, T]) -> tuple[T, T]:
        """(own, target) from values in vessel order (a, b)."""
        return values[self.own_index], values[self.target_index]

    @property
    def own(self) -> VesselAtTrigger:
        return self.pair.vessels[self.own_index]

    @property
    def target(self) -> VesselAtTrigger:
        return self.pair.vessels[self.target_index]

    @property
    def prefixes(self) -> tuple[str, str]:
        """The pair series' column prefixes of own ship and target."""
        return self.mine(PREFIXES)

    def automata(self, verdict: PairVerdict) -> tuple[Rule9Assessment, Rule9Assessment]:
        """(own ship's G_d about the target, the target's G_d about own ship)."""
        return self.mine((verdict.seat_a, verdict.seat_b))

    @property
    def encounter_id(self) -> str:
        return f"{self.pair.encounter.start:%Y%m%dT%H%M%S}-{self.own.mmsi}-{self.target.mmsi}"


def nav_status(value: Any) -> int | None:
    """A series' navigational status cell as a code, or None."""
    return None if pd.isna(value) else int(value)


def reports_restricted(value: Any, restricted_nav_statuses: frozenset[int]) -> bool:
    """True when a series' navigational status cell claims restricted manoeuvrability (d2)."""
    return _finding(nav_status(value), restricted_nav_statuses) is Finding.TRUE


def rests_on_defaults(
    verdict: PairVerdict,
    dimensions: tuple[VesselDimensions, VesselDimensions],
    estimates: tuple[Restriction, Restriction],
    nav_status: tuple[int | None, int | None],
    restricted_nav_statuses: frozenset[int],
    standings: tuple[ChannelStanding, ChannelStanding] | None = None,
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
            standings,
        )
        if (alternative.role_final, alternative.deciding_rule) != (
            verdict.role_final,
            verdict.deciding_rule,
        ):
            return True
    return False
