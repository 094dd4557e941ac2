"""AIS claims a vessel's own data can refute: her navigational status (``ais_claims``)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from colregs9_cli.core.ais_claims import (
    NavStatus,
    NavStatusBelief,
    NavStatusParams,
    nav_status_belief,
)

# The category texts of ais.clean.SHIP_TYPE_CATEGORIES (core may not import ais).
SHIP_TYPES = (
    "Reserved",
    "WIG",
    "Fishing",
    "Towing",
    "Towing long/wide",
    "Dredging",
    "Diving",
    "Military",
    "Sailing",
    "Pleasure",
    "HSC",
    "Pilot",
    "SAR",
    "Tug",
    "Port tender",
    "Anti-pollution",
    "Law enforcement",
    "Spare 1",
    "Spare 2",
    "Medical",
    "Not party to conflict",
    "Passenger",
    "Cargo",
    "Tanker",
    "Other",
)
UNKNOWN_TYPES = (None, math.nan, "", "  ", "Reserved", "Spare 1", "spare 2")


def test_the_ship_types_are_those_the_cleaner_writes() -> None:
    from colregs9_cli.ais.clean import SHIP_TYPE_CATEGORIES

    assert set(SHIP_TYPES) == set(SHIP_TYPE_CATEGORIES.values())


def belief(status, ship_type=None, length_m=None, draught_m=None) -> NavStatusBelief:
    return nav_status_belief(status, ship_type, length_m, draught_m)


# -- 8 under way sailing ---------------------------------------------------------------------


@pytest.mark.parametrize(
    ("ship_type", "length_m"), [("Tug", 28.0), ("Towing", 20.0), ("Passenger", 301.0)]
)
def test_sailing_on_a_tug_a_towboat_or_a_cruise_ship_is_refuted(ship_type, length_m) -> None:
    """The issue's three: rule 18 decided four pairs by them."""
    said = belief(8, ship_type, length_m)
    assert not said.believed
    assert said.reason == (
        f"status 8 (under way sailing) on a vessel of type {ship_type}: "
        "only sailing craft and yachts sail"
    )


@pytest.mark.parametrize("ship_type", ["Sailing", "Pleasure", "SAILING", " pleasure "])
def test_sailing_on_sailing_craft_and_yachts_is_believed(ship_type) -> None:
    said = belief(8, ship_type, 12.0)
    assert said.believed
    assert said.reason == f"status 8 (under way sailing) on a vessel of type {ship_type}"


@pytest.mark.parametrize("ship_type", UNKNOWN_TYPES)
def test_sailing_on_a_vessel_of_unknown_type_is_believed(ship_type) -> None:
    said = belief(8, ship_type, 301.0)
    assert said.believed
    assert said.reason == (
        "status 8 (under way sailing) on a vessel of unknown type: nothing refutes it"
    )


@pytest.mark.parametrize("ship_type", ["Cargo", "Tanker", "Fishing", "HSC", "Other", "Military"])
def test_sailing_on_any_other_type_is_refuted(ship_type) -> None:
    assert not belief(8, ship_type).believed


# -- 4 constrained by her draught ------------------------------------------------------------


def test_constrained_by_draught_on_a_16_m_towboat_is_refuted() -> None:
    """The issue's towboat, with her AIS draught and without one."""
    drawing = belief(4, "Towing", 16.0, 2.7)
    assert not drawing.believed
    assert drawing.reason == (
        "status 4 (constrained by her draught) on a vessel drawing 2.7 m, less than 4.6 m"
    )
    undrawn = belief(4, "Towing", 16.0, None)
    assert not undrawn.believed
    assert undrawn.reason == (
        "status 4 (constrained by her draught) on a vessel of 16 m with no draught, "
        "shorter than 72 m"
    )


def test_constrained_by_draught_on_a_deep_draught_vessel_is_believed() -> None:
    said = belief(4, "Tanker", 250.0, 14.5)
    assert said.believed
    assert said.reason == (
        "status 4 (constrained by her draught) on a vessel drawing 14.5 m, at least 4.6 m"
    )


def test_constrained_by_draught_at_the_thresholds() -> None:
    assert belief(4, "Cargo", 90.0, 4.6).believed
    assert not belief(4, "Tug", 30.0, 4.5).believed  # the table's harbour tug
    # The draught decides when it is known: a long vessel drawing little is not constrained.
    assert not belief(4, "Cargo", 150.0, 4.0).believed
    assert belief(4, "Cargo", 10.0, 5.0).believed
    # With no draught, the length stands in for it: 72 m = 4.6 m × 50.1 / 3.2.
    assert belief(4, "Cargo", 72.0, None).believed
    assert not belief(4, "Cargo", 71.9, None).believed


@pytest.mark.parametrize("draught_m", [None, math.nan, 0.0, -1.0, pd.NA])
def test_constrained_by_draught_with_no_draught_on_a_large_ship_is_believed(draught_m) -> None:
    said = belief(4, "Passenger", 301.0, draught_m)
    assert said.believed
    assert said.reason == (
        "status 4 (constrained by her draught) on a vessel of 301 m with no draught, at least 72 m"
    )


def test_constrained_by_draught_with_nothing_known_is_believed() -> None:
    said = belief(4, None, None, None)
    assert said.believed
    assert said.reason == "status 4 (constrained by her draught): no draught or length to judge by"


# -- 7 engaged in fishing --------------------------------------------------------------------


