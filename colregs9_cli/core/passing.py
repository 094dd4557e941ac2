"""When a passing is over, and how close the vessels came (docs/design.md §5, Replay).

A passing runs from the trigger until the range has opened clearly past its observed
minimum, not to the first step with a negative TCPA: TCPA is a prediction at constant
velocity, and a turn or a speed change flips its sign long before the vessels are past (two
vessels 1,068 m apart turned away for a minute, then closed to 97 m). The range has *opened*
at the first step at which it exceeds its least value so far by the larger of ``open_m`` and
``open_frac`` of that least value; the closest approach is the least range up to that step.

- ``open_m`` = 100 m: well beyond the noise of two AIS positions (a few metres each, more
  where a track is interpolated between reports), and about a ship's length, so that two
  vessels sliding past each other at a steady range are not called past too early.
- ``open_frac`` = 0.5: at a kilometre a 100 m swing is still a manoeuvre, not a pass; the
  range must open by half again.

A passing is followed for at most ``follow_s`` past the closest approach predicted at the
trigger (600 s: two vessels passing at 100 m and 2 kn relative open by 100 m within two
minutes; ten minutes leaves room for turns and slow vessels without following a pair that
stays close for hours). Where the data ends before the range opens, or the range has not
opened by then, the passing is not covered: its least range so far is still reported, as
observed, but the vessels may have come closer after it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class PassingParams:
    """When the range has opened clearly, and how long a passing is followed at most (the
    ``[replay]`` keys ``passing_open_m``, ``passing_open_frac`` and ``passing_follow_s``)."""

    open_m: float = 100.0
    open_frac: float = 0.5
    follow_s: float = 600.0


def horizon_steps(tcpa_s_at_trigger: float, params: PassingParams, step_s: float) -> int:
    """How many steps past the trigger a passing is followed at most."""
    return math.ceil((max(tcpa_s_at_trigger, 0.0) + params.follow_s) / step_s)


@dataclass(frozen=True)
class Passing:
    """One passing over rows from the trigger (row 0).

    ``end_row`` is the row at which the range has opened (``covers_cpa``), else the last row
    of the data; ``cpa_row`` is the row of the least range up to ``end_row`` (None when no
    range is known).
    """

    covers_cpa: bool
    end_row: int
    cpa_row: int | None
    min_separation_m: float | None


def opening_threshold_m(least_m: ArrayLike, params: PassingParams) -> np.ndarray:
    """The range at which a passing whose least range so far is ``least_m`` has opened."""
    least = np.asarray(least_m, dtype=float)
    return least + np.maximum(params.open_m, params.open_frac * least)


def passing(range_m: ArrayLike, params: PassingParams) -> Passing:
    """The passing in ``range_m`` (the range at each step from the trigger on)."""
    ranges = np.asarray(range_m, dtype=float)
    if len(ranges) == 0:
        return Passing(covers_cpa=False, end_row=0, cpa_row=None, min_separation_m=None)
    least = np.fmin.accumulate(np.where(np.isfinite(ranges), ranges, np.inf))
    with np.errstate(invalid="ignore"):
        opened = np.flatnonzero(ranges > opening_threshold_m(least, params))
    end_row = int(opened[0]) if len(opened) else len(ranges) - 1
    if not np.isfinite(ranges[: end_row + 1]).any():
        return Passing(covers_cpa=False, end_row=end_row, cpa_row=None, min_separation_m=None)
    cpa_row = int(np.nanargmin(ranges[: end_row + 1]))
    return Passing(
        covers_cpa=len(opened) > 0,
        end_row=end_row,
        cpa_row=cpa_row,
        min_separation_m=float(ranges[cpa_row]),
    )


@dataclass(frozen=True)
class MinimumEvidence:
    """What the least separation rests on (the issue's river bend: 0.9 m interpolated across
    gaps of 195 s and 161 s, where the real fixes never came closer than 33.6 m).

    - ``report_gap_s``: the larger of the two vessels' report gaps at the least separation's
      row (each the time between the two reports that bracket her sample there; 0 at a
      report's own time).
    - ``at_fixes_m``: the least range over the passing (rows 0 to ``end_row``) at the steps
      where at least one vessel is at a real fix, a report of hers less than one step from
      the sample (with whole-second reports and 1 s steps: the report's own second); None
      when no such step.
    - ``interpolated``: a vessel's own gap there is longer than the time she needs to cover
      her own length at her speed there (``gap_s · speed_mps > length_m``): she may have
      been a ship's length or more off the straight line between her reports.
    """

    report_gap_s: float
    at_fixes_m: float | None
    interpolated: bool


def minimum_evidence(
    range_m: ArrayLike,
    report_gap_s: ArrayLike,
    nearest_report_s: ArrayLike,
    speed_mps: ArrayLike,
    length_m: tuple[float, float],
    seen: Passing,
    step_s: float,
) -> MinimumEvidence | None:
    """``MinimumEvidence`` of ``seen`` over rows from the trigger: ``range_m`` per row, and
    ``report_gap_s``, ``nearest_report_s`` and ``speed_mps`` per row and vessel (shape
    (rows, 2)). None when the passing has no least separation."""
    if seen.cpa_row is None:
        return None
    ranges = np.asarray(range_m, dtype=float)[: seen.end_row + 1]
    gaps = np.asarray(report_gap_s, dtype=float)[: seen.end_row + 1]
    nearest = np.asarray(nearest_report_s, dtype=float)[: seen.end_row + 1]
    speeds = np.asarray(speed_mps, dtype=float)[seen.cpa_row]
    at_fix = (nearest < step_s).any(axis=1) & np.isfinite(ranges)
    gap_there = gaps[seen.cpa_row]
    with np.errstate(invalid="ignore"):
        covered_m = gap_there * speeds
    return MinimumEvidence(
        report_gap_s=float(np.nanmax(gap_there)),
        at_fixes_m=float(ranges[at_fix].min()) if at_fix.any() else None,
        interpolated=bool((covered_m > np.asarray(length_m, dtype=float)).any()),
    )
