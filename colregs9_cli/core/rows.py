"""The rows of pairs.csv and encounters.csv and the columns of each seat's time series: each a
projection of the pair model (``pair_model.py``), so that a new column is its field and one
line in its projection, here.

``PairSummary`` is the pair in vessel order (a, b); ``EncounterSummary`` and the series are
one ``Seat`` of it (own ship, target). Everything about the pair (situation, final roles,
audit facts) is the same in both seats' rows, seen from either side.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, TypeVar

import pandas as pd

from .audit import Action, Fact, all_of, negated
from .channel_audit import VesselInChannel
from .colregs import Role, Situation, SituationBasis
from .interactions import InteractionKind
from .manoeuvrability import Restriction, SwingModel
from .pair_model import PairEvaluation, Seat, VesselAtTrigger, reports_restricted
from .rule9 import DecidingRule, Rule9Clause


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
    interaction: InteractionKind
    interaction_basis: str
    situation: Situation | None
    situation_ambiguous: bool | None
    situation_basis: SituationBasis | None
    situation_utc: pd.Timestamp | None
    role_colregs_a: Role | None
    role_colregs_b: Role | None
    nav_status_a: int | None
    nav_status_b: int | None
    nav_status_believed_a: bool | None
    nav_status_believed_b: bool | None
    nav_status_doubt_a: str
    nav_status_doubt_b: str
    estimated_restricted_a: Restriction | None
    estimated_restricted_b: Restriction | None
    swing_model: SwingModel | None
    turn_radius_m_a: float | None
    turn_radius_m_b: float | None
    automaton_path_a: str | None
    automaton_path_b: str | None
    rule9_applied: bool | None
    rule9_clause: Rule9Clause | None
    deciding_rule: DecidingRule | None
    both_restricted: bool | None
    role_final_a: Role | None
    role_final_b: Role | None
    give_way_vessels: str | None
    verdict_rests_on_defaults: bool | None
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
    actual_min_separation_hull_m: float | None
    hull_antenna_position_assumed: bool | None
    min_separation_report_gap_s: float | None
    min_separation_at_fixes_m: float | None
    min_separation_interpolated: bool | None
    min_separation_over_land: bool | None
    largest_report_gap_s_a: float | None
    largest_report_gap_s_b: float | None
    reports_sparse_a: bool | None
    reports_sparse_b: bool | None
    channel_a: str | None
    channel_b: str | None
    channel_relation_a: str | None
    channel_relation_b: str | None
    channel_offset_m_a: float | None
    channel_offset_m_b: float | None
    channel_at_min_separation_a: str | None
    channel_at_min_separation_b: str | None
    channel_relation_at_min_separation_a: str | None
    channel_relation_at_min_separation_b: str | None
    channel_offset_m_at_min_separation_a: float | None
    channel_offset_m_at_min_separation_b: float | None
    keeps_to_starboard_side_a: Fact | None
    keeps_to_starboard_side_b: Fact | None
    keeps_to_starboard_side_basis_a: str | None
    keeps_to_starboard_side_basis_b: str | None
    follows_lane_direction_a: Fact | None
    follows_lane_direction_b: Fact | None
    crosses_lane_at_right_angles_a: Fact | None
    crosses_lane_at_right_angles_b: Fact | None
    traffic_lane_basis_a: str | None
    traffic_lane_basis_b: str | None
    confined_to_channel_a: Fact | None
    confined_to_channel_b: Fact | None
    confined_to_channel_basis_a: str | None
    confined_to_channel_basis_b: str | None
    give_way_vessel_acted: Fact | None
    give_way_action: str | None
    give_way_action_as_rule_asks: Fact | None
    action_before_cpa_s: str | None
    stand_on_vessel_kept_course: Fact | None
    stand_on_turned_to_port_for_vessel_on_port: Fact | None
    passed_port_to_port: Fact | None
    action_a: Action | None
    action_b: Action | None
    length_m_a: float
    breadth_m_a: float
    draught_m_a: float
    defaulted_dimensions_a: str
    length_m_b: float
    breadth_m_b: float
    draught_m_b: float
    defaulted_dimensions_b: str


PAIR_COLUMNS: tuple[str, ...] = tuple(f.name for f in dataclasses.fields(PairSummary))
# What only an encounter gets (interactions.py): empty for the other interactions.
PAIR_VERDICT_COLUMNS: tuple[str, ...] = (
    "situation",
    "situation_ambiguous",
    "situation_basis",
    "situation_utc",
    "role_colregs_a",
    "role_colregs_b",
    "estimated_restricted_a",
    "estimated_restricted_b",
    "swing_model",
    "turn_radius_m_a",
    "turn_radius_m_b",
    "automaton_path_a",
    "automaton_path_b",
    "rule9_applied",
    "rule9_clause",
    "deciding_rule",
    "both_restricted",
    "role_final_a",
    "role_final_b",
    "give_way_vessels",
    "verdict_rests_on_defaults",
    "give_way_vessel_acted",
    "give_way_action",
    "give_way_action_as_rule_asks",
    "action_before_cpa_s",
    "stand_on_vessel_kept_course",
    "stand_on_turned_to_port_for_vessel_on_port",
    "passed_port_to_port",
    "action_a",
    "action_b",
    "keeps_to_starboard_side_a",
    "keeps_to_starboard_side_b",
    "keeps_to_starboard_side_basis_a",
    "keeps_to_starboard_side_basis_b",
    "follows_lane_direction_a",
    "follows_lane_direction_b",
    "crosses_lane_at_right_angles_a",
    "crosses_lane_at_right_angles_b",
    "traffic_lane_basis_a",
    "traffic_lane_basis_b",
    "confined_to_channel_a",
    "confined_to_channel_b",
    "confined_to_channel_basis_a",
    "confined_to_channel_basis_b",
)


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
    interaction: InteractionKind
    interaction_basis: str
    situation: Situation | None
    situation_ambiguous: bool | None
    situation_basis: SituationBasis | None
    situation_utc: pd.Timestamp | None
    own_role_colregs: Role | None
    target_role_colregs: Role | None
    own_nav_status: int | None
    target_nav_status: int | None
    own_nav_status_believed: bool | None
    target_nav_status_believed: bool | None
    own_nav_status_doubt: str
    target_nav_status_doubt: str
    target_reports_restricted: bool
    target_estimated_restricted: Restriction | None
    own_estimated_restricted: Restriction | None
    automaton_path: str | None
    target_seat_automaton_path: str | None
    rule9_applied: bool | None
    rule9_clause: Rule9Clause | None
    deciding_rule: DecidingRule | None
    both_restricted: bool | None
    own_role_final: Role | None
    target_role_final: Role | None
    give_way_vessel: str | None
    give_way_vessels: str | None
    verdict_rests_on_defaults: bool | None
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
    actual_min_separation_hull_m: float | None
    hull_antenna_position_assumed: bool | None
    min_separation_report_gap_s: float | None
    min_separation_at_fixes_m: float | None
    min_separation_interpolated: bool | None
    min_separation_over_land: bool | None
    own_largest_report_gap_s: float | None
    target_largest_report_gap_s: float | None
    own_reports_sparse: bool | None
    target_reports_sparse: bool | None
    own_channel: str | None
    target_channel: str | None
    own_channel_relation: str | None
    target_channel_relation: str | None
    own_channel_offset_m: float | None
    target_channel_offset_m: float | None
    own_channel_at_min_separation: str | None
    target_channel_at_min_separation: str | None
    own_channel_relation_at_min_separation: str | None
    target_channel_relation_at_min_separation: str | None
    own_channel_offset_m_at_min_separation: float | None
    target_channel_offset_m_at_min_separation: float | None
    own_keeps_to_starboard_side: Fact | None
    target_keeps_to_starboard_side: Fact | None
    own_keeps_to_starboard_side_basis: str | None
    target_keeps_to_starboard_side_basis: str | None
    own_follows_lane_direction: Fact | None
    target_follows_lane_direction: Fact | None
    own_crosses_lane_at_right_angles: Fact | None
    target_crosses_lane_at_right_angles: Fact | None
    own_traffic_lane_basis: str | None
    target_traffic_lane_basis: str | None
    own_confined_to_channel: Fact | None
    target_confined_to_channel: Fact | None
    own_confined_to_channel_basis: str | None
    target_confined_to_channel_basis: str | None
    give_way_vessel_acted: Fact | None
    give_way_action: str | None
    give_way_action_as_rule_asks: Fact | None
    action_before_cpa_s: str | None
    stand_on_vessel_kept_course: Fact | None
    stand_on_turned_to_port_for_vessel_on_port: Fact | None
    passed_port_to_port: Fact | None
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
ENCOUNTER_VERDICT_COLUMNS: tuple[str, ...] = (
    "situation",
    "situation_ambiguous",
    "situation_basis",
    "situation_utc",
    "own_role_colregs",
    "target_role_colregs",
    "target_estimated_restricted",
    "own_estimated_restricted",
    "automaton_path",
    "target_seat_automaton_path",
    "rule9_applied",
    "rule9_clause",
    "deciding_rule",
    "both_restricted",
    "own_role_final",
    "target_role_final",
    "give_way_vessel",
    "give_way_vessels",
    "verdict_rests_on_defaults",
    "give_way_vessel_acted",
    "give_way_action",
    "give_way_action_as_rule_asks",
    "action_before_cpa_s",
    "stand_on_vessel_kept_course",
    "stand_on_turned_to_port_for_vessel_on_port",
    "passed_port_to_port",
    "own_keeps_to_starboard_side",
    "target_keeps_to_starboard_side",
    "own_keeps_to_starboard_side_basis",
    "target_keeps_to_starboard_side_basis",
    "own_follows_lane_direction",
    "target_follows_lane_direction",
    "own_crosses_lane_at_right_angles",
    "target_crosses_lane_at_right_angles",
    "own_traffic_lane_basis",
    "target_traffic_lane_basis",
    "own_confined_to_channel",
    "target_confined_to_channel",
    "own_confined_to_channel_basis",
    "target_confined_to_channel_basis",
)
# The series columns of the verdict, empty for the other interactions.
SERIES_VERDICT_COLUMNS: tuple[str, ...] = (
    "situation",
    "own_role_colregs",
    "target_role_colregs",
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
    "report_gap_s",
    "nearest_report_s",
    "gap_turn_deg",
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


RowT = TypeVar("RowT", "PairSummary", "EncounterSummary")


def situation_or_interaction(row: PairSummary | EncounterSummary) -> str:
    """The situation of an encounter, else the kind of interaction (``in-company`` …): what
    a report's situation column shows."""
    return row.interaction.value if row.situation is None else row.situation.value


