"""Audit facts beyond the paper (docs/design.md §5 Replay): what each vessel did before the
closest approach, and whether it was what the rules ask.

Every function works on one pair's steps from the trigger on (row 0 is the trigger), both
vessels present at every step. The facts are three-valued (``Fact``): where the data stops
before the closest approach the answer is ``insufficient-data``, never ``false``.

- **The pass** is ``passing.py``'s: the range opened clearly past its least value.
- **Conduct.** Up to the closest approach, a vessel *changed* when her course turned by at
  least ``course_change_deg`` from her first course that can be judged, or her speed changed
  by at least ``speed_change_frac`` of her speed at the trigger and by at least
  ``speed_change_min_kn`` (a slow vessel's SOG noise is a large fraction of it). A course is
  judged only at speeds of at least ``course_judged_above_kn``: below that COG is GPS noise.
  The first change in time is her action (starboard turn, port turn, slowed, stopped, sped
  up). A slowing is *stopped* when her speed, once slowed, falls below ``stopped_below_kn``
  at any step up to the closest approach (rule 8(e): "take all way off"); its row is still
  the row where the slowing began. With no change, and her course judged at fewer than half
  of the steps, the answer is ``insufficient-data``: a slow vessel's turn cannot be seen in
  her COG.
- **Only what her reports show.** Her course and speed are judged only at *observed* rows:
  at one of her reports, or interpolated across a gap between two reports of at most
  ``observed_gap_max_s`` (30 s, the interval of a Class B transponder above 2 kn and the
  longest of a Class A one under way, ITU-R M.1371-5 Table 1 and Annex 2 Table 2). Inside a
  longer gap the series is a straight line drawn between two reports, and a change that
  line shows happened at some unknown time in the gap (San Diego: a yacht reporting 0.4 kn
  and, 151 s later, 4.8 kn "sped up" 45 s after a trigger 4 s into that gap). Her reference
  is her first observed row. When the trigger falls inside a longer gap and her course or
  speed changed across it (the trigger's interpolated values against the gap's closing
  report), the change may have come before the trigger or after it: her conduct is
  ``insufficient-data``. Likewise at the other end: when the closest approach falls inside a
  longer gap, no action was seen before it, and her course or speed changed across that gap
  (her last report before it against her first after it), the change may have come before
  the closest approach: ``insufficient-data`` (San Diego: WELL PLAYED reported 009° at
  00:12:56 and 319° at 00:14:27, and the least separation was drawn at 00:14:06).
- **The kind of action** (``action_as_rule_asks``). Whether the give-way vessel's action is
  the kind the deciding rule asks for (judged on her first action only):

  ============  ==================================  =====================================
  deciding      as the rule asks                    not as the rule asks
  ============  ==================================  =====================================
  14 head-on    starboard turn (rule 14(a))         port turn, slowed, stopped, sped up,
                                                    none
  15 crossing   starboard turn, slowed, stopped     port turn, sped up ("avoid crossing
                (rules 15, 16, 8(e))                ahead", rule 15), none (rule 16)
  13, 9, 18     a turn either way that opened the   sped up, none, a turn after which
                predicted CPA, slowed, stopped      the predicted CPA was nearer
  ============  ==================================  =====================================

  Rules 13 ("keep out of the way"), 9(b)–(d) ("not impede") and 18 ("keep out of the way")
  name no side: which side is clear depends on where the other vessel is and on the water,
  so either turn is of the kind they ask, if it turned her away: a turn after which the
  predicted closest approach is nearer than at the trigger closed on the other vessel and
  kept out of nobody's way (DMA: a boat overtaking a ship turned to port toward her, and the
  predicted CPA fell from 150 m to 26 m). Whether the pass was in fact clear is the separate
  ``passing.Passing.min_separation_m``. Rule 14(a) names the alteration to starboard: a slowing may
  go with it, but one that comes first is the action judged, and is not the alteration.
  Speeding up is never of the kind: rule 8(e) names slackening speed,
  stopping or reversing as the speed actions that avoid a collision or allow more time, and
  a faster give-way vessel closes on the other and leaves both less time. No action is not
  of the kind either: rule 16 asks every give-way vessel to "take early and substantial
  action", and the trigger (CPA under ``cpa_req_m`` within ``tcpa_act_s``) says one was
  needed. An action that is ``insufficient-data`` gives ``insufficient-data``; a vessel that
  is not a give-way vessel, or a pair with no situation, gives ``None`` (not applicable).
- **Rule 14(a)** (``passed_port_to_port``): in a head-on situation, whether each vessel had
  the other on her port side at the least separation.
- **Rule 17(c)** (``stand_on_turned_to_port_for_vessel_on_port``). In a rule 15 crossing the
  stand-on vessel that acts "shall, if the circumstances of the case admit, not alter course
  to port for a vessel on her own port side". The fact is ``true`` when her action was a
  port turn and the give-way vessel bore from her, at the trigger, more than 0° and less than
  180° to port (relative bearing in (180°, 360°)). A rule 9 or 18 pair is not judged (``None``):
  rule 17(c) binds two power-driven vessels in a crossing, and a rule 9 or 18 stand-on
  vessel is in the channel or of another kind. Nor is a vessel that is not the stand-on
  vessel of a crossing. A port turn with the bearing unknown is ``insufficient-data``.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import ArrayLike

from ..errors import ParameterError
from ..units import signed_angle_deg, wrap_deg
from .colregs import Role, Situation
from .rule9 import DecidingRule


class Fact(StrEnum):
    TRUE = "true"
    FALSE = "false"
    INSUFFICIENT = "insufficient-data"

    @classmethod
    def of(cls, value: bool) -> Fact:
        return cls.TRUE if value else cls.FALSE


class Action(StrEnum):
    STARBOARD_TURN = "starboard-turn"
    PORT_TURN = "port-turn"
    SLOWED = "slowed"
    STOPPED = "stopped"  # slowed, and then below ``ConductParams.stopped_below_kn``
    SPED_UP = "sped-up"
    NONE = "none"
    INSUFFICIENT = "insufficient-data"


@dataclass(frozen=True)
class ConductParams:
    """The thresholds of the module docstring.

    ``stopped_below_kn`` (default 0.5 kn) is the replay's ``min_sog_kn``, below which a
    vessel is not under way for the pair search; AIS SOG at rest sits under it (San Diego
    fixture, status at anchor or moored: 99 % of reports ≤ 0.5 kn, the highest 0.6 kn).
    """

    course_change_deg: float
    speed_change_frac: float
    speed_change_min_kn: float
    course_judged_above_kn: float
    stopped_below_kn: float = 0.5
    observed_gap_max_s: float = 30.0

    def __post_init__(self) -> None:
        for name in ("stopped_below_kn", "observed_gap_max_s"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ParameterError(f"[replay] {name} = {value!r}: give a number >= 0")


@dataclass(frozen=True)
class Conduct:
    """What one vessel did from the trigger to the closest approach."""

    changed: Fact  # true: she changed course or speed; false: she kept both
    action: Action
    action_row: int | None


INSUFFICIENT_CONDUCT = Conduct(Fact.INSUFFICIENT, Action.INSUFFICIENT, None)


def observed_rows(
    report_gap_s: ArrayLike, nearest_report_s: ArrayLike, step_s: float, params: ConductParams
) -> np.ndarray:
    """The rows where a vessel's course and speed are observed (module docstring): at one of
    her reports (one less than a step away) or interpolated across a short gap."""
    gap = np.asarray(report_gap_s, dtype=float)
    nearest = np.asarray(nearest_report_s, dtype=float)
    with np.errstate(invalid="ignore"):
        return (nearest < step_s) | (gap <= params.observed_gap_max_s)


def course_drawn_through_a_turn(
    report_gap_s: ArrayLike, gap_turn_deg: ArrayLike, params: ConductParams
) -> np.ndarray:
    """The rows where a vessel's course is interpolated across a gap between two of her
    reports longer than ``observed_gap_max_s`` in which she turned by ``course_change_deg``
    or more: a straight line drawn through her turn, no observation of her heading (San
    Diego: SHELTER ISLAND reported 087° and, three minutes later, 126°; the crossing read
    from the 113° between was a meeting at the later report)."""
    gap = np.asarray(report_gap_s, dtype=float)
    turn = np.asarray(gap_turn_deg, dtype=float)
    with np.errstate(invalid="ignore"):
        return (gap > params.observed_gap_max_s) & (turn >= params.course_change_deg)


def conduct(
    course_deg: ArrayLike,
    sog_kn: ArrayLike,
    params: ConductParams,
    observed: ArrayLike | None = None,
    last_row: int | None = None,
) -> Conduct:
    """One vessel's conduct from the trigger (row 0) to the closest approach (``last_row``,
    default the last row).

    ``observed`` (``observed_rows``; default: every row) marks the rows her reports show.
    Rows after ``last_row`` are read only to close a report gap that holds it."""
    course_all = np.asarray(course_deg, dtype=float)
    sog_all = np.asarray(sog_kn, dtype=float)
    seen = np.ones(len(sog_all), bool) if observed is None else np.asarray(observed, bool)
    last = len(sog_all) - 1 if last_row is None else last_row
    rows = np.flatnonzero(seen[: last + 1])
    if len(rows) == 0:
        return INSUFFICIENT_CONDUCT
    if rows[0] > 0 and _changed_between(course_all, sog_all, 0, int(rows[0]), params):
        return INSUFFICIENT_CONDUCT
    found = _conduct_at(course_all[rows], sog_all[rows], params)
    if found.action_row is not None:
        return Conduct(found.changed, found.action, int(rows[found.action_row]))
    if not seen[last]:
        after = np.flatnonzero(seen[last + 1 :])
        if not len(after) or _changed_between(
            course_all, sog_all, int(rows[-1]), last + 1 + int(after[0]), params
        ):
            return INSUFFICIENT_CONDUCT
    return found


def _changed_between(
    course: np.ndarray, sog: np.ndarray, first: int, last: int, params: ConductParams
) -> bool:
    """Whether her course or speed differs between two rows by an action's threshold."""
    return _conduct_at(course[[first, last]], sog[[first, last]], params).changed is Fact.TRUE


