"""The COLREGs rule 9 assessment automaton G_d (paper, Fig. "automaton_A"; docs/design.md §5).

G_d = (D, E_d, f_d, D1, {D1, D4}) with

    D1  check whether the target needs to give way        (initial, marked)
    D2  check whether the target reports restricted manoeuvrability
    D3  evaluate the target's manoeuvrability
    D4  apply rule 9: invert give-way/stand-on             (marked)

and the transition function ``TRANSITIONS`` (exactly the figure's six arrows):

    D1 –¬d1→ D1    D1 –d1→ D2
    D2 –d2→  D4    D2 –¬d2→ D3
    D3 –d3→  D4    D3 –¬d3→ D1

Events, as in the paper: d1 the target needs to give way under rules 13–15 (a crossing or
overtaking in which own ship stands on, and every head-on); d2 the target's AIS navigational
status is in the restricted set (``Rule9Params.restricted_nav_statuses``, default {3, 4});
d3 the manoeuvrability estimator says the target is restricted, or, where the chart charts
channels, she proceeds along a narrow one to which her draught confines her (the water
navigable for her ends within her length of its limits on both hands, in a channel under
five of her lengths wide for her: ``confinement.confined_to_channel``, rule 9(b)'s "a vessel
which can safely navigate only within a narrow channel"). The
estimator's "unknown" is ¬d3, recorded as ``unknown`` and never as "not restricted"; so is a
missing nav status for d2.
D4 means the target is not expected to give way: she stands on and own ship gives way.

One assessment runs the automaton from D1 until it reaches a marked state after at least one
transition. A target that need not give way gives the ¬d1 self-loop and the path ``D1>D1``;
the other paths are ``D1>D2>D4``, ``D1>D2>D3>D4`` and ``D1>D2>D3>D1``.

The pair's final roles (``decide_pair``) combine the automaton of both seats (seat A asks
whether B is restricted, seat B whether A is) with rules 13 and 18, so that both seats name
the same give-way vessel(s). This module is the one place that decides them:

1. No situation: no roles.
2. Overtaking: rule 13 keeps the roles whatever either vessel reports or is estimated (rule 18
   opens "except where Rules 9, 10 and 13 otherwise require"); the paths are still recorded.
3. A vessel is restricted when the other seat's G_d reached D4 about her (she had to give way
   and is restricted), or, even as the stand-on vessel, when her AIS status claims it (a status
   in the restricted set, or not under command, restricted, constrained by her draught) or d3
   holds of her (the estimator, or her draught in a channel). Exactly one restricted vessel
   stands on and the other gives way; the deciding rule is 9 when d3 said so (she can navigate
   safely only within the channel), 18 when her AIS status did. With the chart's channels, rule
   9 decides only where a clause binds the other vessel (``rule9_clause``).
4. Both restricted: the rules 13–15 roles stay, flagged ``both_restricted``. Rule 9 asks
   the vessel that can leave the channel to keep out of the way of one that cannot; when
   neither can, it does not choose between them.
5. Otherwise rule 18 where AIS says so: of a vessel not under command or restricted in her
   ability to manoeuvre (status 2, 3), constrained by her draught (4), engaged in fishing (7)
   and sailing (8), ranked in that order of rule 18, the lower-ranked vessel keeps out of the
   way of the higher-ranked one. A missing or other status ranks as a power-driven vessel.
6. Otherwise the roles of rules 14 and 15.

The deciding rule is 13, 14 or 15 wherever rules 9 and 18 leave those roles unchanged.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from enum import Enum, StrEnum

from .colregs import Role, Situation

# What every verdict applies (DESIGN §7, jurisdiction): the international rules, not the
# inland rules some waters have instead.
RULES_APPLIED = (
    "Rules applied: COLREGs 1972 as amended (rules 9, 13-15, 17 and 18, with the rule 9 "
    "framework of Hansen et al., the paper this tool implements), the international rules "
    "for the high seas and waters connected with them. Inland rules are not applied: where "
    "they govern (the US Inland Rules, 33 CFR 83, which differ in rules 9(a)(ii), 14(d) and "
    "15(b); the Kiel Canal; the Rhine; Japan's port rules) read the verdicts against them."
)


@dataclass(frozen=True)
class Rule9Params:
    """What G_d needs beyond the pair (the ``[replay]`` keys of the same names).

    - ``restricted_nav_statuses``: AIS navigational status codes that mean "restricted
      manoeuvrability" for event d2 (3 restricted manoeuvrability, 4 constrained by her
      draught).
    - ``reassess_every_s``: after the trigger, a manoeuvrability estimate (event d3) is made
      again only where G_d reaches D3 and the last one is at least this old (``core/pair.py``).
    """

    restricted_nav_statuses: frozenset[int] = frozenset({3, 4})
    reassess_every_s: float = 10.0


class State(Enum):
    D1 = "D1"
    D2 = "D2"
    D3 = "D3"
    D4 = "D4"


class Event(Enum):
    D1 = "d1"
    NOT_D1 = "not_d1"
    D2 = "d2"
    NOT_D2 = "not_d2"
    D3 = "d3"
    NOT_D3 = "not_d3"


TRANSITIONS: dict[tuple[State, Event], State] = {
    (State.D1, Event.NOT_D1): State.D1,
    (State.D1, Event.D1): State.D2,
    (State.D2, Event.D2): State.D4,
    (State.D2, Event.NOT_D2): State.D3,
    (State.D3, Event.D3): State.D4,
    (State.D3, Event.NOT_D3): State.D1,
}
INITIAL_STATE = State.D1
MARKED_STATES: frozenset[State] = frozenset({State.D1, State.D4})


class UndefinedTransitionError(LookupError):
    """An event with no arrow from the current state: a programming error, not bad input."""


class Finding(StrEnum):
    """What the assessment recorded for an event's condition."""

    TRUE = "true"
    FALSE = "false"
    UNKNOWN = "unknown"
    NOT_EVALUATED = "not-evaluated"  # the path never reached the state that asks


