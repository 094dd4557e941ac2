"""The rule 9 assessment automaton G_d, checked against the paper's figure (automaton_A)."""

from __future__ import annotations

import itertools
import re
from collections import deque

import pytest
from hypothesis import given
from hypothesis import strategies as st

from colregs9_cli.core.colregs import Role, Situation
from colregs9_cli.core.rule9 import (
    INITIAL_STATE,
    MARKED_STATES,
    TRANSITIONS,
    DecidingRule,
    Event,
    Finding,
    State,
    UndefinedTransitionError,
    accepts,
    assess_rule9,
    decide_pair,
    path_text,
    run,
    step,
)

from seat_checks import swapped

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


# (target's role under rules 13–15, her nav status, estimator, path, D4 reached, d2, d3)
ASSESSMENTS = [
    (Role.STAND_ON, 3, "true", "D1>D1", False, "not-evaluated", "not-evaluated"),
    (Role.NONE, 0, "unknown", "D1>D1", False, "not-evaluated", "not-evaluated"),
    (Role.GIVE_WAY, 3, "false", "D1>D2>D4", True, "true", "not-evaluated"),
    (Role.GIVE_WAY, 4, "unknown", "D1>D2>D4", True, "true", "not-evaluated"),
    (Role.GIVE_WAY, 0, "true", "D1>D2>D3>D4", True, "false", "true"),
    (Role.GIVE_WAY, 0, "false", "D1>D2>D3>D1", False, "false", "false"),
    (Role.GIVE_WAY, 0, "unknown", "D1>D2>D3>D1", False, "false", "unknown"),
    (Role.GIVE_WAY, None, "true", "D1>D2>D3>D4", True, "unknown", "true"),
    (Role.GIVE_WAY, None, "unknown", "D1>D2>D3>D1", False, "unknown", "unknown"),
    (Role.GIVE_WAY, 7, "false", "D1>D2>D3>D1", False, "false", "false"),
]


@pytest.mark.parametrize(
    ("target_role", "nav_status", "estimate", "path", "applied", "d2", "d3"), ASSESSMENTS
)
def test_assessments(
    target_role: Role,
    nav_status: int | None,
    estimate: str,
    path: str,
    applied: bool,
    d2: str,
    d3: str,
) -> None:
    result = assess_rule9(target_role, nav_status, estimate)
    assert result.path_text == path
    assert result.rule9_applied is applied
    assert result.target_role_colregs is target_role
    assert result.d1 is (target_role is Role.GIVE_WAY)
    assert result.d2 == Finding(d2)
    assert result.d3 == Finding(d3)
    assert run(result.events) == result.path
    assert result.final_state is result.path[-1]


def test_unknown_estimate_is_recorded_as_unknown_never_as_not_restricted() -> None:
    result = assess_rule9(Role.GIVE_WAY, 0, "unknown")
    assert result.events[-1] is Event.NOT_D3
    assert result.d3 is Finding.UNKNOWN
    assert result.d3 != Finding.FALSE


def test_restricted_status_set_is_configurable() -> None:
    fishing = frozenset({7})
    assert assess_rule9(Role.GIVE_WAY, 7, "false", fishing).path_text == "D1>D2>D4"
    assert assess_rule9(Role.GIVE_WAY, 3, "false", fishing).path_text == "D1>D2>D3>D1"


@pytest.mark.parametrize("target_role", list(Role))
@pytest.mark.parametrize("nav_status", [None, *range(16)])
@pytest.mark.parametrize("estimate", ["true", "false", "unknown"])
def test_every_assessment_ends_in_a_marked_state_after_a_transition(
    target_role: Role, nav_status: int | None, estimate: str
) -> None:
    result = assess_rule9(target_role, nav_status, estimate)
    assert result.path[0] is D1
    assert len(result.path) >= 2
    assert result.final_state in MARKED_STATES
    assert all(state not in MARKED_STATES for state in result.path[1:-1])
    # D4 only for a target that had to give way (d1), as in the paper
    if result.rule9_applied:
        assert target_role is Role.GIVE_WAY


def test_estimator_value_must_be_a_restriction() -> None:
    with pytest.raises(ValueError, match="'maybe'"):
        assess_rule9(Role.GIVE_WAY, 0, "maybe")