def _conduct_at(course: np.ndarray, sog: np.ndarray, params: ConductParams) -> Conduct:
    """``conduct`` over rows that are all observed (row 0 the reference)."""
    judged = np.isfinite(course) & (sog >= params.course_judged_above_kn)
    events: list[tuple[int, Action]] = []
    if judged.any():
        reference = course[int(np.flatnonzero(judged)[0])]
        change = np.where(judged, signed_angle_deg(course - reference), 0.0)
        turned = np.flatnonzero(np.abs(change) >= params.course_change_deg)
        if len(turned):
            row = int(turned[0])
            events.append((row, Action.STARBOARD_TURN if change[row] > 0.0 else Action.PORT_TURN))
    trigger_speed = float(sog[0]) if len(sog) else math.nan
    if math.isfinite(trigger_speed) and trigger_speed > 0.0:
        least_kn = max(params.speed_change_frac * trigger_speed, params.speed_change_min_kn)
        with np.errstate(invalid="ignore"):
            slowed = np.flatnonzero(sog <= trigger_speed - least_kn)
            sped_up = np.flatnonzero(sog >= trigger_speed + least_kn)
        if len(slowed):
            stopped = bool((sog[slowed] < params.stopped_below_kn).any())
            events.append((int(slowed[0]), Action.STOPPED if stopped else Action.SLOWED))
        if len(sped_up):
            events.append((int(sped_up[0]), Action.SPED_UP))
    if events:
        row, action = min(events, key=lambda event: event[0])
        return Conduct(Fact.TRUE, action, row)
    if judged.mean() < 0.5:
        return INSUFFICIENT_CONDUCT
    return Conduct(Fact.FALSE, Action.NONE, None)


