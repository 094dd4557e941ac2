"""The COLREGs rule 9 assessment automaton G_d (paper, Fig. "automaton_A"; DESIGN §5).

G_d = (D, E_d, f_d, D1, {D1, D4}) with

    D1  check whether the target needs to give way        (initial, marked)
    D2  check whether the target reports restricted manoeuvrability
    D3  evaluate the target's manoeuvrability
    D4  apply rule 9: invert give-way/stand-on             (marked)

and the transition function ``TRANSITIONS`` (exactly the figure's six arrows):

    D1 –¬d1→ D1    D1 –d1→ D2
    D2 –d2→  D4    D2 –¬d2→ D3
    D3 –d3→  D4    D3 –¬d3→ D1

Events: d1 the target needs to give way (own ship's COLREGs role is stand-on); d2 the target's
AIS navigational status is in the restricted set (``ReplayParams.restricted_nav_statuses``,
the ``[replay]`` table; default {3, 4}); d3 the manoeuvrability estimator says the target is
restricted. The estimator's "unknown" is ¬d3, recorded as ``unknown`` and never as "not
restricted"; so is a missing nav status for d2.

One assessment runs the automaton from D1 until it reaches a marked state after at least one
transition. Own ship not stand-on gives the ¬d1 self-loop and the path ``D1>D1``; the other
paths are ``D1>D2>D4``, ``D1>D2>D3>D4`` and ``D1>D2>D3>D1``.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from enum import Enum, StrEnum

from .colregs import Role


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
    """One run of G_d for an own ship / target pair at one step."""

    path: tuple[State, ...]
    events: tuple[Event, ...]
    own_role_colregs: Role
    own_role_final: Role
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
        return self.final_state is State.D4


_RESTRICTION_FINDINGS = {"true": Finding.TRUE, "false": Finding.FALSE, "unknown": Finding.UNKNOWN}


def assess_rule9(
    own_role: Role,
    target_nav_status: int | None,
    target_restricted: str,
    restricted_nav_statuses: frozenset[int] = frozenset({3, 4}),
) -> Rule9Assessment:
    """Run G_d from D1 to a marked state.

    ``target_restricted`` is the estimator's verdict, a
    ``manoeuvrability.Restriction`` ("true", "false" or "unknown"; a ``StrEnum``, so plain
    strings work too). D4 inverts own ship's role (stand-on becomes give-way).
    """
    try:
        d3_finding = _RESTRICTION_FINDINGS[str(target_restricted)]
    except KeyError:
        raise ValueError(
            f"target_restricted must be 'true', 'false' or 'unknown', not {target_restricted!r}"
        ) from None
    d2_finding = (
        Finding.UNKNOWN
        if target_nav_status is None
        else Finding.TRUE
        if int(target_nav_status) in restricted_nav_statuses
        else Finding.FALSE
    )
    d1 = own_role is Role.STAND_ON
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
    final = path[-1]
    return Rule9Assessment(
        path=tuple(path),
        events=tuple(events),
        own_role_colregs=own_role,
        own_role_final=own_role.inverted() if final is State.D4 else own_role,
        d1=d1,
        d2=d2_finding if State.D2 in visited else Finding.NOT_EVALUATED,
        d3=d3_finding if State.D3 in visited else Finding.NOT_EVALUATED,
    )