def step(state: State, event: Event) -> State:
    """f_d(state, event); raises ``UndefinedTransitionError`` where the figure has no arrow."""
    try:
        return TRANSITIONS[(state, event)]
    except KeyError:
        raise UndefinedTransitionError(
            f"G_d has no transition from {state.value} on {event.value}"
        ) from None


def run(events: Iterable[Event], start: State = INITIAL_STATE) -> tuple[State, ...]:
    """The path of states visited by ``events`` from ``start`` (start included)."""
    path = [start]
    for event in events:
        path.append(step(path[-1], event))
    return tuple(path)


def accepts(events: Iterable[Event]) -> bool:
    """True when every event has an arrow and the run from D1 ends in a marked state."""
    try:
        return run(events)[-1] in MARKED_STATES
    except UndefinedTransitionError:
        return False


def path_text(path: Iterable[State]) -> str:
    return ">".join(state.value for state in path)


@dataclass(frozen=True)
class Rule9Assessment:
    """One run of G_d in one seat: own ship asks about the target."""

    path: tuple[State, ...]
    events: tuple[Event, ...]
    target_role_colregs: Role
    d1: bool
    d2: Finding
    d3: Finding

    @property
    def path_text(self) -> str:
        return path_text(self.path)

    @property
    def final_state(self) -> State:
        return self.path[-1]

    @property
    def rule9_applied(self) -> bool:
        """D4: the target is not expected to give way."""
        return self.final_state is State.D4


_RESTRICTION_FINDINGS = {"true": Finding.TRUE, "false": Finding.FALSE, "unknown": Finding.UNKNOWN}


def nav_status_finding(nav_status: int | None, restricted_nav_statuses: frozenset[int]) -> Finding:
    """d2's condition: whether an AIS status is in the restricted set (unknown when missing)."""
    if nav_status is None:
        return Finding.UNKNOWN
    return Finding.TRUE if int(nav_status) in restricted_nav_statuses else Finding.FALSE


def assess_rule9(
    target_role: Role,
    target_nav_status: int | None,
    target_restricted: str,
    restricted_nav_statuses: frozenset[int] = frozenset({3, 4}),
) -> Rule9Assessment:
    """Run G_d from D1 to a marked state.

    ``target_role`` is the target's role under rules 13–15 (d1: she gives way).
    ``target_restricted`` is the estimator's verdict, a ``manoeuvrability.Restriction``
    ("true", "false" or "unknown"; a ``StrEnum``, so plain strings work too).
    """
    try:
        d3_finding = _RESTRICTION_FINDINGS[str(target_restricted)]
    except KeyError:
        raise ValueError(
            f"target_restricted must be 'true', 'false' or 'unknown', not {target_restricted!r}"
        ) from None
    d2_finding = nav_status_finding(target_nav_status, restricted_nav_statuses)
    d1 = target_role is Role.GIVE_WAY
    # The event each state generates, from the observations.
    event_at = {
        State.D1: Event.D1 if d1 else Event.NOT_D1,
        State.D2: Event.D2 if d2_finding is Finding.TRUE else Event.NOT_D2,
        State.D3: Event.D3 if d3_finding is Finding.TRUE else Event.NOT_D3,
    }
    path = [INITIAL_STATE]
    events: list[Event] = []
    while len(path) == 1 or path[-1] not in MARKED_STATES:
        events.append(event_at[path[-1]])
        path.append(step(path[-1], events[-1]))
    visited = set(path)
    return Rule9Assessment(
        path=tuple(path),
        events=tuple(events),
        target_role_colregs=target_role,
        d1=d1,
        d2=d2_finding if State.D2 in visited else Finding.NOT_EVALUATED,
        d3=d3_finding if State.D3 in visited else Finding.NOT_EVALUATED,
    )