# The kinds of action each deciding rule asks of the give-way vessel (module docstring).
_KEEPS_OUT_OF_THE_WAY = frozenset(
    {Action.STARBOARD_TURN, Action.PORT_TURN, Action.SLOWED, Action.STOPPED}
)
_KINDS_ASKED: dict[DecidingRule, frozenset[Action]] = {
    DecidingRule.RULE_14: frozenset({Action.STARBOARD_TURN}),
    DecidingRule.RULE_15: frozenset({Action.STARBOARD_TURN, Action.SLOWED, Action.STOPPED}),
    DecidingRule.RULE_13: _KEEPS_OUT_OF_THE_WAY,
    DecidingRule.RULE_9: _KEEPS_OUT_OF_THE_WAY,
    DecidingRule.RULE_18: _KEEPS_OUT_OF_THE_WAY,
}
_TURNS = frozenset({Action.STARBOARD_TURN, Action.PORT_TURN})
_NAME_NO_SIDE = frozenset({DecidingRule.RULE_13, DecidingRule.RULE_9, DecidingRule.RULE_18})
# rule9.decide_pair: rules 13-15 decide only their own situation, and rule 13 keeps the
# roles of every overtaking, so rules 9 and 18 never decide one.
_SITUATIONS_DECIDED: dict[DecidingRule, frozenset[Situation]] = {
    DecidingRule.RULE_13: frozenset({Situation.OVERTAKING}),
    DecidingRule.RULE_14: frozenset({Situation.HEAD_ON}),
    DecidingRule.RULE_15: frozenset({Situation.CROSSING}),
    DecidingRule.RULE_9: frozenset({Situation.HEAD_ON, Situation.CROSSING}),
    DecidingRule.RULE_18: frozenset({Situation.HEAD_ON, Situation.CROSSING}),
    DecidingRule.NONE: frozenset({Situation.NONE}),
}