# --- the pair's final roles --------------------------------------------------------------

HO, CR, OT, NS = Situation.HEAD_ON, Situation.CROSSING, Situation.OVERTAKING, Situation.NONE
GW, SO, NO = Role.GIVE_WAY, Role.STAND_ON, Role.NONE
R9, R13, R14, R15, R18 = (
    DecidingRule.RULE_9,
    DecidingRule.RULE_13,
    DecidingRule.RULE_14,
    DecidingRule.RULE_15,
    DecidingRule.RULE_18,
)

# (situation, roles a/b, nav a/b, estimate a/b, final a/b, rule, both restricted)
PAIR_CASES = [
    # the paper's crossing: b gives way, is estimated restricted → she stands on (rule 9)
    (CR, (SO, GW), (0, 0), ("false", "true"), (GW, SO), R9, False),
    (CR, (SO, GW), (0, 0), ("false", "false"), (SO, GW), R15, False),
    # the same from a restricted stand-on vessel: nothing to invert
    (CR, (SO, GW), (0, 0), ("true", "false"), (SO, GW), R15, False),
    # both estimated restricted: rule 9 does not choose between them, rule 15 stays
    (CR, (SO, GW), (0, 0), ("true", "true"), (SO, GW), R15, True),
    # b reports restricted manoeuvrability (D1>D2>D4 in a's seat): rule 18
    (CR, (SO, GW), (0, 3), ("false", "false"), (GW, SO), R18, False),
    # head-on, b restricted: she is not expected to give way (rule 18 / rule 9)
    (HO, (GW, GW), (0, 3), ("unknown", "unknown"), (GW, SO), R18, False),
    (HO, (GW, GW), (0, 0), ("unknown", "true"), (GW, SO), R9, False),
    # head-on, both restricted: rule 14 stays, flagged
    (HO, (GW, GW), (3, 0), ("false", "true"), (GW, GW), R14, True),
    # port to port, each stand-on... the crossing b gives way, reports 3; a reports 3 too
    (CR, (SO, GW), (3, 3), ("false", "false"), (SO, GW), R15, True),
    # a estimated restricted as give-way, b reports 3 as stand-on: both restricted
    (CR, (GW, SO), (0, 3), ("true", "false"), (GW, SO), R15, True),
    # overtaking: rule 13 whatever the status or estimate
    (OT, (GW, SO), (3, 0), ("true", "false"), (GW, SO), R13, False),
    (OT, (SO, GW), (0, 0), ("false", "true"), (SO, GW), R13, False),
    # rule 18 where AIS says so: a fishing vessel gives way to nobody but NUC/RAM/CBD
    (CR, (GW, SO), (7, 0), ("false", "false"), (SO, GW), R18, False),
    (CR, (SO, GW), (7, 0), ("false", "false"), (SO, GW), R15, False),
    (CR, (GW, SO), (8, 7), ("false", "false"), (GW, SO), R15, False),  # sailing < fishing
    (CR, (SO, GW), (8, 7), ("false", "false"), (GW, SO), R18, False),
    (HO, (GW, GW), (0, 8), ("false", "false"), (GW, SO), R18, False),
    (HO, (GW, GW), (None, None), ("unknown", "unknown"), (GW, GW), R14, False),
    # not under command (2) is not in the d2 set by default, yet rule 18 applies
    (CR, (GW, SO), (2, 0), ("false", "false"), (SO, GW), R18, False),
    (NS, (NO, NO), (3, 0), ("true", "true"), (NO, NO), DecidingRule.NONE, False),
]


@pytest.mark.parametrize(
    ("situation", "roles", "nav", "estimates", "final", "rule", "both"), PAIR_CASES
)
def test_pair_final_roles_are_the_same_from_both_seats(
    situation: Situation,
    roles: tuple[Role, Role],
    nav: tuple[int | None, int | None],
    estimates: tuple[str, str],
    final: tuple[Role, Role],
    rule: DecidingRule,
    both: bool,
) -> None:
    verdict = decide_pair(situation, roles, nav, estimates)
    assert verdict.role_final == final
    assert verdict.deciding_rule is rule
    assert verdict.both_restricted is both
    mirrored = decide_pair(situation, roles[::-1], nav[::-1], estimates[::-1])
    assert mirrored == swapped(verdict)
    assert mirrored.role_final == final[::-1]


