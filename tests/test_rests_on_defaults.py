"""``verdict_rests_on_defaults``: an estimate made from defaulted dimensions decided the
verdict when the other answer about that vessel would change the final roles."""

from __future__ import annotations

import pytest

from colregs9_cli.core.colregs import Role, Situation
from colregs9_cli.core.manoeuvrability import Restriction
from colregs9_cli.core.pair_model import rests_on_defaults
from colregs9_cli.core.rule9 import DecidingRule, decide_pair
from colregs9_cli.core.vessel_defaults import VesselDimensions

from seat_checks import swapped

KNOWN = VesselDimensions(50.0, 9.0, 5.0, defaulted=(), basis="")
DEFAULTED = VesselDimensions(12.0, 4.0, 1.5, defaulted=("draught_m",), basis="Class B")
STATUSES = frozenset({3, 4})
R, C, U = Restriction.RESTRICTED, Restriction.NOT_RESTRICTED, Restriction.UNKNOWN


def _rests(
    situation: Situation,
    roles: tuple[Role, Role],
    estimates: tuple[Restriction, Restriction],
    dimensions: tuple[VesselDimensions, VesselDimensions],
    nav_status: tuple[int | None, int | None] = (0, 0),
) -> tuple[bool, DecidingRule]:
    verdict = decide_pair(situation, roles, nav_status, estimates, STATUSES)
    flag = rests_on_defaults(verdict, dimensions, estimates, nav_status, STATUSES)
    other_seat = rests_on_defaults(
        swapped(verdict),
        (dimensions[1], dimensions[0]),
        (estimates[1], estimates[0]),
        (nav_status[1], nav_status[0]),
        STATUSES,
    )
    assert flag == other_seat, "the flag must not depend on the vessels' order"
    return flag, verdict.deciding_rule


GW, SO = Role.GIVE_WAY, Role.STAND_ON


def test_the_stand_on_vessels_defaulted_clear_that_let_rule_9_decide_counts() -> None:
    # a gives way (known dimensions, restricted); b stands on, clear on a default draught.
    # Had b come out restricted too, both would be restricted and rule 15 would stand.
    assert _rests(Situation.CROSSING, (GW, SO), (R, C), (KNOWN, DEFAULTED)) == (
        True,
        DecidingRule.RULE_9,
    )


def test_a_decisive_estimate_from_ais_dimensions_does_not_count() -> None:
    assert _rests(Situation.CROSSING, (GW, SO), (R, C), (KNOWN, KNOWN)) == (
        False,
        DecidingRule.RULE_9,
    )


@pytest.mark.parametrize(
    ("situation", "roles", "estimates", "dimensions", "nav_status", "expected"),
    [
        # The give-way vessel's d3 on a default decided that rule 9 did not apply.
        (Situation.CROSSING, (GW, SO), (C, C), (DEFAULTED, KNOWN), (0, 0), True),
        # Unknown rests on no dimension.
        (Situation.CROSSING, (GW, SO), (U, U), (DEFAULTED, DEFAULTED), (0, 0), False),
        # Overtaking: rule 13 keeps the roles whatever the estimates.
        (Situation.OVERTAKING, (GW, SO), (R, C), (DEFAULTED, DEFAULTED), (0, 0), False),
        # AIS status 3 makes b's estimate moot; a's default still decides nothing either.
        (Situation.CROSSING, (SO, GW), (C, C), (KNOWN, DEFAULTED), (0, 3), False),
    ],
)
def test_only_estimates_that_change_the_verdict_count(
    situation: Situation,
    roles: tuple[Role, Role],
    estimates: tuple[Restriction, Restriction],
    dimensions: tuple[VesselDimensions, VesselDimensions],
    nav_status: tuple[int | None, int | None],
    expected: bool,
) -> None:
    assert _rests(situation, roles, estimates, dimensions, nav_status)[0] is expected
