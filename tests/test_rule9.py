"""The rule 9 assessment automaton G_d, checked against the paper's figure (automaton_A)."""

from __future__ import annotations

import itertools
import re
from collections import deque

import pytest
from hypothesis import given
from hypothesis import strategies as st

from colregs9_cli.colregs import Role
from colregs9_cli.rule9 import (
    INITIAL_STATE,
    MARKED_STATES,
    TRANSITIONS,
    Event,
    Finding,
    State,
    UndefinedTransitionError,
    accepts,
    assess_rule9,
    path_text,
    run,
    step,
)

D1, D2, D3, D4 = State.D1, State.D2, State.D3, State.D4

# The six arrows of the figure, read off tikz/automaton_A.tex in ../shared/paper.tex.
FIGURE_ARROWS = [
    (D1, Event.NOT_D1, D1),  # loop left, ¬d1
    (D1, Event.D1, D2),
    (D2, Event.D2, D4),
    (D2, Event.NOT_D2, D3),
    (D3, Event.D3, D4),
    (D3, Event.NOT_D3, D1),
]


@pytest.mark.parametrize(("state", "event", "target"), FIGURE_ARROWS)
def test_every_transition_of_the_figure(state: State, event: Event, target: State) -> None:
    assert step(state, event) is target


def test_the_table_has_exactly_the_figure_arrows() -> None:
    assert {(s, e): t for s, e, t in FIGURE_ARROWS} == TRANSITIONS
    assert INITIAL_STATE is D1
    assert {D1, D4} == MARKED_STATES


UNDEFINED = [
    (s, e) for s in State for e in Event if (s, e) not in {(a, b) for a, b, _ in FIGURE_ARROWS}
]


@pytest.mark.parametrize(("state", "event"), UNDEFINED)
def test_every_undefined_transition_raises(state: State, event: Event) -> None:
    with pytest.raises(UndefinedTransitionError, match=f"from {state.value} on {event.value}"):
        step(state, event)


def test_undefined_transitions_are_the_rest_of_the_product() -> None:
    assert len(UNDEFINED) == len(State) * len(Event) - 6 == 18
    assert all((D4, e) in UNDEFINED for e in Event)  # D4 ends the assessment


def test_non_blocking_every_reachable_state_can_reach_a_marked_state() -> None:
    # The paper: {D1, D4} are co-accessible from every non-marked state.
    successors: dict[State, set[State]] = {s: set() for s in State}
    for (source, _), target in TRANSITIONS.items():
        successors[source].add(target)
    for start in State:
        seen, queue = {start}, deque([start])
        while queue:
            for nxt in successors[queue.popleft()]:
                if nxt not in seen:
                    seen.add(nxt)
                    queue.append(nxt)
        assert seen & MARKED_STATES, start


# The marked language of G_d written independently as a regular expression over one letter
# per event: a loop of ¬d1 or d1 ¬d2 ¬d3 back to D1, optionally ended by a path into D4.
LETTER = {
    Event.NOT_D1: "a",
    Event.D1: "b",
    Event.D2: "c",
    Event.NOT_D2: "d",
    Event.D3: "e",
    Event.NOT_D3: "f",
}
MARKED_LANGUAGE = re.compile(r"(?:a|bdf)*(?:bc|bde)?")


def well_formed(events: tuple[Event, ...]) -> bool:
    return MARKED_LANGUAGE.fullmatch("".join(LETTER[e] for e in events)) is not None


def test_exhaustive_short_sequences() -> None:
    checked = 0
    for length in range(7):
        for events in itertools.product(Event, repeat=length):
            try:
                path = run(events)
            except UndefinedTransitionError:
                assert not well_formed(events)
                assert not accepts(events)
            else:
                assert len(path) == length + 1
                assert all(isinstance(state, State) for state in path)
                assert accepts(events) is (path[-1] in MARKED_STATES)
            assert accepts(events) is well_formed(events)
            checked += 1
    assert checked == sum(6**n for n in range(7))


@given(st.lists(st.sampled_from(list(Event)), max_size=40))
def test_any_event_sequence_is_accepted_only_when_well_formed(events: list[Event]) -> None:
    assert accepts(events) is well_formed(tuple(events))


@given(st.lists(st.sampled_from(["loop", "restricted_ais", "restricted_estimate", "clear"])))
def test_generated_well_formed_sequences_run_to_a_marked_state(rounds: list[str]) -> None:
    words = {
        "loop": [Event.NOT_D1],
        "clear": [Event.D1, Event.NOT_D2, Event.NOT_D3],
        "restricted_ais": [Event.D1, Event.D2],
        "restricted_estimate": [Event.D1, Event.NOT_D2, Event.D3],
    }
    # Only the last round may enter D4, which has no way out.
    events = [e for word in rounds for e in words[word] if word in ("loop", "clear")]
    if rounds and rounds[-1] in ("restricted_ais", "restricted_estimate"):
        events += words[rounds[-1]]
    path = run(events)
    assert path[-1] in MARKED_STATES
    assert accepts(events)