ROLE_PAIRS = {HO: (GW, GW), CR: (SO, GW), OT: (GW, SO), NS: (NO, NO)}


@given(
    st.sampled_from([HO, CR, OT, NS]),
    st.booleans(),
    st.sampled_from([None, *range(16)]),
    st.sampled_from([None, *range(16)]),
    st.sampled_from(["true", "false", "unknown"]),
    st.sampled_from(["true", "false", "unknown"]),
)
def test_every_pair_verdict_is_consistent(
    situation: Situation,
    swap: bool,
    nav_a: int | None,
    nav_b: int | None,
    estimate_a: str,
    estimate_b: str,
) -> None:
    roles = ROLE_PAIRS[situation][::-1] if swap else ROLE_PAIRS[situation]
    verdict = decide_pair(situation, roles, (nav_a, nav_b), (estimate_a, estimate_b))
    give_way = verdict.role_final.count(GW)
    if situation is NS:
        assert verdict.role_final == (NO, NO)
    elif situation is HO:
        assert give_way in (1, 2)
        assert give_way == 2 or verdict.deciding_rule in (R9, R18)
    else:
        assert give_way == 1  # a crossing or overtaking never ends with both or neither
    if situation is OT:
        assert verdict.role_final == roles and verdict.deciding_rule is R13
    assert verdict.rule9_applied is (verdict.deciding_rule is R9)
    mirrored = decide_pair(situation, roles[::-1], (nav_b, nav_a), (estimate_b, estimate_a))
    assert mirrored == swapped(verdict)


# -- which clause of rule 9, with the chart's channels --------------------------------------


_NAMES = (
    "along_channel",
    "crossing_channel",
    "small_or_sailing",
    "fishing",
    "confined_to_channel",
)


def _standing(**flags: bool):
    from colregs9_cli.core.rule9 import ChannelStanding

    values = dict.fromkeys(_NAMES, False)
    return ChannelStanding(**{**values, **flags})


@pytest.mark.parametrize(
    ("restricted", "other", "clause"),
    [
        # a deep-draught ship along the channel; a yacht crossing it: 9(d) before 9(b)
        ({"along_channel": True}, {"crossing_channel": True, "small_or_sailing": True}, "9(d)"),
        ({"along_channel": True}, {"small_or_sailing": True}, "9(b)"),
        ({"along_channel": True}, {"fishing": True}, "9(c)"),
        # two ships along the channel: 9(b)-(d) do not invert rules 13-15
        ({"along_channel": True}, {"along_channel": True}, "none"),
        # no charted channel where she is: the estimator alone, as in the paper
        ({}, {"small_or_sailing": True}, "estimator"),
        ({"crossing_channel": True}, {"along_channel": True}, "estimator"),
    ],
)
def test_the_clause_of_rule_9_that_binds_the_other_vessel(restricted, other, clause) -> None:
    from colregs9_cli.core.rule9 import rule9_clause

    assert rule9_clause(_standing(**restricted), _standing(**other)).value == clause


def test_sandiego_rule_9_binds_no_one_outside_a_charted_channel(sandiego_replay) -> None:
    # SHELTER ISLAND, a 9 m yacht the estimator finds restricted by shoals outside any
    # charted channel, meets WHITE NIGHTS proceeding along the main channel end on (read at
    # her report at 00:10:13): rule 9 is about narrow channels, so with the chart's channels
    # known it does not make WHITE NIGHTS give way to her alone; rule 14 has both give way.
    summaries = [p.summary for p in sandiego_replay.pairs]
    assert not any(s.rule9_applied for s in summaries)
    (s,) = [s for s in summaries if s.rule9_clause is not None]
    assert (s.name_a, s.name_b) == ("SHELTER ISLAND", "WHITE NIGHTS")
    assert s.rule9_clause.value == "estimator" and s.deciding_rule.value == "14"
    assert s.estimated_restricted_a.value == "true" and s.channel_a is None
    assert s.channel_relation_b.value == "along"
    assert (s.role_final_a.value, s.role_final_b.value) == ("give-way", "give-way")