@pytest.mark.parametrize(("ship_type", "believed"), [("Fishing", True), (None, True)])
def test_fishing_on_fishing_vessels_or_unknown_types_is_believed(ship_type, believed) -> None:
    assert belief(7, ship_type, 15.0).believed is believed


@pytest.mark.parametrize("ship_type", ["Cargo", "Pleasure", "Sailing", "Tug", "Passenger"])
def test_fishing_on_other_types_is_refuted(ship_type) -> None:
    said = belief(7, ship_type, 15.0)
    assert not said.believed
    assert said.reason == (
        f"status 7 (engaged in fishing) on a vessel of type {ship_type}: only fishing vessels fish"
    )


# -- 3 restricted in her ability to manoeuvre -------------------------------------------------


@pytest.mark.parametrize(
    "ship_type",
    [
        "Dredging",
        "Diving",
        "Towing",
        "Towing long/wide",
        "Tug",
        "Pilot",
        "SAR",
        "Port tender",
        "Anti-pollution",
        "Law enforcement",
        "Military",
        "Other",
        None,
        "Reserved",
    ],
)
def test_restricted_on_working_types_and_unknown_types_is_believed(ship_type) -> None:
    assert belief(3, ship_type, 20.0).believed


@pytest.mark.parametrize("ship_type", ["Pleasure", "Sailing"])
def test_restricted_on_a_yacht_is_refuted(ship_type) -> None:
    said = belief(3, ship_type, 12.0)
    assert not said.believed
    assert said.reason == (
        f"status 3 (restricted in her ability to manoeuvre) on a vessel of type {ship_type}: "
        "her type does no rule 3(g) work and she is shorter than 50 m"
    )


def test_restricted_on_a_large_ship_of_any_type_is_believed() -> None:
    said = belief(3, "Cargo", 120.0)
    assert said.believed
    assert said.reason == (
        "status 3 (restricted in her ability to manoeuvre) on a vessel of 120 m: "
        "large ships do rule 3(g) work"
    )
    assert belief(3, "Passenger", 50.0).believed
    assert not belief(3, "Passenger", 49.9).believed
    assert not belief(3, "Cargo", None).believed
    assert belief(3, "Pleasure", 60.0).believed  # a superyacht may fly her helicopter


# -- 2 not under command, and statuses without a rule 18 rank ----------------------------------


@pytest.mark.parametrize("ship_type", [*SHIP_TYPES, None])
def test_not_under_command_is_believed_on_any_vessel(ship_type) -> None:
    said = belief(2, ship_type, 5.0, 0.5)
    assert said.believed
    assert said.reason == "status 2 (not under command): any vessel may be"


@pytest.mark.parametrize("status", [0, 1, 5, 6, 9, 14, 15, 16, -1, None, math.nan, pd.NA, 8.5])
def test_statuses_without_a_rule_18_rank_are_believed(status) -> None:
    said = belief(status, "Tug", 28.0, 4.0)
    assert said.believed
    assert said.reason.endswith(": no rule 18 rank")


def test_codes_from_numpy_and_pandas_are_read() -> None:
    assert not belief(np.int64(8), "Tug").believed
    assert not belief(np.float64(8.0), "Tug").believed
    assert not belief(pd.array([8], dtype="Int64")[0], "Tug").believed
    assert belief(0, "Tug").reason == "status 0: no rule 18 rank"
    assert belief(None, "Tug").reason == "status none: no rule 18 rank"


def test_the_parameters_move_the_lines() -> None:
    lenient = NavStatusParams(constrained_min_draught_m=2.0, sailing_types=frozenset({"tug"}))
    assert nav_status_belief(4, "Towing", 16.0, 2.7, lenient).believed
    assert nav_status_belief(8, "Tug", 28.0, None, lenient).believed
    assert not nav_status_belief(8, "Sailing", 12.0, None, lenient).believed


# -- properties --------------------------------------------------------------------------------

_types = st.sampled_from([*SHIP_TYPES, None])
_lengths = st.one_of(st.none(), st.floats(0.5, 460.0))
_draughts = st.one_of(st.none(), st.floats(0.1, 25.0))


@given(status=st.integers(-5, 30), ship_type=_types, length_m=_lengths, draught_m=_draughts)
def test_only_rule_18_statuses_are_ever_refuted(status, ship_type, length_m, draught_m) -> None:
    said = belief(status, ship_type, length_m, draught_m)
    if status not in set(NavStatus) or status == NavStatus.NOT_UNDER_COMMAND:
        assert said.believed
    assert said.reason.startswith(f"status {status}")


@given(status=st.sampled_from(list(NavStatus)))
def test_a_vessel_nothing_is_known_of_is_believed(status) -> None:
    assert belief(status, None, None, None).believed


@given(
    status=st.sampled_from(list(NavStatus)),
    ship_type=_types,
    length_m=_lengths,
    draught_m=_draughts,
)
def test_an_unknown_type_refutes_nothing_a_known_one_allows(
    status, ship_type, length_m, draught_m
) -> None:
    """Forgetting the ship type can only turn a refutation into belief (the type never
    speaks for a status, it only speaks against one)."""
    if belief(status, ship_type, length_m, draught_m).believed:
        assert belief(status, None, length_m, draught_m).believed


@given(status=st.sampled_from(list(NavStatus)), ship_type=_types, length_m=_lengths)
def test_the_case_of_the_type_does_not_matter(status, ship_type, length_m) -> None:
    upper = None if ship_type is None else ship_type.upper()
    assert belief(status, ship_type, length_m).believed == belief(status, upper, length_m).believed