def test_path_text() -> None:
    assert path_text([D1, D2, D3, D4]) == "D1>D2>D3>D4"
    assert path_text(run([Event.D1, Event.NOT_D2, Event.NOT_D3])) == "D1>D2>D3>D1"


# (own role, nav status, estimator, path, rule 9 applied, final own role, d2, d3)
ASSESSMENTS = [
    (Role.GIVE_WAY, 3, "true", "D1>D1", False, Role.GIVE_WAY, "not-evaluated", "not-evaluated"),
    (Role.NONE, 0, "unknown", "D1>D1", False, Role.NONE, "not-evaluated", "not-evaluated"),
    (Role.STAND_ON, 3, "false", "D1>D2>D4", True, Role.GIVE_WAY, "true", "not-evaluated"),
    (Role.STAND_ON, 4, "unknown", "D1>D2>D4", True, Role.GIVE_WAY, "true", "not-evaluated"),
    (Role.STAND_ON, 0, "true", "D1>D2>D3>D4", True, Role.GIVE_WAY, "false", "true"),
    (Role.STAND_ON, 0, "false", "D1>D2>D3>D1", False, Role.STAND_ON, "false", "false"),
    (Role.STAND_ON, 0, "unknown", "D1>D2>D3>D1", False, Role.STAND_ON, "false", "unknown"),
    (Role.STAND_ON, None, "true", "D1>D2>D3>D4", True, Role.GIVE_WAY, "unknown", "true"),
    (Role.STAND_ON, None, "unknown", "D1>D2>D3>D1", False, Role.STAND_ON, "unknown", "unknown"),
    (Role.STAND_ON, 7, "false", "D1>D2>D3>D1", False, Role.STAND_ON, "false", "false"),
]


@pytest.mark.parametrize(
    ("own_role", "nav_status", "estimate", "path", "applied", "final_role", "d2", "d3"),
    ASSESSMENTS,
)
def test_assessments(
    own_role: Role,
    nav_status: int | None,
    estimate: str,
    path: str,
    applied: bool,
    final_role: Role,
    d2: str,
    d3: str,
) -> None:
    result = assess_rule9(own_role, nav_status, estimate)
    assert result.path_text == path
    assert result.rule9_applied is applied
    assert result.own_role_colregs is own_role
    assert result.own_role_final is final_role
    assert result.d1 is (own_role is Role.STAND_ON)
    assert result.d2 == Finding(d2)
    assert result.d3 == Finding(d3)
    assert run(result.events) == result.path
    assert result.final_state is result.path[-1]


def test_unknown_estimate_is_recorded_as_unknown_never_as_not_restricted() -> None:
    result = assess_rule9(Role.STAND_ON, 0, "unknown")
    assert result.events[-1] is Event.NOT_D3
    assert result.d3 is Finding.UNKNOWN
    assert result.d3 != Finding.FALSE


def test_restricted_status_set_is_configurable() -> None:
    fishing = frozenset({7})
    assert assess_rule9(Role.STAND_ON, 7, "false", fishing).path_text == "D1>D2>D4"
    assert assess_rule9(Role.STAND_ON, 3, "false", fishing).path_text == "D1>D2>D3>D1"


@pytest.mark.parametrize("own_role", list(Role))
@pytest.mark.parametrize("nav_status", [None, *range(16)])
@pytest.mark.parametrize("estimate", ["true", "false", "unknown"])
def test_every_assessment_ends_in_a_marked_state_after_a_transition(
    own_role: Role, nav_status: int | None, estimate: str
) -> None:
    result = assess_rule9(own_role, nav_status, estimate)
    assert result.path[0] is D1
    assert len(result.path) >= 2
    assert result.final_state in MARKED_STATES
    assert all(state not in MARKED_STATES for state in result.path[1:-1])
    # D4 inverts the role; every other end keeps it.
    expected = own_role.inverted() if result.rule9_applied else own_role
    assert result.own_role_final is expected
    if result.rule9_applied:
        assert (own_role, result.own_role_final) == (Role.STAND_ON, Role.GIVE_WAY)


def test_estimator_value_must_be_a_restriction() -> None:
    with pytest.raises(ValueError, match="'maybe'"):
        assess_rule9(Role.STAND_ON, 0, "maybe")
