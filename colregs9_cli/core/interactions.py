"""Interactions: what a triggered pair is doing before any COLREGs rule is applied (DESIGN §7).

Rules 13–17 bind two vessels under way that meet. Much of what the pair search triggers on
in real AIS is something else: a tow, a pilot boat boarding, a ferry leaving her berth. Each
triggered pair is classified from what both vessels did over a window around the trigger,
judged on their positions over ground (a reported SOG is a claim: a yacht reporting 102.2 kn
from one fixed position is not making way), with these tests in this order; the first that
holds decides:

1. ``alongside``: the range stays under the sum of the half-breadths plus
   ``alongside_margin_m`` for ``alongside_min_s`` (hulls together or nearly: STS transfer, tug
   made fast, pilot alongside, a short tow). First because it describes the two hulls
   whatever they are doing: an STS transfer at anchor is alongside, not merely at rest.
2. ``service``: one vessel, and only one, is a service craft (``SERVICE_SHIP_TYPES``) that
   comes to the other within ``service_margin_m`` of her half-length and holds there at a
   relative speed over ground under ``service_speed_kn`` for ``service_min_s`` (a pilot
   boarding, a tug making up). Coming: the hold starts after the window opens; a craft
   already in station for the whole window is a tow or an escort (``in-company``). Before
   ``not-making-way``: a tug coming to a ship at anchor is serving her. Two service craft
   together are judged by the other tests (tugs in company).
3. ``not-making-way``: either vessel moves over ground slower than ``making_way_kn`` for
   ``at_rest_min_s`` on end (at anchor, moored, aground, drifting, berthing, unberthing).
   Before ``in-company``: two towboats drifting side by side are not sailing together.
4. ``in-company``: for ``company_min_s`` both vessels make way on courses over ground within
   ``company_course_deg`` of each other, and the relative position, in the frame of their
   mean course (a formation turning in succession) or over ground (one turning together),
   stays within a box of ``company_drift_m`` (or ``company_drift_frac`` of the range, if
   larger): a tow, a convoy, an escort, tugs in company. The box is what tells
   them from a slow overtaking, whose range also changes slowly but whose relative
   position runs along the formation.
5. ``encounter``: none of the above.

Every measure is symmetric in the two vessels (ranges, relative velocities, tests applied
to both), so both seats get the same kind, and only the rows within ``interaction_window_s``
of the trigger are read (for ``alongside`` and ``service`` also up to the predicted closest
approach and ``interaction_window_s`` past it), so the kind does not depend on how long the
series is. The series
should reach ``interaction_window_s`` before the trigger (``window_steps``): a ferry leaving
her berth reports SOG under ``min_sog_kn`` until her candidate run starts, and her time at
the berth is the evidence.

Speeds and courses over ground are measured from the positions over ``speed_span_s``
centred on each step (one-sided at the window's ends), in Earth-centred coordinates
(``geo.ecef_m``), never from the run's map frame, whose ``north_m``/``east_m`` may be NaN.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from enum import StrEnum
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from ..errors import ParameterError
from ..geo import ecef_m, in_tangent_plane
from ..units import MPS_PER_KNOT
from .vessel_defaults import vessel_dimensions


class InteractionKind(StrEnum):
    """What a triggered pair is doing (DESIGN §7); only an ``encounter`` gets a verdict."""

    ENCOUNTER = "encounter"
    IN_COMPANY = "in-company"
    ALONGSIDE = "alongside"
    SERVICE = "service"
    NOT_MAKING_WAY = "not-making-way"


# The AIS ship types (ITU-R M.1371 codes 31, 32, 50, 51, 52, 53) of craft that come to work
# at a ship, spelt as ``ais.clean.SHIP_TYPE_CATEGORIES`` writes them.
SERVICE_SHIP_TYPES: frozenset[str] = frozenset(
    {"Towing", "Towing long/wide", "Pilot", "SAR", "Tug", "Port tender"}
)
# Navigational statuses that claim the vessel is not making way: at anchor, moored, aground.
_STILL_STATUSES = {1: "at anchor", 5: "moored", 6: "aground"}


@dataclass(frozen=True)
class InteractionParams:
    """The thresholds of the module docstring (``[replay]`` keys of the same names).

    - ``interaction_window_s`` (120 s): the pair is judged over the trigger ± this, clipped
      to the data: the 4 minutes around the trigger of the issue's screen, long enough for
      a tow's steady range and a berthing's stop, short enough that the pass itself (TCPA
      at most ``tcpa_act_s`` = 180 s after the trigger) still dominates an encounter's window.
    - ``speed_span_s`` (30 s): speeds and courses over ground are measured over this span.
      At 1 kn a vessel covers 15 m in 30 s, several times the metre-level scatter of
      consecutive fixes, so the speed error is a few tenths of a knot.
    - ``making_way_kn`` (1.0 kn): slower than this over ground a vessel is not making way.
      Above the drift of the held-out towboats (0.2–0.8 kn) and of the San Diego yacht at
      her mooring (0.1 kn over ground while reporting 0.5 kn); below every vessel of the
      fixtures' real encounters (the slowest: 245281000 entering the Holtenau locks at
      1.0–1.5 kn, yachts tacking in San Diego Bay at 1.6 kn).
    - ``at_rest_min_s`` (30 s): that slow for at least this long, on end: one full speed
      span, so that a momentary low (a turn, a fix that jumps back) does not count.
    - ``alongside_margin_m`` (10 m): added to the half-breadths. The range runs antenna to
      antenna; the margin covers the fenders' gap and the fixes' error: AIS's position
      accuracy flag divides fixes at 10 m (ITU-R M.1371, message 1 "position accuracy").
    - ``alongside_min_s`` (60 s): for at least this long. Two vessels passing at relative
      speed v stay within a distance L of each other for at most 2L/v: for two unknown
      merchant ships (L = 9.2 m + 10 m) 60 s admits only v < 1.3 kn.
    - ``service_margin_m`` (30 m): a service craft within the served vessel's half-length
      plus this is at her side (her antenna may be anywhere along her; "closing to tens of
      metres"). A pilot boat at the ladder of a 185 m tanker: within 122 m.
    - ``service_speed_kn`` (1.0 kn): matching speed: relative speed over ground under this
      (30 m a minute at most, while a boarding pilot boat holds station at the ladder).
    - ``service_min_s`` (30 s): held for at least this long (a speed span; a boarding takes
      minutes, a passing craft matches speed for a moment at most).
    - ``company_min_s`` (120 s): in company for at least this long ("over minutes"; the
      DMA tow held 13–16 m for 4.5 min, the held-out tugs 60–80 m for 6 min).
    - ``company_course_deg`` (20°): courses over ground within this of each other (the tow
      turned 13° together within 2°; a 20° crossing is not a formation).
    - ``company_drift_m`` (30 m) and ``company_drift_frac`` (0.25): the relative position
      keeps within a box this size (the larger of the two; the fraction of the median
      range). The held-out tugs in company ranged 60–80 m, the DMA tow drifted 4 m; a slow
      overtaking at 0.5 kn moves 62 m along the formation in 4 min.
    """

    interaction_window_s: float = 120.0
    speed_span_s: float = 30.0
    making_way_kn: float = 1.0
    at_rest_min_s: float = 30.0
    alongside_margin_m: float = 10.0
    alongside_min_s: float = 60.0
    service_margin_m: float = 30.0
    service_speed_kn: float = 1.0
    service_min_s: float = 30.0
    company_min_s: float = 120.0
    company_course_deg: float = 20.0
    company_drift_m: float = 30.0
    company_drift_frac: float = 0.25

    def __post_init__(self) -> None:
        for field in fields(self):
            value = getattr(self, field.name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0.0):
                raise ParameterError(f"[replay] {field.name} = {value!r}: give a number >= 0")
        if self.interaction_window_s <= 0.0 or self.speed_span_s <= 0.0:
            raise ParameterError(
                "[replay] interaction_window_s and speed_span_s must be > 0 (got "
                f"{self.interaction_window_s:g} and {self.speed_span_s:g})"
            )
        if self.company_course_deg > 180.0:
            raise ParameterError(
                f"[replay] company_course_deg = {self.company_course_deg:g}: give 0 to 180"
            )


@dataclass(frozen=True)
class VesselFacts:
    """What AIS says of a vessel, beside her track (``Tracks.vessels``' static columns).

    ``ship_type`` as the canonical schema spells it ('Pilot', 'Tug', 'Tanker' …);
    ``length_m`` and ``breadth_m`` as reported, None when not; a missing one takes the value
    of ``vessel_defaults`` by ``mobile_type`` and ship type (and the basis says so). ``mmsi``
    names her in the basis (without it: 'a' or 'b', by seat).
    """

    mmsi: int | None = None
    ship_type: str | None = None
    mobile_type: str | None = None
    length_m: float | None = None
    breadth_m: float | None = None

    @classmethod
    def from_static(cls, mmsi: int, static: Mapping[str, Any]) -> VesselFacts:
        """From a row of ``Tracks.vessels`` (or any mapping of its columns); NaN and absent
        values are None."""

        def known(name: str) -> Any:
            value = static.get(name)
            missing = value is None or (not isinstance(value, str) and bool(pd.isna(value)))
            return None if missing else value

        length, breadth = known("length_m"), known("breadth_m")
        return cls(
            mmsi=int(mmsi),
            ship_type=None if known("ship_type") is None else str(known("ship_type")),
            mobile_type=None if known("mobile_type") is None else str(known("mobile_type")),
            length_m=None if length is None else float(length),
            breadth_m=None if breadth is None else float(breadth),
        )


@dataclass(frozen=True)
class Interaction:
    """A pair's interaction: its kind, and the rule that fired with its measured values
    (``basis``, one short line). ``first_step``..``last_step`` (grid steps) is the window
    judged; ``-1`` when under two rows were usable (no positions at the trigger)."""

    kind: InteractionKind
    basis: str
    first_step: int
    last_step: int


def window_steps(params: InteractionParams, step_s: float) -> int:
    """How many steps either side of the trigger the classification reads: the series
    should start this many steps before the trigger (``encounter_series(from_step=…)``)."""
    return math.ceil(params.interaction_window_s / step_s - 1e-9)


def approach_steps(approach_s: float, step_s: float) -> int:
    """How many steps past the trigger's window the alongside and service tests read: up
    to the predicted closest approach (TCPA at the trigger, at least 0)."""
    return math.ceil(max(approach_s, 0.0) / step_s - 1e-9)


@dataclass(frozen=True)
class _Vessel:
    """One vessel's measures over the window."""

    name: str
    position_m: NDArray[np.float64]  # Earth-centred (n, 3)
    velocity_mps: NDArray[np.float64]  # over ground, Earth-centred (n, 3)
    speed_kn: NDArray[np.float64]
    sog_kn: NDArray[np.float64]  # as reported
    nav_status: NDArray[np.float64]
    half_breadth_m: float
    breadth_defaulted: bool
    half_length_m: float
    service: bool


@dataclass(frozen=True)
class _Window:
    steps: NDArray[np.int64]
    trigger_step: int
    step_s: float
    vessels: tuple[_Vessel, _Vessel]  # in naming order (MMSI order when both are known)
    range_m: NDArray[np.float64]
    rel_speed_kn: NDArray[np.float64]

    def span_s(self, first: int, last: int) -> float:
        return float(self.steps[last] - self.steps[first]) * self.step_s

    def since_trigger_s(self, row: int) -> float:
        return float(self.steps[row] - self.trigger_step) * self.step_s


def classify_interaction(
    series: pd.DataFrame,
    trigger_row: int,
    facts: tuple[VesselFacts, VesselFacts],
    params: InteractionParams,
    step_s: float,
    approach_s: float = 0.0,
) -> Interaction:
    """The interaction of a triggered pair (see the module docstring for the tests).

    ``series``: the pair's steps as ``encounters.encounter_series`` gives them (``own_*`` is
    vessel a with ``facts[0]``, ``target_*`` vessel b with ``facts[1]``); ``trigger_row``
    its row of the trigger; ``step_s`` the grid step; ``approach_s`` the TCPA at the
    trigger. Only the rows on consecutive steps within ``interaction_window_s`` of the
    trigger are read, and for ``alongside`` and ``service`` also those up to
    ``interaction_window_s`` past the predicted closest approach (``approach_steps``): a
    pilot boat triggers minutes before she reaches the ladder, and what she does there is
    what she is.
    """
    near = _window(series, trigger_row, facts, params, step_s, 0.0)
    if near is None:
        return Interaction(
            InteractionKind.ENCOUNTER,
            "under two steps around the trigger: nothing to judge",
            -1,
            -1,
        )
    wide = _window(series, trigger_row, facts, params, step_s, approach_s)
    assert wide is not None  # it holds the near window
    tests = ((_alongside, wide), (_service, wide), (_not_making_way, near), (_in_company, near))
    for test, window in tests:
        found = test(window, params)
        if found is not None:
            kind, basis = found
            return Interaction(kind, basis, int(window.steps[0]), int(window.steps[-1]))
    basis = _encounter_basis(near)
    return Interaction(InteractionKind.ENCOUNTER, basis, int(near.steps[0]), int(near.steps[-1]))


def under_way_from(
    series: pd.DataFrame,
    facts: tuple[VesselFacts, VesselFacts],
    params: InteractionParams,
    step_s: float,
) -> tuple[int, int] | None:
    """Where both vessels are under way, in rows of ``series`` (from a pair's trigger on):
    the first row from which both make way over ground (``making_way_kn``, measured as the
    tests measure it) on consecutive steps, and the row at which they have done so for
    ``at_rest_min_s``. A pair judged not making way at its trigger may meet under way later
    in the same passing: a ferry leaving her berth (DMA: 219622000 at Helsingør, at her
    berth at the trigger, 12:00:39, away at 12:00:45, at 9-10 kn 155 m from the other ferry
    at 12:02:30). None when they never do so for that long."""
    known = _positions_known(series)
    steps = series["step"].to_numpy(dtype=np.int64)
    consecutive = np.r_[True, np.diff(steps) == 1]
    usable = known & np.logical_and.accumulate(consecutive)
    rows = np.flatnonzero(usable)
    if len(rows) < 2 or rows[0] != 0:
        return None
    part = series.iloc[: rows[-1] + 1]
    span = _half_span_steps(params, step_s)
    speeds = [
        _vessel(part, prefix, fact, seat, span, step_s).speed_kn
        for prefix, fact, seat in zip(("own_", "target_"), facts, "ab", strict=True)
    ]
    making_way = (speeds[0] >= params.making_way_kn) & (speeds[1] >= params.making_way_kn)
    held_steps = math.ceil(params.at_rest_min_s / step_s - 1e-9)
    edges = np.diff(np.r_[0, making_way.astype(np.int8), 0])
    for start, end in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1, strict=True):
        if end - start >= held_steps:
            return int(start), int(start) + held_steps
    return None


# -- the window -----------------------------------------------------------------------------


def _window(
    series: pd.DataFrame,
    trigger_row: int,
    facts: tuple[VesselFacts, VesselFacts],
    params: InteractionParams,
    step_s: float,
    approach_s: float,
) -> _Window | None:
    """The rows within the window around the trigger, reaching ``approach_s`` further after
    it, on consecutive steps with both positions known, measured; None when that is under
    two rows."""
    if not 0 <= trigger_row < len(series):
        return None
    steps = series["step"].to_numpy(dtype=np.int64)
    known = _positions_known(series)
    if not known[trigger_row]:
        return None
    trigger_step = int(steps[trigger_row])
    # the run of usable rows on consecutive steps that holds the trigger, within reach
    reach = window_steps(params, step_s)
    after = reach + approach_steps(approach_s, step_s)
    near = np.flatnonzero((steps >= trigger_step - reach) & (steps <= trigger_step + after))
    usable = known[near] & (steps[near] - trigger_step == near - trigger_row)
    at = int(np.searchsorted(near, trigger_row))
    breaks = np.flatnonzero(~usable)
    lo = int(breaks[breaks < at].max(initial=-1)) + 1
    hi = int(breaks[breaks > at].min(initial=len(near)))
    rows = near[lo:hi]
    if len(rows) < 2:
        return None
    part = series.iloc[rows]
    span = _half_span_steps(params, step_s)
    vessels = [
        _vessel(part, prefix, fact, seat, span, step_s)
        for prefix, fact, seat in zip(("own_", "target_"), facts, "ab", strict=True)
    ]
    if facts[0].mmsi is not None and facts[1].mmsi is not None and facts[1].mmsi < facts[0].mmsi:
        vessels.reverse()
    a, b = vessels
    rel_velocity = b.velocity_mps - a.velocity_mps
    return _Window(
        steps=part["step"].to_numpy(dtype=np.int64),
        trigger_step=trigger_step,
        step_s=step_s,
        vessels=(a, b),
        range_m=np.linalg.norm(b.position_m - a.position_m, axis=-1),
        rel_speed_kn=np.linalg.norm(rel_velocity, axis=-1) / MPS_PER_KNOT,
    )


def _positions_known(series: pd.DataFrame) -> NDArray[np.bool_]:
    """The rows with both vessels' positions."""
    known = np.ones(len(series), dtype=bool)
    for column in ("own_lat_deg", "own_lon_deg", "target_lat_deg", "target_lon_deg"):
        known &= np.isfinite(series[column].to_numpy(dtype=float))
    return known


def _half_span_steps(params: InteractionParams, step_s: float) -> int:
    """Steps either side of a row over which speeds over ground are measured."""
    return max(1, round(params.speed_span_s / step_s / 2.0))


def _vessel(
    part: pd.DataFrame, prefix: str, fact: VesselFacts, seat: str, span: int, step_s: float
) -> _Vessel:
    lat = part[f"{prefix}lat_deg"].to_numpy(dtype=float)
    lon = part[f"{prefix}lon_deg"].to_numpy(dtype=float)
    position = ecef_m(lat, lon)
    rows = np.arange(len(part))
    before = np.clip(rows - span, 0, len(part) - 1)
    after = np.clip(rows + span, 0, len(part) - 1)
    elapsed_s = (after - before).astype(float) * step_s
    velocity = (position[after] - position[before]) / elapsed_s[:, None]
    dimensions = vessel_dimensions(
        {
            "ship_type": fact.ship_type,
            "mobile_type": fact.mobile_type,
            "length_m": fact.length_m,
            "breadth_m": fact.breadth_m,
        }
    )
    return _Vessel(
        name=str(fact.mmsi) if fact.mmsi is not None else seat,
        position_m=position,
        velocity_mps=velocity,
        speed_kn=np.linalg.norm(velocity, axis=-1) / MPS_PER_KNOT,
        sog_kn=part[f"{prefix}sog_kn"].to_numpy(dtype=float),
        nav_status=pd.to_numeric(part[f"{prefix}nav_status"], errors="coerce").to_numpy(
            dtype=float, na_value=np.nan
        ),
        half_breadth_m=dimensions.breadth_m / 2.0,
        breadth_defaulted="breadth_m" in dimensions.defaulted,
        half_length_m=dimensions.length_m / 2.0,
        service=(fact.ship_type or "").strip().casefold()
        in {t.casefold() for t in SERVICE_SHIP_TYPES},
    )


def _held_for(
    window: _Window, held: NDArray[np.bool_], min_s: float, first_row: int = 0
) -> tuple[int, int] | None:
    """First and last row of the longest run of ``held`` (the earliest of equals) that
    starts at ``first_row`` or later and lasts at least ``min_s``; None if there is none."""
    edges = np.diff(np.r_[0, held.astype(np.int8), 0])
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    keep = starts >= first_row
    starts, ends = starts[keep], ends[keep]
    if not len(starts):
        return None
    best = int(np.argmax(ends - starts))
    run = int(starts[best]), int(ends[best])
    return run if window.span_s(*run) >= min_s else None


def _spread(values: NDArray[np.float64], unit: str, digits: int = 0) -> str:
    low, high = float(np.min(values)), float(np.max(values))
    if round(low, digits) == round(high, digits):
        return f"{low:.{digits}f} {unit}"
    return f"{low:.{digits}f}–{high:.{digits}f} {unit}"


# -- the tests, in order ----------------------------------------------------------------------

_Found = tuple[InteractionKind, str] | None


def _alongside(window: _Window, params: InteractionParams) -> _Found:
    a, b = window.vessels
    half_breadths_m = a.half_breadth_m + b.half_breadth_m
    limit_m = half_breadths_m + params.alongside_margin_m
    run = _held_for(window, window.range_m <= limit_m, params.alongside_min_s)
    if run is None:
        return None
    first, last = run
    defaulted = " (defaulted)" if a.breadth_defaulted or b.breadth_defaulted else ""
    return InteractionKind.ALONGSIDE, (
        f"range {_spread(window.range_m[first : last + 1], 'm')} <= half-breadths "
        f"{half_breadths_m:.1f} m{defaulted} + margin {params.alongside_margin_m:g} m "
        f"for {window.span_s(first, last):.0f} s"
    )


def _service(window: _Window, params: InteractionParams) -> _Found:
    a, b = window.vessels
    if a.service == b.service:
        return None
    craft, served = (a, b) if a.service else (b, a)
    reach_m = served.half_length_m + params.service_margin_m
    close = (window.range_m <= reach_m) & (window.rel_speed_kn < params.service_speed_kn)
    # coming to work: not already in station when the window opens (a tow, an escort)
    run = _held_for(window, close, params.service_min_s, first_row=1)
    if run is None:
        return None
    first, last = run
    rows = slice(first, last + 1)
    return InteractionKind.SERVICE, (
        f"service craft {craft.name} within {_spread(window.range_m[rows], 'm')} of "
        f"{served.name} (half-length {served.half_length_m:.0f} m + margin "
        f"{params.service_margin_m:g} m) at relative speed "
        f"{_spread(window.rel_speed_kn[rows], 'kn', 1)} for {window.span_s(first, last):.0f} s"
    )


def _not_making_way(window: _Window, params: InteractionParams) -> _Found:
    parts: list[str] = []
    for vessel in window.vessels:
        run = _held_for(window, vessel.speed_kn < params.making_way_kn, params.at_rest_min_s)
        if run is None:
            continue
        first, last = run
        rows = slice(first, last + 1)
        moved_m = float(np.linalg.norm(vessel.position_m[last] - vessel.position_m[first]))
        duration_s = window.span_s(first, last)
        sog = vessel.sog_kn[rows]
        claims = (
            [f"SOG {_spread(sog[np.isfinite(sog)], 'kn', 1)}"] if np.isfinite(sog).any() else []
        )
        statuses = sorted({int(s) for s in vessel.nav_status[rows] if s in _STILL_STATUSES})
        claims += [_STILL_STATUSES[s] for s in statuses]
        parts.append(
            f"{vessel.name} moved {moved_m:.0f} m in {duration_s:.0f} s from "
            f"{window.since_trigger_s(first):+.0f} s (< {params.making_way_kn:g} kn over ground; "
            f"reports {', '.join(claims) or 'nothing'})"
        )
    if not parts:
        return None
    return InteractionKind.NOT_MAKING_WAY, "; ".join(parts)


def _in_company(window: _Window, params: InteractionParams) -> _Found:
    a, b = window.vessels
    if window.span_s(0, len(window.steps) - 1) < params.company_min_s:
        return None
    if min(a.speed_kn.min(), b.speed_kn.min()) < params.making_way_kn:
        return None
    course_apart_deg = _angle_between_deg(a.velocity_mps, b.velocity_mps)
    if course_apart_deg.max() > params.company_course_deg:
        return None
    (along_m, across_m), (north_m, east_m) = _formation_offsets(window)
    # A formation that turns in succession (a tow, a column) keeps its shape in the frame
    # of its course; one that turns together (ships abreast, each turning on the spot)
    # keeps it in the Earth's: either is in company.
    drifts_m = {
        "along the course": math.hypot(float(np.ptp(along_m)), float(np.ptp(across_m))),
        "over ground": math.hypot(float(np.ptp(north_m)), float(np.ptp(east_m))),
    }
    frame, drift_m = min(drifts_m.items(), key=lambda item: item[1])
    median_range_m = float(np.median(window.range_m))
    allowed_m = max(params.company_drift_m, params.company_drift_frac * median_range_m)
    if drift_m > allowed_m:
        return None
    return InteractionKind.IN_COMPANY, (
        f"range {_spread(window.range_m, 'm')}, relative position {frame} within "
        f"{drift_m:.0f} m (<= {allowed_m:.0f} m), courses within "
        f"{course_apart_deg.max():.0f}° at "
        f"{_spread(a.speed_kn, 'kn', 1)} and {_spread(b.speed_kn, 'kn', 1)} for "
        f"{window.span_s(0, len(window.steps) - 1):.0f} s"
    )


def _angle_between_deg(u: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """The angle between two sets of 3-D vectors (degrees; symmetric in u and v)."""
    cross = np.linalg.norm(np.cross(u, v), axis=-1)
    dot = np.sum(u * v, axis=-1)
    return np.degrees(np.arctan2(cross, dot))


Offsets = tuple[NDArray[np.float64], NDArray[np.float64]]


def _formation_offsets(window: _Window) -> tuple[Offsets, Offsets]:
    """b's offset from a along and across the pair's mean course over ground (a turn in
    succession leaves it unchanged), and north and east (a turn together leaves it
    unchanged), in the tangent plane at their midpoint."""
    a, b = window.vessels
    middle = (a.position_m + b.position_m) / 2.0
    length = np.linalg.norm(middle, axis=-1, keepdims=True)
    # the midpoint's latitude and longitude on the sphere are enough for a tangent plane
    lat_deg = np.degrees(np.arcsin(middle[:, 2] / length[:, 0]))
    lon_deg = np.degrees(np.arctan2(middle[:, 1], middle[:, 0]))
    heading = a.velocity_mps / np.linalg.norm(a.velocity_mps, axis=-1, keepdims=True)
    heading = heading + b.velocity_mps / np.linalg.norm(b.velocity_mps, axis=-1, keepdims=True)
    h_north, h_east = in_tangent_plane(heading, lat_deg, lon_deg)
    theta = np.arctan2(h_east, h_north)
    r_north, r_east = in_tangent_plane(b.position_m - a.position_m, lat_deg, lon_deg)
    along = r_north * np.cos(theta) + r_east * np.sin(theta)
    across = -r_north * np.sin(theta) + r_east * np.cos(theta)
    return (along, across), (r_north, r_east)


def _encounter_basis(window: _Window) -> str:
    a, b = window.vessels
    return (
        f"none of the other kinds: {a.name} at {_spread(a.speed_kn, 'kn', 1)} and {b.name} at "
        f"{_spread(b.speed_kn, 'kn', 1)} over ground, range {_spread(window.range_m, 'm')}, "
        f"relative speed {_spread(window.rel_speed_kn, 'kn', 1)} "
        f"over {window.span_s(0, len(window.steps) - 1):.0f} s"
    )