class DecidingRule(StrEnum):
    """The rule that settled a pair's final roles."""

    RULE_9 = "9"
    RULE_13 = "13"
    RULE_14 = "14"
    RULE_15 = "15"
    RULE_18 = "18"
    NONE = ""


# Rule 18's order of precedence by AIS navigational status; other codes and a missing status
# rank as a power-driven vessel (0). A lower-ranked vessel keeps out of the way.
RULE18_RANK: dict[int, int] = {2: 4, 3: 4, 4: 3, 7: 2, 8: 1}

_STEERING_RULE = {
    Situation.OVERTAKING: DecidingRule.RULE_13,
    Situation.HEAD_ON: DecidingRule.RULE_14,
    Situation.CROSSING: DecidingRule.RULE_15,
    Situation.NONE: DecidingRule.NONE,
}


def rule18_rank(nav_status: int | None) -> int:
    return 0 if nav_status is None else RULE18_RANK.get(int(nav_status), 0)


@dataclass(frozen=True)
class PairVerdict:
    """A pair's final roles, the same from both seats.

    Vessel ``a`` and vessel ``b`` in a fixed order; ``seat_a`` is G_d run by a about b, and
    ``seat_b`` by b about a.
    """

    situation: Situation
    role_colregs: tuple[Role, Role]
    seat_a: Rule9Assessment
    seat_b: Rule9Assessment
    role_final: tuple[Role, Role]
    deciding_rule: DecidingRule
    both_restricted: bool
    # Where d3 found the vessel that rule 9 would make stand on restricted: the
    # clause that binds the other (``rule9_clause``); None where it did not arise.
    rule9_clause: Rule9Clause | None = None

    @property
    def rule9_applied(self) -> bool:
        return self.deciding_rule is DecidingRule.RULE_9

    @property
    def overridden_by_rule13(self) -> bool:
        """G_d reached D4 in an overtaking, where rule 13 keeps the roles."""
        return self.situation is Situation.OVERTAKING and (
            self.seat_a.rule9_applied or self.seat_b.rule9_applied
        )


