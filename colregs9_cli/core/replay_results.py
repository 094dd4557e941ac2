"""The results of ``colregs9 replay``: the row types of pairs.csv and encounters.csv, the
time-series columns, and the run's result. Below both ``replay`` (which fills them) and
``report.replay_report`` (which lays them out), so that every import points down.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from ..geo import LocalFrame
from .audit import Action, Conduct, Fact
from .colregs import ColregsParams, Role, Situation, SituationBasis
from .manoeuvrability import ManoeuvrabilityAssessment, ManoeuvrabilityParams, Restriction
from .replay_params import ReplayParams
from .rule9 import DecidingRule
from .vessel_defaults import VesselDimensions


@dataclass(frozen=True)
class ReplayRunParams:
    """Every parameter of one replay run, as written to run.json."""

    replay: ReplayParams
    colregs: ColregsParams
    manoeuvrability: ManoeuvrabilityParams
    own_mmsi: tuple[int, ...]


@dataclass(frozen=True)
class VesselAtTrigger:
    """One vessel of a pair: who she is, her state at the trigger and her conduct after it."""

    mmsi: int
    name: str | None
    dimensions: VesselDimensions
    nav_status: int | None
    course_deg: float
    speed_kn: float
    lat_deg: float
    lon_deg: float
    lat_deg_at_cpa: float  # predicted at constant velocity from the trigger to TCPA
    lon_deg_at_cpa: float
    estimated_restricted: Restriction
    conduct: Conduct
    action_before_cpa_s: float | None


@dataclass(frozen=True)
class PairSummary:
    """One row of pairs.csv: the pair-level verdict; vessel a has the lower MMSI."""

    pair_id: str
    mmsi_a: int
    mmsi_b: int
    name_a: str | None
    name_b: str | None
    seats_reported: str
    start_utc: pd.Timestamp
    trigger_utc: pd.Timestamp
    end_utc: pd.Timestamp
    situation: Situation
    situation_ambiguous: bool
    situation_basis: SituationBasis
    role_colregs_a: Role
    role_colregs_b: Role
    nav_status_a: int | None
    nav_status_b: int | None
    estimated_restricted_a: Restriction
    estimated_restricted_b: Restriction
    automaton_path_a: str
    automaton_path_b: str
    rule9_applied: bool
    deciding_rule: DecidingRule
    both_restricted: bool
    role_final_a: Role
    role_final_b: Role
    give_way_vessels: str
    verdict_rests_on_defaults: bool
    range_m_at_trigger: float
    cpa_m: float
    tcpa_s: float
    lat_deg_at_trigger_a: float
    lon_deg_at_trigger_a: float
    lat_deg_at_trigger_b: float
    lon_deg_at_trigger_b: float
    lat_deg_at_cpa_a: float
    lon_deg_at_cpa_a: float
    lat_deg_at_cpa_b: float
    lon_deg_at_cpa_b: float
    data_covers_cpa: bool
    actual_min_separation_m: float | None
    actual_min_separation_utc: pd.Timestamp | None
    give_way_vessel_acted: Fact | None
    give_way_action: str
    action_before_cpa_s: str
    stand_on_vessel_kept_course: Fact | None
    action_a: Action
    action_b: Action
    length_m_a: float
    breadth_m_a: float
    draught_m_a: float
    defaulted_dimensions_a: str
    length_m_b: float
    breadth_m_b: float
    draught_m_b: float
    defaulted_dimensions_b: str


PAIR_COLUMNS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(PairSummary))


@dataclass(frozen=True)
class EncounterSummary:
    """One row of encounters.csv (one seat of a pair); the field order is the column order.

    ``automaton_path`` is this seat's G_d (own ship asks about the target) and
    ``target_seat_automaton_path`` the other seat's (the target asks about own ship).
    Everything about the pair (situation, final roles, audit facts) is the same in both
    seats' rows, seen from the other side.
    """

    encounter_id: str
    pair_id: str
    own_mmsi: int
    target_mmsi: int
    own_name: str | None
    target_name: str | None
    start_utc: pd.Timestamp
    trigger_utc: pd.Timestamp
    end_utc: pd.Timestamp
    situation: Situation
    situation_ambiguous: bool
    situation_basis: SituationBasis
    own_role_colregs: Role
    target_role_colregs: Role
    own_nav_status: int | None
    target_nav_status: int | None
    target_reports_restricted: bool
    target_estimated_restricted: Restriction
    own_estimated_restricted: Restriction
    automaton_path: str
    target_seat_automaton_path: str
    rule9_applied: bool
    deciding_rule: DecidingRule
    both_restricted: bool
    own_role_final: Role
    target_role_final: Role
    give_way_vessel: str
    give_way_vessels: str
    verdict_rests_on_defaults: bool
    range_m_at_trigger: float
    cpa_m: float
    tcpa_s: float
    own_lat_deg_at_trigger: float
    own_lon_deg_at_trigger: float
    target_lat_deg_at_trigger: float
    target_lon_deg_at_trigger: float
    own_lat_deg_at_cpa: float
    own_lon_deg_at_cpa: float
    target_lat_deg_at_cpa: float
    target_lon_deg_at_cpa: float
    data_covers_cpa: bool
    actual_min_separation_m: float | None
    actual_min_separation_utc: pd.Timestamp | None
    give_way_vessel_acted: Fact | None
    give_way_action: str
    action_before_cpa_s: str
    stand_on_vessel_kept_course: Fact | None
    own_course_deg_at_trigger: float
    own_speed_kn_at_trigger: float
    target_course_deg_at_trigger: float
    target_speed_kn_at_trigger: float
    own_length_m: float
    own_breadth_m: float
    own_draught_m: float
    own_dimensions_defaulted: str
    target_length_m: float
    target_breadth_m: float
    target_draught_m: float
    target_dimensions_defaulted: str


ENCOUNTER_COLUMNS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(EncounterSummary))

# Per-vessel columns of a time series; each seat's series has them as own_* and target_*.
SERIES_VESSEL_FIELDS: tuple[str, ...] = (
    "lat_deg",
    "lon_deg",
    "north_m",
    "east_m",
    "cog_deg",
    "heading_deg",
    "course_deg",
    "sog_kn",
    "nav_status",
)
SERIES_COLUMNS: tuple[str, ...] = (
    "step",
    "timestamp",
    *(f"own_{name}" for name in SERIES_VESSEL_FIELDS),
    *(f"target_{name}" for name in SERIES_VESSEL_FIELDS),
    "range_m",
    "cpa_m",
    "tcpa_s",
    "beta_deg",
    "beta_prime_deg",
    "situation_now",
    "situation_now_ambiguous",
    "situation",
    "own_role_colregs",
    "target_role_colregs",
    "own_reports_restricted",
    "target_reports_restricted",
    "own_estimated_restricted",
    "target_estimated_restricted",
    "own_assessed_utc",
    "target_assessed_utc",
    "automaton_state",
    "automaton_path",
    "target_seat_automaton_path",
    "rule9_applied",
    "deciding_rule",
    "own_role_final",
    "target_role_final",
)


@dataclass(frozen=True)
class EncounterOutcome:
    """One seat of a triggered pair: its row, time series and what its figure shows.

    ``own_track``/``target_track`` (``north_m``, ``east_m``) cover the encounter and the
    audit window after it; ``*_at_trigger_m`` are (north, east) at the trigger and
    ``*_at_tcpa_m`` predicted at constant velocity from the trigger to TCPA; ``assessment`` is
    the target's manoeuvrability at the trigger. These metres are in ``frame``: the run's
    frame, or, for a pair beyond its reach (``geo.FRAME_REACH_M``), a frame centred on the
    pair, where no chart and no arcs are drawn.
    """

    summary: EncounterSummary
    series: pd.DataFrame
    own_track: pd.DataFrame
    target_track: pd.DataFrame
    own_at_trigger_m: tuple[float, float]
    target_at_trigger_m: tuple[float, float]
    own_at_tcpa_m: tuple[float, float]
    target_at_tcpa_m: tuple[float, float]
    assessment: ManoeuvrabilityAssessment
    frame: LocalFrame
    in_run_frame: bool


@dataclass(frozen=True)
class PairOutcome:
    """A triggered pair: its pair-level row and one outcome per reported seat."""

    summary: PairSummary
    seats: tuple[EncounterOutcome, ...]


@dataclass(frozen=True)
class ReplayCounts:
    vessels: int
    segments: int
    candidate_pair_steps: int
    candidate_pairs: int
    encounters: int
    triggered: int
    triggered_pairs: int


@dataclass(frozen=True)
class ReplayResult:
    """What ``colregs9 replay`` produced."""

    query_name: str
    out_dir: Path
    frame: LocalFrame
    params: ReplayRunParams
    pairs: tuple[PairOutcome, ...]
    counts: ReplayCounts
    manifest: dict[str, Any]
    files: tuple[Path, ...]
    text: str = ""  # the summary printed to stdout (report.replay_report.format_summary)

    @property
    def encounters(self) -> tuple[EncounterOutcome, ...]:
        """Every reported seat, ordered by start, own MMSI and target MMSI."""
        return seats_in_order(self.pairs)


def seats_in_order(pairs: Sequence[PairOutcome]) -> tuple[EncounterOutcome, ...]:
    """The pairs' seats ordered by start, own MMSI and target MMSI: the order of the reports'
    rows. Slabs own the encounters that start in them, so the seats of consecutive slabs,
    each ordered, follow one another in this order."""
    seats = [seat for pair in pairs for seat in pair.seats]
    return tuple(
        sorted(
            seats, key=lambda o: (o.summary.start_utc, o.summary.own_mmsi, o.summary.target_mmsi)
        )
    )