@pytest.mark.parametrize(
    ("other", "inverted", "clause"),
    [
        ({"small_or_sailing": True}, True, "9(b)"),
        ({"crossing_channel": True}, True, "9(d)"),
        ({"along_channel": True}, False, "none"),
    ],
)
def test_with_the_channels_known_rule_9_inverts_only_where_a_clause_binds(
    other, inverted, clause
) -> None:
    # A crossing: vessel a gives way under rule 15; b, along a channel, is found restricted.
    roles = (Role.GIVE_WAY, Role.STAND_ON)
    flipped = (Role.STAND_ON, Role.GIVE_WAY)
    # a stands on under rule 15 here, b would give way; b's estimate says restricted
    verdict = decide_pair(
        Situation.CROSSING,
        flipped,
        (None, None),
        ("false", "true"),
        channels=(_standing(**other), _standing(along_channel=True)),
    )
    assert verdict.rule9_clause.value == clause
    assert verdict.rule9_applied is inverted
    assert verdict.role_final == (roles if inverted else flipped)
    # Without channels charted: the paper's estimator alone inverts.
    paper = decide_pair(Situation.CROSSING, flipped, (None, None), ("false", "true"))
    assert paper.rule9_applied and paper.rule9_clause.value == "estimator"


@pytest.mark.parametrize("estimate", ["false", "unknown"])
def test_a_vessel_her_draught_confines_to_the_channel_is_restricted_for_d3(estimate) -> None:
    # A crossing in which b gives way under rule 15, but b proceeds along a channel her
    # draught confines her to; a, a yacht under 20 m, shall not impede her (9(b)). The
    # estimator's own verdict about b does not matter: d3 holds by the chart.
    flipped = (Role.STAND_ON, Role.GIVE_WAY)
    confined = _standing(along_channel=True, confined_to_channel=True)
    verdict = decide_pair(
        Situation.CROSSING,
        flipped,
        (None, None),
        ("false", estimate),
        channels=(_standing(small_or_sailing=True), confined),
    )
    assert verdict.seat_a.path_text == "D1>D2>D3>D4" and verdict.seat_a.d3 is Finding.TRUE
    assert verdict.rule9_applied and verdict.rule9_clause.value == "9(b)"
    assert verdict.role_final == (Role.GIVE_WAY, Role.STAND_ON)
    # Along the channel but with room outside it: the estimator's verdict stands alone.
    free = decide_pair(
        Situation.CROSSING,
        flipped,
        (None, None),
        ("false", estimate),
        channels=(_standing(small_or_sailing=True), _standing(along_channel=True)),
    )
    assert not free.rule9_applied and free.role_final == flipped
    assert free.seat_a.path_text == "D1>D2>D3>D1"
    # Two vessels along the channel, both confined: rule 9 does not choose between them.
    both = decide_pair(
        Situation.HEAD_ON,
        (Role.GIVE_WAY, Role.GIVE_WAY),
        (None, None),
        ("false", "false"),
        channels=(confined, confined),
    )
    assert both.both_restricted and not both.rule9_applied


_STANDINGS = st.builds(
    lambda *flags: _standing(**dict(zip(_NAMES, flags, strict=True))),
    *(st.booleans() for _ in _NAMES),
)


@given(
    st.sampled_from([HO, CR, OT, NS]),
    st.booleans(),
    st.sampled_from([None, 0, 3, 4, 7, 8]),
    st.sampled_from([None, 0, 3, 4, 7, 8]),
    st.sampled_from(["true", "false", "unknown"]),
    st.sampled_from(["true", "false", "unknown"]),
    _STANDINGS,
    _STANDINGS,
)
def test_with_channels_the_verdict_is_the_same_from_both_seats(
    situation, flip, nav_a, nav_b, est_a, est_b, standing_a, standing_b
) -> None:
    roles = ROLE_PAIRS[situation] if not flip else ROLE_PAIRS[situation][::-1]
    verdict = decide_pair(
        situation, roles, (nav_a, nav_b), (est_a, est_b), channels=(standing_a, standing_b)
    )
    mirrored = decide_pair(
        situation,
        roles[::-1],
        (nav_b, nav_a),
        (est_b, est_a),
        channels=(standing_b, standing_a),
    )
    assert mirrored == swapped(verdict)
    # rule 9 decides only where a clause binds the other vessel
    if verdict.rule9_applied:
        assert verdict.rule9_clause.value in ("9(b)", "9(c)", "9(d)")