def _blank(row: RowT, columns: Sequence[str]) -> RowT:
    """``row`` with ``columns`` empty: the verdict of a pair that is not an encounter."""
    empty: dict[str, Any] = dict.fromkeys(columns)
    return dataclasses.replace(row, **empty)


def _believed(vessel: VesselAtTrigger) -> bool | None:
    """Whether her status at the trigger is believed; None when she reported none."""
    return None if vessel.nav_status is None else vessel.nav_status_belief.believed


def _doubt(vessel: VesselAtTrigger) -> str:
    """Why her status is not believed (``ais_claims.py``); empty when it is."""
    return "" if vessel.nav_status_belief.believed else vessel.nav_status_belief.reason


def _mmsi_list(mmsis: Sequence[int]) -> str:
    return ";".join(str(m) for m in mmsis)


def _joined(values: Sequence[Any]) -> str:
    return ";".join(str(v) for v in values)


def _seconds(value: float | None) -> str:
    return "" if value is None else f"{value:g}"


def _channel_fields(vessel: VesselInChannel, name: str) -> dict[str, Any]:
    """A vessel's channel columns, named by ``name`` (``"{}_a"``, ``"own_{}"``)."""
    trigger, least = vessel.at_trigger, vessel.at_least_separation
    starboard = vessel.keeps_to_starboard_side
    return {
        name.format("channel"): trigger.channel,
        name.format("channel_relation"): None if trigger.channel is None else trigger.relation,
        name.format("channel_offset_m"): trigger.offset_m,
        name.format("channel_at_min_separation"): least.channel,
        name.format("channel_relation_at_min_separation"): (
            None if least.channel is None else least.relation
        ),
        name.format("channel_offset_m_at_min_separation"): least.offset_m,
        name.format("keeps_to_starboard_side"): starboard.fact,
        name.format("keeps_to_starboard_side_basis"): starboard.basis,
        name.format("follows_lane_direction"): vessel.lane.follows_lane,
        name.format("crosses_lane_at_right_angles"): vessel.lane.crosses_at_right_angles,
        name.format("traffic_lane_basis"): vessel.lane.basis,
        name.format("confined_to_channel"): vessel.confined.fact,
        name.format("confined_to_channel_basis"): vessel.confined.basis,
    }