def decide_pair(
    situation: Situation,
    role_colregs: tuple[Role, Role],
    nav_status: tuple[int | None, int | None],
    estimated_restricted: tuple[str, str],
    restricted_nav_statuses: frozenset[int] = frozenset({3, 4}),
    channels: tuple[ChannelStanding, ChannelStanding] | None = None,
) -> PairVerdict:
    """The final roles of vessels a and b (module docstring), from both seats' G_d.

    Each tuple holds vessel a's value, then vessel b's. ``estimated_restricted`` is each
    vessel's estimator verdict (a ``Restriction`` or its string). ``channels``: where the
    chart charts channels, each vessel's standing in them; rule 9 then decides only where
    a clause binds the other vessel (``rule9_clause``: 9(b), (c) or (d)); without, the
    estimator alone decides, as in the paper.
    """
    role_a, role_b = role_colregs
    # d3 with the chart's channels: the estimator's arcs, or her draught confining her to
    # the channel she proceeds along.
    if channels is not None:
        estimated_restricted = (
            "true" if channels[0].confined_to_channel else estimated_restricted[0],
            "true" if channels[1].confined_to_channel else estimated_restricted[1],
        )
    seat_a = assess_rule9(role_b, nav_status[1], estimated_restricted[1], restricted_nav_statuses)
    seat_b = assess_rule9(role_a, nav_status[0], estimated_restricted[0], restricted_nav_statuses)
    # A vessel is restricted when G_d reached D4 about her, or when her AIS status or the
    # estimator says so even as the stand-on vessel: then the other, restricted too, cannot
    # be made to stand on by rule 9.
    restricted = tuple(
        seat.rule9_applied
        or _claims_restriction(status, restricted_nav_statuses)
        or str(estimate) == "true"
        for seat, status, estimate in zip(
            (seat_b, seat_a), nav_status, estimated_restricted, strict=True
        )
    )
    final = role_colregs
    rule = _STEERING_RULE[situation]
    clause: Rule9Clause | None = None
    if situation not in (Situation.NONE, Situation.OVERTAKING):
        if restricted[0] != restricted[1]:
            about_restricted = seat_b if restricted[0] else seat_a
            by_restriction = (
                (Role.STAND_ON, Role.GIVE_WAY) if restricted[0] else (Role.GIVE_WAY, Role.STAND_ON)
            )
            by_d3 = about_restricted.d3 is Finding.TRUE
            if by_restriction != final and by_d3:
                which = 0 if restricted[0] else 1
                clause = (
                    Rule9Clause.ESTIMATOR
                    if channels is None
                    else rule9_clause(channels[which], channels[1 - which])
                )
            binds = channels is None or clause not in (Rule9Clause.ESTIMATOR, Rule9Clause.NO_CLAUSE)
            if by_restriction != final and (binds or not by_d3):
                final = by_restriction
                rule = DecidingRule.RULE_9 if by_d3 else DecidingRule.RULE_18
        elif not restricted[0]:
            rank_a, rank_b = rule18_rank(nav_status[0]), rule18_rank(nav_status[1])
            by_rank = (
                (Role.STAND_ON, Role.GIVE_WAY)
                if rank_a > rank_b
                else (Role.GIVE_WAY, Role.STAND_ON)
            )
            if rank_a != rank_b and by_rank != final:
                final, rule = by_rank, DecidingRule.RULE_18
    return PairVerdict(
        situation=situation,
        role_colregs=role_colregs,
        seat_a=seat_a,
        seat_b=seat_b,
        role_final=final,
        deciding_rule=rule,
        both_restricted=situation is not Situation.NONE and all(restricted),
        rule9_clause=clause,
    )


def _claims_restriction(nav_status: int | None, restricted_nav_statuses: frozenset[int]) -> bool:
    return nav_status is not None and (
        int(nav_status) in restricted_nav_statuses or rule18_rank(nav_status) >= RULE18_RANK[4]
    )


# Rule 9(b): "a vessel of less than 20 metres in length or a sailing vessel".
RULE_9B_LENGTH_M = 20.0


class Rule9Clause(StrEnum):
    """Which clause of rule 9 bears out an inversion by rule 9 where the chart is known
    (``rule9_clause``)."""

    SMALL_OR_SAILING = "9(b)"  # under 20 m or sailing: shall not impede
    FISHING = "9(c)"  # engaged in fishing: shall not impede
    CROSSING = "9(d)"  # shall not cross a channel if that impedes
    ESTIMATOR = "estimator"  # in no charted channel: the paper's estimator alone
    NO_CLAUSE = "none"  # in a charted channel, but none of 9(b)-(d) binds the other vessel


@dataclass(frozen=True)
class ChannelStanding:
    """What the clauses of rule 9 read about one vessel: whether she proceeds along a
    charted channel, crosses one, is under 20 m or a sailing vessel, is fishing, or can
    safely navigate only within the channel she proceeds along, her draught confining her."""

    along_channel: bool
    crossing_channel: bool
    small_or_sailing: bool
    fishing: bool
    # Along a charted channel, and the water navigable for her draught ends within her
    # length of its limits on both hands, in a channel narrow for her
    # (``confinement.confined_to_channel``).
    confined_to_channel: bool = False


def rule9_clause(restricted: ChannelStanding, other: ChannelStanding) -> Rule9Clause:
    """The clause of rule 9 under which ``other`` keeps out of the way of ``restricted``, the
    vessel rule 9 made stand on (d3: the estimator, or her draught in the channel, found that
    she can safely navigate only within the channel): 9(d) when the other crosses the channel,
    9(b) when she is under 20 m or sailing, 9(c) when she is fishing; ``none`` when the
    restricted vessel proceeds along a charted channel and none of these binds the other (two
    ships along it: rule 9 then asks each to keep to her starboard side, 9(a), and does not
    invert rules 13-15; the paper's estimator did); ``estimator`` where no charted channel holds
    her."""
    if not restricted.along_channel:
        return Rule9Clause.ESTIMATOR
    if other.crossing_channel:
        return Rule9Clause.CROSSING
    if other.small_or_sailing:
        return Rule9Clause.SMALL_OR_SAILING
    if other.fishing:
        return Rule9Clause.FISHING
    return Rule9Clause.NO_CLAUSE
