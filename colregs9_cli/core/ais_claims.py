"""What AIS claims that the vessel's own data can refute: her navigational status, her SOG.

**Navigational status** (``nav_status_belief``). Rule 18 ranks a vessel by what she is doing
(not under command, restricted in her ability to manoeuvre, constrained by her draught,
engaged in fishing, sailing), and AIS says so in a field her crew sets by hand, often wrongly
and long after the fact. A status is believed unless the vessel's static data make it
implausible: "under way sailing" on a tug or a cruise ship, "constrained by her draught" on a
16 m towboat. What the data do not say (no ship type, no draught) refutes nothing. Statuses
without a rule 18 rank (0 under way using engine, 1 at anchor, 5 moored, 6 aground, 9-15
and none) are believed. Ship types are the category texts of ``ais.clean``'s
``SHIP_TYPE_CATEGORIES`` (``Sailing``, ``Tug``, ``Towing long/wide`` ...), in any case.

**SOG** (``contradicted_sog``, rule 3a of ``tracks.py``). A reported SOG is contradicted when
the vessel's positions around the report show she covered much less ground than it claims
(a yacht reporting 102.2 kn from one fixed position), with allowances for what makes an
honest SOG look too high against positions (``SogCheckParams``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from enum import IntEnum

import numpy as np
from numpy.typing import NDArray

from ..geo import ecef_m
from ..units import MPS_PER_KNOT, signed_angle_deg


class NavStatus(IntEnum):
    """The AIS navigational statuses (ITU-R M.1371) that give a rule 18 rank."""

    NOT_UNDER_COMMAND = 2
    RESTRICTED_MANOEUVRABILITY = 3
    CONSTRAINED_BY_DRAUGHT = 4
    ENGAGED_IN_FISHING = 7
    UNDER_WAY_SAILING = 8


_STATUS_TEXT = {
    NavStatus.NOT_UNDER_COMMAND: "not under command",
    NavStatus.RESTRICTED_MANOEUVRABILITY: "restricted in her ability to manoeuvre",
    NavStatus.CONSTRAINED_BY_DRAUGHT: "constrained by her draught",
    NavStatus.ENGAGED_IN_FISHING: "engaged in fishing",
    NavStatus.UNDER_WAY_SAILING: "under way sailing",
}


@dataclass(frozen=True)
class NavStatusParams:
    """Which vessels a rule 18 status is plausible on (ship types as ``SHIP_TYPE_CATEGORIES``
    spells them; compared without case).

    - ``sailing_types`` (Sailing, Pleasure): rule 3(c), a vessel under sail. Only sailing
      craft and yachts sail; pleasure craft (37) because AIS has one code for all yachts and
      many sailing yachts are typed 37.
    - ``fishing_types`` (Fishing): rule 3(d), a vessel fishing with nets, lines or trawls.
    - ``restricted_types``: rule 3(g), a vessel whose work restricts her: dredging, surveying
      and underwater operations (Dredging, Diving), towing (Towing, Towing long/wide, Tug),
      transferring persons or stores under way and tending marks (Pilot, SAR, Port tender,
      Law enforcement, Anti-pollution), replenishment, launching aircraft and mine clearance
      (Military), and the survey, cable and supply vessels AIS has no code for (Other).
      Pleasure and sailing craft are not: a yacht does none of rule 3(g)'s work under way,
      and the one that could (a dive boat with divers down) lies stopped, so she forms no
      pair (below ``min_sog_kn``); a yacht under way that says "restricted" claims a right of
      way over everything but NUC vessels that nothing she does gives her.
    - ``restricted_min_length_m`` (50 m): vessels this long may be doing rule 3(g) work
      whatever their type (ship-to-ship transfer, replenishment, crane and cable work by
      vessels typed Cargo or Tanker; a superyacht launching her helicopter, rule 3(g)(iv));
      50 m is where the COLREGs count a vessel as a large one (rule 23(a)(ii): a second
      masthead light; rule 30(b): two anchor lights, not one).
    - ``constrained_min_draught_m`` (4.6 m): rule 3(h) is a vessel restricted by her draught
      in relation to the depth available. One drawing less would float in a shallow-draft
      channel: the US Army Corps of Engineers calls channels deeper than 15 ft (4.6 m)
      deep-draft and shallower ones shallow-draft (IWR, "Corps and the Coast: Navigation").
      A 16 m towboat (about 2.5 m) or a harbour tug (4.5 m) is not deep-draught.
    - ``constrained_min_length_m`` (72 m): with no draught reported, a vessel this long may
      draw 4.6 m: 4.6 m × 15.7, the length-to-draught ratio of the paper's Table 1 means
      (50.1 m / 3.2 m). Shorter, or with no length either: a known short vessel is refuted,
      an unknown one is not.
    - ``unknown_types`` (Reserved, Spare 1, Spare 2): codes that say nothing, read as no type.
    """

    sailing_types: frozenset[str] = frozenset({"sailing", "pleasure"})
    fishing_types: frozenset[str] = frozenset({"fishing"})
    restricted_types: frozenset[str] = frozenset(
        {
            "dredging",
            "diving",
            "towing",
            "towing long/wide",
            "tug",
            "pilot",
            "sar",
            "port tender",
            "law enforcement",
            "anti-pollution",
            "military",
            "other",
        }
    )
    restricted_min_length_m: float = 50.0
    constrained_min_draught_m: float = 4.6
    constrained_min_length_m: float = 72.0
    unknown_types: frozenset[str] = frozenset({"reserved", "spare 1", "spare 2"})


@dataclass(frozen=True)
class NavStatusBelief:
    """Whether a navigational status is believed, and why (always said, for the record)."""

    believed: bool
    reason: str


def nav_status_belief(
    status: int | None,
    ship_type: str | None,
    length_m: float | None,
    draught_m: float | None,
    params: NavStatusParams | None = None,
) -> NavStatusBelief:
    """Whether ``status`` (an AIS navigational status code) is plausible for a vessel of
    ``ship_type``, ``length_m`` and ``draught_m`` (each ``None`` or NaN when unknown; a
    length or draught of 0 or less is unknown). Per vessel, pure.

    - 2 not under command: plausible for any vessel (any may break down).
    - 3 restricted in her ability to manoeuvre: on ``restricted_types``, an unknown type, or
      a vessel of at least ``restricted_min_length_m``.
    - 4 constrained by her draught: on a vessel drawing at least
      ``constrained_min_draught_m``; with no draught, one of at least
      ``constrained_min_length_m`` or of unknown length.
    - 7 engaged in fishing: on ``fishing_types`` or an unknown type.
    - 8 under way sailing: on ``sailing_types`` or an unknown type.
    - Any other status, or none: no rule 18 rank, believed.
    """
    params = params if params is not None else NavStatusParams()
    number = _code(status)
    if number not in _STATUS_TEXT:
        shown = "none" if number is None else str(number)
        return NavStatusBelief(True, f"status {shown}: no rule 18 rank")
    code = NavStatus(number)
    said = f"status {code.value} ({_STATUS_TEXT[code]})"
    kind = _type_key(ship_type, params)
    on = f"on a vessel of type {ship_type}" if kind is not None else "on a vessel of unknown type"
    if code is NavStatus.NOT_UNDER_COMMAND:
        return NavStatusBelief(True, f"{said}: any vessel may be")
    if code is NavStatus.UNDER_WAY_SAILING:
        return _by_type(said, on, kind, params.sailing_types, "only sailing craft and yachts sail")
    if code is NavStatus.ENGAGED_IN_FISHING:
        return _by_type(said, on, kind, params.fishing_types, "only fishing vessels fish")
    length = _dimension(length_m)
    if code is NavStatus.RESTRICTED_MANOEUVRABILITY:
        if length is not None and length >= params.restricted_min_length_m:
            return NavStatusBelief(
                True, f"{said} on a vessel of {length:g} m: large ships do rule 3(g) work"
            )
        return _by_type(
            said,
            on,
            kind,
            params.restricted_types,
            "her type does no rule 3(g) work and she is shorter than "
            f"{params.restricted_min_length_m:g} m",
        )
    return _constrained(said, length, _dimension(draught_m), params)


def _constrained(
    said: str, length_m: float | None, draught_m: float | None, params: NavStatusParams
) -> NavStatusBelief:
    """Status 4 by draught, else by length; nothing known refutes nothing."""
    if draught_m is not None:
        deep = draught_m >= params.constrained_min_draught_m
        relation = "at least" if deep else "less than"
        return NavStatusBelief(
            deep,
            f"{said} on a vessel drawing {draught_m:g} m, {relation} "
            f"{params.constrained_min_draught_m:g} m",
        )
    if length_m is None:
        return NavStatusBelief(True, f"{said}: no draught or length to judge by")
    long_enough = length_m >= params.constrained_min_length_m
    relation = "at least" if long_enough else "shorter than"
    return NavStatusBelief(
        long_enough,
        f"{said} on a vessel of {length_m:g} m with no draught, {relation} "
        f"{params.constrained_min_length_m:g} m",
    )


def _by_type(
    said: str, on: str, kind: str | None, plausible: frozenset[str], refuted_because: str
) -> NavStatusBelief:
    if kind is None:
        return NavStatusBelief(True, f"{said} {on}: nothing refutes it")
    if kind in plausible:
        return NavStatusBelief(True, f"{said} {on}")
    return NavStatusBelief(False, f"{said} {on}: {refuted_because}")


def _number(value: object) -> float | None:
    """A finite number, else None (None, NaN, ``pd.NA``, text)."""
    if value is None or isinstance(value, bool):
        return None
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) else None


def _code(status: object) -> int | None:
    """A status code as an int (8.0 and numpy or pandas integers too), else None."""
    number = _number(status)
    return int(number) if number is not None and number == int(number) else None


def _type_key(ship_type: object, params: NavStatusParams) -> str | None:
    """The ship type compared without case and spaces around it; None when unknown."""
    if not isinstance(ship_type, str):
        return None
    key = ship_type.strip().casefold()
    return None if not key or key in params.unknown_types else key


def _dimension(value: object) -> float | None:
    """A length or draught in metres; unknown (None) when missing, 0 or less."""
    number = _number(value)
    return number if number is not None and number > 0.0 else None


# -- SOG ------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SogCheckParams:
    """When a vessel's positions contradict her reported SOG (rule 3a of ``tracks.py``).

    The SOG ``v`` of a report is contradicted when its neighbours in the segment (those at
    most ``max_gap_s`` away; one-sided at a segment's end; none: not judged) lie ``c`` metres
    apart over ``Δt`` seconds with

        c < (1 − shortfall_frac) · v · (Δt − stale_s) − 2 · position_error_m   and
        v − c / Δt > min_excess_kn,

    unless her reported COGs there turn by more than ``max_turn_deg``. A SOG lower than the
    positions imply is never contradicted: that is what GNSS scatter does to the positions of
    a slow vessel (in the DMA NMEA sample, 211209290 at 0.1 kn has fixes 100 m apart 20 s
    apart, "24 kn"), and taking the positions' word would set her under way. Each term is an
    allowance for what makes an honest SOG look too high:

    - ``max_gap_s`` (180 s): the longest regular AIS reporting interval (Class A at anchor
      and Class B "CS" at 2 kn or less: 3 min, ITU-R M.1371-5 Tables 1 and 2). Beyond it
      reports were lost, and the vessel may have stopped or turned back unseen.
    - ``shortfall_frac`` (0.5): the chord of a track may be half its length (the chord of a
      turn of 217° is half the arc), or the speed may halve within the span.
    - ``stale_s`` (10 s): a position may be older than its report (a GNSS fix repeated:
      219601000 in the DMA NMEA sample repeats one fix over 4 s at 36.6 kn), by up to the
      Class A reporting interval at 0-14 kn (10 s). Spans of 10 s or less are never judged.
    - ``position_error_m`` (10 m): each position may be this far off (ITU-R M.1371: "high"
      position accuracy is 10 m or better).
    - ``min_excess_kn`` (3 kn): smaller excesses are not judged: the SOG of a vessel at rest
      reads up to 1.5 kn in the DMA sample (265571320), and a vessel slowing or turning
      makes good less than her SOG.
    - ``max_turn_deg`` (90°): a vessel whose own COGs (of the report and its neighbours,
      where known) differ by more than this was turning, and a loop brings her back near
      where she was (the San Diego pleasure craft 338403914 at 19 kn: 150 m in 92 s).
    """

    max_gap_s: float = 180.0
    shortfall_frac: float = 0.5
    stale_s: float = 10.0
    position_error_m: float = 10.0
    min_excess_kn: float = 3.0
    max_turn_deg: float = 90.0


@dataclass(frozen=True)
class Fixes:
    """Times (s), positions and true COGs of reports, NaN where there is no report."""

    t_s: NDArray[np.float64]
    lat_deg: NDArray[np.float64]
    lon_deg: NDArray[np.float64]
    cog_deg: NDArray[np.float64]

    def take(self, index: NDArray[np.int64], present: NDArray[np.bool_]) -> Fixes:
        """The fixes at ``index`` where ``present``, NaN elsewhere."""
        return Fixes(
            *(np.where(present, values[index], np.nan) for values in dataclasses.astuple(self))
        )

    def where(self, chosen: NDArray[np.bool_], other: Fixes) -> Fixes:
        """These fixes where ``chosen``, ``other``'s elsewhere."""
        pairs = zip(dataclasses.astuple(self), dataclasses.astuple(other), strict=True)
        return Fixes(*(np.where(chosen, mine, theirs) for mine, theirs in pairs))

    def table(self) -> NDArray[np.float64]:
        """One row per report: time, latitude, longitude, COG."""
        return np.column_stack(dataclasses.astuple(self))


def contradicted_sog(
    sog_kn: NDArray[np.float64],
    own: Fixes,
    previous: Fixes,
    following: Fixes,
    params: SogCheckParams,
) -> NDArray[np.bool_]:
    """Where the reports ``own`` and their neighbours in the segment (``previous``,
    ``following``; NaN: none) contradict the reported ``sog_kn`` (``SogCheckParams``).
    Vectorised and pure; a null SOG is not contradicted."""
    t_s = own.t_s
    with np.errstate(invalid="ignore"):
        start = previous.where(t_s - previous.t_s <= params.max_gap_s, own)
        end = following.where(following.t_s - t_s <= params.max_gap_s, own)
    span_s = end.t_s - start.t_s
    chord_m = np.linalg.norm(
        ecef_m(end.lat_deg, end.lon_deg) - ecef_m(start.lat_deg, start.lon_deg), axis=-1
    )
    turn_deg = np.zeros(len(t_s))
    for a, b in ((start, own), (own, end), (start, end)):
        # fmax: an unknown COG shows no turn.
        turn_deg = np.fmax(turn_deg, np.abs(signed_angle_deg(b.cog_deg - a.cog_deg)))
    claimed_m = (1.0 - params.shortfall_frac) * sog_kn * MPS_PER_KNOT * (span_s - params.stale_s)
    with np.errstate(invalid="ignore", divide="ignore"):
        excess_kn = sog_kn - chord_m / span_s / MPS_PER_KNOT
        contradicted = (
            (span_s > 0.0)
            & ~(turn_deg > params.max_turn_deg)
            & (chord_m < claimed_m - 2.0 * params.position_error_m)
            & (excess_kn > params.min_excess_kn)
        )
    return np.asarray(contradicted, dtype=bool)