def _decided(situation: Situation, deciding_rule: DecidingRule) -> tuple[Situation, DecidingRule]:
    """The enums (from members or their strings); a pair rule9 cannot decide is a bug."""
    situation, deciding_rule = Situation(situation), DecidingRule(deciding_rule)
    if situation not in _SITUATIONS_DECIDED[deciding_rule]:
        raise ValueError(f"rule {deciding_rule.value!r} does not decide a {situation} situation")
    return situation, deciding_rule


def action_as_rule_asks(
    situation: Situation,
    deciding_rule: DecidingRule,
    role: Role,
    action: Action,
    closed_cpa: bool = False,
) -> Fact | None:
    """Whether a vessel's action is of the kind the deciding rule asks of a give-way vessel.

    ``role`` is her final role (``PairVerdict.role_final``). ``closed_cpa``: the predicted
    closest approach at her action's row is nearer than at the trigger (a turn then counts
    for no rule that names no side). ``None`` where there is no give-way action to judge: she
    is not a give-way vessel, or the pair has no situation. Members or their strings (as in
    pairs.csv) are accepted.
    """
    situation, deciding_rule = _decided(situation, deciding_rule)
    if deciding_rule is DecidingRule.NONE or Role(role) is not Role.GIVE_WAY:
        return None
    action = Action(action)
    if action is Action.INSUFFICIENT:
        return Fact.INSUFFICIENT
    if closed_cpa and action in _TURNS and deciding_rule in _NAME_NO_SIDE:
        return Fact.FALSE
    return Fact.of(action in _KINDS_ASKED[deciding_rule])


def stand_on_turned_to_port_for_vessel_on_port(
    situation: Situation,
    deciding_rule: DecidingRule,
    role: Role,
    action: Action,
    give_way_bearing_deg: float,
) -> Fact | None:
    """Rule 17(c) breached: the stand-on vessel of a rule 15 crossing turned to port for a
    give-way vessel on her own port side.

    ``give_way_bearing_deg`` is the give-way vessel's bearing from the stand-on vessel at the
    trigger, clockwise from her course (the stand-on seat's ``beta_deg``); NaN when unknown.
    ``None`` where rule 17(c) does not apply (module docstring).
    """
    situation, deciding_rule = _decided(situation, deciding_rule)
    if deciding_rule is not DecidingRule.RULE_15 or Role(role) is not Role.STAND_ON:
        return None
    action = Action(action)
    if action is Action.INSUFFICIENT:
        return Fact.INSUFFICIENT
    if action is not Action.PORT_TURN:
        return Fact.FALSE
    if not math.isfinite(give_way_bearing_deg):
        return Fact.INSUFFICIENT
    # dead ahead (0°) and dead astern (180°) are on neither side
    return Fact.of(float(wrap_deg(give_way_bearing_deg)) > 180.0)


def passed_port_to_port(
    situation: Situation, bearings_deg: tuple[float, float], courses_judged: bool
) -> Fact | None:
    """Rule 14(a): two vessels meeting head-on pass "on the port side of the other".

    ``bearings_deg``: each vessel's bearing of the other at the least separation, clockwise
    from her course (``beta_deg``, ``beta_prime_deg``); true when each had the other on her
    port side (in (180°, 360°)). ``courses_judged``: both courses there are judged (at
    ``course_judged_above_kn`` or more), else ``insufficient-data``. ``None`` unless the
    situation is head-on. A head-on pair that already passes port to port needs no turn:
    this is the fact to read beside a ``give_way_vessel_acted`` of false (two vessels each
    keeping to her own side of a channel).
    """
    if Situation(situation) is not Situation.HEAD_ON:
        return None
    if not courses_judged or not all(math.isfinite(b) for b in bearings_deg):
        return Fact.INSUFFICIENT
    return Fact.of(all(float(wrap_deg(b)) > 180.0 for b in bearings_deg))


def all_of(facts: Iterable[Fact]) -> Fact:
    """Three-valued AND: false if any is false, else insufficient if any is, else true."""
    values = list(facts)
    if Fact.FALSE in values:
        return Fact.FALSE
    if Fact.INSUFFICIENT in values:
        return Fact.INSUFFICIENT
    return Fact.TRUE


def negated(fact: Fact) -> Fact:
    return {Fact.TRUE: Fact.FALSE, Fact.FALSE: Fact.TRUE}.get(fact, Fact.INSUFFICIENT)