def _largest_gap_s(pair: PairEvaluation, vessel: int) -> float | None:
    gaps = pair.audit.report_gaps[vessel]
    return None if gaps is None else gaps.largest_gap_s


def pair_row(pair: PairEvaluation, seats: Sequence[int]) -> PairSummary:
    """The pairs.csv row of ``pair``; ``seats``: the own-ship MMSIs reported."""
    verdict = pair.verdict
    trigger = pair.trigger
    held = pair.steps.held
    a, b = pair.vessels
    give_way = pair.with_role(Role.GIVE_WAY)
    stand_on = pair.with_role(Role.STAND_ON)
    row = PairSummary(
        pair_id=pair.pair_id,
        mmsi_a=a.mmsi,
        mmsi_b=b.mmsi,
        name_a=a.name,
        name_b=b.name,
        seats_reported=_mmsi_list(sorted(set(seats))),
        start_utc=pair.encounter.start,
        trigger_utc=trigger["timestamp"],
        end_utc=pair.encounter.end,
        interaction=pair.interaction.kind,
        interaction_basis=pair.interaction.basis,
        situation=verdict.situation,
        situation_ambiguous=bool(held.ambiguous[0]),
        situation_basis=held.basis[0],
        situation_utc=pair.situation_utc,
        role_colregs_a=verdict.role_colregs[0],
        role_colregs_b=verdict.role_colregs[1],
        nav_status_a=a.nav_status,
        nav_status_b=b.nav_status,
        nav_status_believed_a=_believed(a),
        nav_status_believed_b=_believed(b),
        nav_status_doubt_a=_doubt(a),
        nav_status_doubt_b=_doubt(b),
        estimated_restricted_a=a.estimated_restricted,
        estimated_restricted_b=b.estimated_restricted,
        swing_model=pair.swing_model,
        turn_radius_m_a=pair.turn_radius_m[0],
        turn_radius_m_b=pair.turn_radius_m[1],
        automaton_path_a=verdict.seat_a.path_text,
        automaton_path_b=verdict.seat_b.path_text,
        rule9_applied=verdict.rule9_applied,
        rule9_clause=pair.rule9_clause,
        deciding_rule=verdict.deciding_rule,
        both_restricted=verdict.both_restricted,
        role_final_a=verdict.role_final[0],
        role_final_b=verdict.role_final[1],
        give_way_vessels=_mmsi_list([v.mmsi for v in give_way]),
        verdict_rests_on_defaults=pair.verdict_rests_on_defaults,
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
        data_covers_cpa=pair.audit.covers_cpa,
        actual_min_separation_m=pair.audit.min_separation_m,
        actual_min_separation_utc=pair.audit.cpa_utc,
        actual_min_separation_hull_m=pair.audit.min_hull_separation_m,
        hull_antenna_position_assumed=pair.audit.hull_antenna_position_assumed,
        min_separation_report_gap_s=pair.audit.min_separation_report_gap_s,
        min_separation_at_fixes_m=pair.audit.min_separation_at_fixes_m,
        min_separation_interpolated=pair.audit.min_separation_interpolated,
        min_separation_over_land=pair.audit.min_separation_over_land,
        largest_report_gap_s_a=_largest_gap_s(pair, 0),
        largest_report_gap_s_b=_largest_gap_s(pair, 1),
        reports_sparse_a=pair.audit.reports_sparse(0),
        reports_sparse_b=pair.audit.reports_sparse(1),
        **_channel_fields(pair.in_channel[0], "{}_a"),
        **_channel_fields(pair.in_channel[1], "{}_b"),
        give_way_vessel_acted=all_of(v.conduct.changed for v in give_way) if give_way else None,
        give_way_action=_joined([v.conduct.action.value for v in give_way]),
        give_way_action_as_rule_asks=pair.give_way_action_as_rule_asks,
        action_before_cpa_s=_joined([_seconds(v.action_before_cpa_s) for v in give_way]),
        stand_on_vessel_kept_course=(
            all_of(negated(v.conduct.changed) for v in stand_on) if stand_on else None
        ),
        stand_on_turned_to_port_for_vessel_on_port=pair.stand_on_turned_to_port,
        passed_port_to_port=pair.passed_port_to_port,
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
    return row if pair.is_encounter else _blank(row, PAIR_VERDICT_COLUMNS)


def _give_way_side(own_role: Role, target_role: Role) -> str:
    sides = [
        side for side, role in (("own", own_role), ("target", target_role)) if role is Role.GIVE_WAY
    ]
    return "+".join(sides) if sides else "none"


def seat_row(seat: Seat, pair: PairSummary) -> EncounterSummary:
    """The encounters.csv row of one seat; ``pair`` is the pair's row (``pair_row``)."""
    verdict = seat.pair.verdict
    own, target = seat.own, seat.target
    own_automaton, target_automaton = seat.automata(verdict)
    own_colregs, target_colregs = seat.mine(verdict.role_colregs)
    own_final, target_final = seat.mine(verdict.role_final)
    row = EncounterSummary(
        encounter_id=seat.encounter_id,
        pair_id=pair.pair_id,
        own_mmsi=own.mmsi,
        target_mmsi=target.mmsi,
        own_name=own.name,
        target_name=target.name,
        start_utc=pair.start_utc,
        trigger_utc=pair.trigger_utc,
        end_utc=pair.end_utc,
        interaction=pair.interaction,
        interaction_basis=pair.interaction_basis,
        situation=pair.situation,
        situation_ambiguous=pair.situation_ambiguous,
        situation_basis=pair.situation_basis,
        situation_utc=pair.situation_utc,
        own_role_colregs=own_colregs,
        target_role_colregs=target_colregs,
        own_nav_status=own.nav_status,
        target_nav_status=target.nav_status,
        own_nav_status_believed=_believed(own),
        target_nav_status_believed=_believed(target),
        own_nav_status_doubt=_doubt(own),
        target_nav_status_doubt=_doubt(target),
        target_reports_restricted=reports_restricted(
            target.nav_status, seat.pair.restricted_nav_statuses
        ),
        target_estimated_restricted=target.estimated_restricted,
        own_estimated_restricted=own.estimated_restricted,
        automaton_path=own_automaton.path_text,
        target_seat_automaton_path=target_automaton.path_text,
        rule9_applied=pair.rule9_applied,
        rule9_clause=pair.rule9_clause,
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
        actual_min_separation_hull_m=pair.actual_min_separation_hull_m,
        hull_antenna_position_assumed=pair.hull_antenna_position_assumed,
        min_separation_report_gap_s=pair.min_separation_report_gap_s,
        min_separation_at_fixes_m=pair.min_separation_at_fixes_m,
        min_separation_interpolated=pair.min_separation_interpolated,
        min_separation_over_land=pair.min_separation_over_land,
        own_largest_report_gap_s=_largest_gap_s(seat.pair, seat.mine((0, 1))[0]),
        target_largest_report_gap_s=_largest_gap_s(seat.pair, seat.mine((0, 1))[1]),
        own_reports_sparse=seat.pair.audit.reports_sparse(seat.mine((0, 1))[0]),
        target_reports_sparse=seat.pair.audit.reports_sparse(seat.mine((0, 1))[1]),
        **_channel_fields(seat.mine(seat.pair.in_channel)[0], "own_{}"),
        **_channel_fields(seat.mine(seat.pair.in_channel)[1], "target_{}"),
        give_way_vessel_acted=pair.give_way_vessel_acted,
        give_way_action=pair.give_way_action,
        give_way_action_as_rule_asks=pair.give_way_action_as_rule_asks,
        action_before_cpa_s=pair.action_before_cpa_s,
        stand_on_vessel_kept_course=pair.stand_on_vessel_kept_course,
        stand_on_turned_to_port_for_vessel_on_port=pair.stand_on_turned_to_port_for_vessel_on_port,
        passed_port_to_port=pair.passed_port_to_port,
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
    return row if seat.pair.is_encounter else _blank(row, ENCOUNTER_VERDICT_COLUMNS)


def seat_series(seat: Seat) -> pd.DataFrame:
    """The time series of one seat (``SERIES_COLUMNS``), from the trigger to the pass."""
    steps = seat.pair.steps
    series = steps.series
    statuses = seat.pair.restricted_nav_statuses
    timestamps = series["timestamp"].tolist()
    columns: dict[str, Any] = {
        "step": series["step"].to_numpy(),
        "timestamp": series["timestamp"].to_numpy(),
    }
    own_prefix, target_prefix = seat.prefixes
    for name in SERIES_VESSEL_FIELDS:
        columns[f"own_{name}"] = series[f"{own_prefix}{name}"].to_numpy()
        columns[f"target_{name}"] = series[f"{target_prefix}{name}"].to_numpy()
    for name in ("range_m", "cpa_m", "tcpa_s"):
        columns[name] = series[name].to_numpy()
    # beta is the bearing of the target from own ship, beta' of own ship from the target.
    columns["beta_deg"], columns["beta_prime_deg"] = seat.mine(
        (steps.g_a.beta_deg, steps.g_a.beta_prime_deg)
    )
    own_roles, target_roles = seat.mine((steps.held.own_role, steps.held.target_role))
    columns |= {
        "situation_now": [s.value for s in steps.g_a.situation],
        "situation_now_ambiguous": steps.g_a.ambiguous,
        "situation": [s.value for s in steps.held.situation],
        "own_role_colregs": [r.value for r in own_roles],
        "target_role_colregs": [r.value for r in target_roles],
    }
    for prefix, vessel, source in zip(
        ("own_", "target_"), seat.mine((0, 1)), seat.prefixes, strict=True
    ):
        columns[f"{prefix}reports_restricted"] = [
            reports_restricted(v, statuses) for v in series[f"{source}nav_status"].tolist()
        ]
        columns[f"{prefix}estimated_restricted"] = [e.value for e in steps.estimates[vessel]]
        columns[f"{prefix}assessed_utc"] = [timestamps[r] for r in steps.assessed_row[vessel]]
    automata = [seat.automata(v) for v in steps.verdicts]
    columns |= {
        "automaton_state": [own.final_state.value for own, _ in automata],
        "automaton_path": [own.path_text for own, _ in automata],
        "target_seat_automaton_path": [other.path_text for _, other in automata],
        "rule9_applied": [v.rule9_applied for v in steps.verdicts],
        "deciding_rule": [v.deciding_rule.value for v in steps.verdicts],
        "own_role_final": [seat.mine(v.role_final)[0].value for v in steps.verdicts],
        "target_role_final": [seat.mine(v.role_final)[1].value for v in steps.verdicts],
    }
    series_table = pd.DataFrame(columns)[list(SERIES_COLUMNS)]
    if not seat.pair.is_encounter:
        series_table[list(SERIES_VERDICT_COLUMNS)] = None
    return series_table
