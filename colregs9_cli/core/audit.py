"""Audit facts beyond the paper (docs/design.md §5 Replay): did the pair pass within the data, how
close, and what each vessel did before the closest approach.

Every function works on one pair's steps from the trigger on (row 0 is the trigger), both
vessels present at every step. The facts are three-valued (``Fact``): where the data stops
before the closest approach the answer is ``insufficient-data``, never ``false``.

- **The pass.** The pair is past at the first step after the trigger at which it is opening
  (TCPA < 0). The data covers the closest approach when that step is in the data; the actual
  minimum separation is then the least range from the trigger to it.
- **Conduct.** Up to the closest approach, a vessel *changed* when her course turned by at
  least ``course_change_deg`` from her first course that can be judged, or her speed changed
  by at least ``speed_change_frac`` of her speed at the trigger and by at least
  ``speed_change_min_kn`` (a slow vessel's SOG noise is a large fraction of it). A course is
  judged only at speeds of at least ``course_judged_above_kn``: below that COG is GPS noise.
  The first change in time is her action (starboard turn, port turn, slowed, sped up). With
  no change, and her course judged at fewer than half of the steps, the answer is
  ``insufficient-data``: a slow vessel's turn cannot be seen in her COG.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import ArrayLike

from ..units import signed_angle_deg


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
    SPED_UP = "sped-up"
    NONE = "none"
    INSUFFICIENT = "insufficient-data"


@dataclass(frozen=True)
class Passage:
    """Where the pair passed: ``cpa_row`` is the row of the least range up to the pass."""

    covers_cpa: bool
    cpa_row: int | None
    min_separation_m: float | None


def passage(range_m: ArrayLike, tcpa_s: ArrayLike) -> Passage:
    """The pass and the actual closest approach (module docstring)."""
    ranges = np.asarray(range_m, dtype=float)
    opening = np.flatnonzero(np.asarray(tcpa_s, dtype=float)[1:] < 0.0)
    if len(opening) == 0:
        return Passage(covers_cpa=False, cpa_row=None, min_separation_m=None)
    past_row = int(opening[0]) + 1
    cpa_row = int(np.nanargmin(ranges[: past_row + 1]))
    return Passage(covers_cpa=True, cpa_row=cpa_row, min_separation_m=float(ranges[cpa_row]))


@dataclass(frozen=True)
class ConductParams:
    course_change_deg: float
    speed_change_frac: float
    speed_change_min_kn: float
    course_judged_above_kn: float


@dataclass(frozen=True)
class Conduct:
    """What one vessel did from the trigger to the closest approach."""

    changed: Fact  # true: she changed course or speed; false: she kept both
    action: Action
    action_row: int | None


INSUFFICIENT_CONDUCT = Conduct(Fact.INSUFFICIENT, Action.INSUFFICIENT, None)


def conduct(course_deg: ArrayLike, sog_kn: ArrayLike, params: ConductParams) -> Conduct:
    """One vessel's conduct over the rows given (the trigger to the closest approach)."""
    course = np.asarray(course_deg, dtype=float)
    sog = np.asarray(sog_kn, dtype=float)
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
            events.append((int(slowed[0]), Action.SLOWED))
        if len(sped_up):
            events.append((int(sped_up[0]), Action.SPED_UP))
    if events:
        row, action = min(events, key=lambda event: event[0])
        return Conduct(Fact.TRUE, action, row)
    if judged.mean() < 0.5:
        return INSUFFICIENT_CONDUCT
    return Conduct(Fact.FALSE, Action.NONE, None)


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
