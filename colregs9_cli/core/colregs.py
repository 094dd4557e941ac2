"""COLREGs rules 13–15: one situation per pair and both vessels' roles (the paper's G_a,
docs/design.md §5).

Angles: β is the relative bearing of the target from own ship and β' that of own ship from
the target, each measured clockwise from the observer's course, in [0, 360). The course is
COG or heading (``ColregsParams.course_source``). "Closing" means the range is decreasing:
``p·v < 0`` for the target's relative position p and relative velocity v (over ground).

The pair's geometry is classified once, and both roles follow from it, so that swapping the
seats swaps the roles and nothing else. In order of precedence:

1. **none**: not closing (range opening or steady, or unknown motion). Roles: none.
2. **overtaking** (rule 13): one vessel is strictly more than 22.5° abaft the other's beam,
   β or β' strictly inside (``overtaking_sector_min_deg``, ``overtaking_sector_max_deg``),
   while the other is not in hers. The vessel coming up from astern gives way.
3. **head-on** (rule 14): each is within ±``head_on_half_angle_deg`` of the other's bow. Both
   give way. Rule 14(c), in doubt assume head-on: each vessel sees the other on the *same*
   side (both on the starboard bow or both on the port bow), each within
   ``head_on_doubt_deg`` of her bow; such courses are within that angle of reciprocal. Red
   to red (each on the other's port side) the doubt reaches further: courses within
   ``head_on_doubt_deg`` of reciprocal with one vessel seeing the other within that angle of
   her bow (San Diego: SAILEBRATE saw SHELTER ISLAND 7° on her port bow, SHELTER ISLAND
   saw her 25° on hers, courses 18° off reciprocal). Rule 15 names neither vessel there (none
   has the other on her starboard side), and a turn to starboard by both, which rule 14
   asks, widens a port-to-port pass; green to green the same two turns would close it, so
   the starboard side keeps the narrower doubt.
4. **crossing** (rule 15), everything else: exactly one vessel gives way, the one that has the
   other on her starboard side. When the two see each other on the same side (or on a
   fore-and-aft line), rule 15's words name both or neither; the vessel whose bearing is
   farther from her fore-and-aft line keeps her side and decides, because the other's side
   is the one a small course error would flip. An exact tie (reciprocal courses, equal
   bearings) is the rule 14(c) doubt again: head-on.

A situation is ``ambiguous`` when moving either bearing by ``ambiguity_margin_deg`` would change
it or either role: it lies near a sector boundary, where the course noise of AIS can decide.
The rules say how a vessel in doubt reads it: a crossing that such a move would put in the
head-on sectors (not merely in the doubt above) is head-on (rule 14(c), "in any doubt ...
assume that it does exist"; San Diego: TRADITION
6.06° off CHAMPAGNE's bow, CHAMPAGNE 2.7° off hers, courses 9° off reciprocal), with
``SituationBasis`` "head-on in doubt"; a crossing that such a move would make an overtaking
by one vessel, and by her alone, is that overtaking (rule 13(c), "in any doubt ... assume
that this is the case"), with "overtaking in doubt".
``evaluate_colregs`` also flags a step where either vessel's course is a COG below the speed at
which COG is judged (``[replay] course_judged_above_kn``): her bearings are noise.
``SituationBasis`` records whether it rests on the sectors alone, on rule 14(c) or on the
same-side reading of rule 15. The replay fixes the situation at the trigger and holds it until
the pair is past (rule 13(d)); ``classify`` itself has no memory and also gives the
instantaneous geometry of every step.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass
from enum import StrEnum
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from ..config import dataclass_from_table
from ..errors import ParameterError
from ..geo import course_in_tangent_plane, velocity_mps
from ..units import MPS_PER_KNOT, signed_angle_deg, wrap_deg
from .tracks import CourseSource


class Situation(StrEnum):
    HEAD_ON = "head-on"
    CROSSING = "crossing"
    OVERTAKING = "overtaking"
    NONE = "none"


class SituationBasis(StrEnum):
    """What settled the situation: the sectors alone, or a reading of a doubtful geometry."""

    SECTORS = "sectors"
    HEAD_ON_IN_DOUBT = "head-on in doubt"  # rule 14(c)
    OVERTAKING_IN_DOUBT = "overtaking in doubt"  # rule 13(c)
    SAME_SIDE = "same-side crossing"  # rule 15 names both or neither; see the module docstring
    CHANNEL = "meeting along a charted channel"  # core/channel_audit.py: a bend is no crossing
    NONE = "none"


class Role(StrEnum):
    GIVE_WAY = "give-way"
    STAND_ON = "stand-on"
    NONE = "none"


# Lookup tables that turn integer codes into enum members, vectorised.
_SITUATIONS = np.array(
    [Situation.OVERTAKING, Situation.HEAD_ON, Situation.CROSSING, Situation.NONE], dtype=object
)
_BASES = np.array(
    [
        SituationBasis.SECTORS,
        SituationBasis.HEAD_ON_IN_DOUBT,
        SituationBasis.SAME_SIDE,
        SituationBasis.NONE,
        SituationBasis.OVERTAKING_IN_DOUBT,
    ],
    dtype=object,
)
_ROLES = np.array([Role.GIVE_WAY, Role.STAND_ON, Role.NONE], dtype=object)


@dataclass(frozen=True)
class ColregsParams:
    """The ``[colregs]`` table: sector angles and margins (degrees) and the course source."""

    head_on_half_angle_deg: float = 6.0
    head_on_doubt_deg: float = 22.5
    overtaking_sector_min_deg: float = 112.5
    overtaking_sector_max_deg: float = 247.5
    ambiguity_margin_deg: float = 3.0
    course_source: CourseSource = CourseSource.COG

    def __post_init__(self) -> None:
        theta = self.head_on_half_angle_deg
        if not (math.isfinite(theta) and 0.0 <= theta < 90.0):
            raise ParameterError(
                f"[colregs] head_on_half_angle_deg = {theta!r}: give an angle in [0, 90)"
            )
        doubt = self.head_on_doubt_deg
        if not (math.isfinite(doubt) and theta <= doubt < 90.0):
            raise ParameterError(
                f"[colregs] head_on_doubt_deg = {doubt!r}: give an angle from "
                f"head_on_half_angle_deg ({theta:g}) up to 90"
            )
        low, high = self.overtaking_sector_min_deg, self.overtaking_sector_max_deg
        if not (math.isfinite(low) and math.isfinite(high) and 90.0 < low < 180.0 < high < 270.0):
            raise ParameterError(
                f"[colregs] overtaking sector [{low!r}, {high!r}]: the sector must lie abaft "
                "the beam and contain dead astern, 90 < overtaking_sector_min_deg < 180 < "
                "overtaking_sector_max_deg < 270"
            )
        margin = self.ambiguity_margin_deg
        if not (math.isfinite(margin) and 0.0 <= margin < 45.0):
            raise ParameterError(
                f"[colregs] ambiguity_margin_deg = {margin!r}: give an angle in [0, 45)"
            )


def colregs_params_from_table(table: dict[str, Any], where: str) -> ColregsParams:
    """``ColregsParams`` from a ``[colregs]`` TOML table; ``where`` names it in messages."""
    return dataclass_from_table(ColregsParams, table, where)


@dataclass(frozen=True)
class Kinematics:
    """Vessel states (arrays of equal length, or scalars): position, COG, heading, speed."""

    north_m: ArrayLike
    east_m: ArrayLike
    cog_deg: ArrayLike
    heading_deg: ArrayLike
    speed_mps: ArrayLike

    @classmethod
    def pair_from_series(cls, series: pd.DataFrame) -> tuple[Kinematics, Kinematics]:
        """Own ship and target of an ``encounter_series`` in own ship's tangent plane.

        Own ship sits at the origin; the target at ``rel_north_m``/``rel_east_m`` (true north
        and east at own ship). Courses are true, the target's turned into own ship's plane,
        so that no map frame enters the bearings between the vessels.
        """
        own_lat = series["own_lat_deg"].to_numpy(dtype=float)
        own_lon = series["own_lon_deg"].to_numpy(dtype=float)
        tgt_lat = series["target_lat_deg"].to_numpy(dtype=float)
        tgt_lon = series["target_lon_deg"].to_numpy(dtype=float)

        def target_course(column: str) -> NDArray[np.float64]:
            return course_in_tangent_plane(
                series[column].to_numpy(dtype=float), tgt_lat, tgt_lon, own_lat, own_lon
            )

        zeros = np.zeros(len(series))
        own = cls(
            north_m=zeros,
            east_m=zeros,
            cog_deg=series["own_cog_deg"].to_numpy(dtype=float),
            heading_deg=series["own_heading_deg"].to_numpy(dtype=float),
            speed_mps=series["own_speed_mps"].to_numpy(dtype=float),
        )
        target = cls(
            north_m=series["rel_north_m"].to_numpy(dtype=float),
            east_m=series["rel_east_m"].to_numpy(dtype=float),
            cog_deg=target_course("target_cog_deg"),
            heading_deg=target_course("target_heading_deg"),
            speed_mps=series["target_speed_mps"].to_numpy(dtype=float),
        )
        return own, target

    def course_from_noisy_cog(
        self, source: CourseSource, course_judged_above_kn: float
    ) -> NDArray[np.bool_]:
        """Where the course used is COG at a speed below ``course_judged_above_kn``."""
        speed_kn = np.asarray(self.speed_mps, dtype=float) / MPS_PER_KNOT
        from_cog = np.ones(np.shape(speed_kn), dtype=bool)
        if source is CourseSource.HEADING:
            from_cog = np.isnan(np.asarray(self.heading_deg, dtype=float))
        return np.atleast_1d(from_cog & (speed_kn < course_judged_above_kn))

    def course_deg(self, source: CourseSource) -> NDArray[np.float64]:
        cog = np.asarray(self.cog_deg, dtype=float)
        if source is CourseSource.COG:
            return cog
        heading = np.asarray(self.heading_deg, dtype=float)
        return np.where(np.isnan(heading), cog, heading)


@dataclass(frozen=True)
class ColregsEvaluation:
    """G_a's output per step (arrays of equal length), seen from the own-ship seat."""

    situation: NDArray[np.object_]  # Situation
    own_role: NDArray[np.object_]  # Role
    target_role: NDArray[np.object_]  # Role
    own_overtaking: NDArray[np.bool_]  # True only in overtaking with own ship astern
    ambiguous: NDArray[np.bool_]
    basis: NDArray[np.object_]  # SituationBasis
    beta_deg: NDArray[np.float64]  # target's relative bearing from own ship
    beta_prime_deg: NDArray[np.float64]  # own ship's relative bearing from the target
    closing: NDArray[np.bool_]


def relative_bearing_deg(
    from_north_m: ArrayLike,
    from_east_m: ArrayLike,
    from_course_deg: ArrayLike,
    to_north_m: ArrayLike,
    to_east_m: ArrayLike,
) -> NDArray[np.float64]:
    """Bearing of the point "to" from the vessel "from", relative to her course, in [0, 360)."""
    d_north = np.asarray(to_north_m, dtype=float) - np.asarray(from_north_m, dtype=float)
    d_east = np.asarray(to_east_m, dtype=float) - np.asarray(from_east_m, dtype=float)
    true_bearing_deg = np.degrees(np.arctan2(d_east, d_north))
    return wrap_deg(true_bearing_deg - np.asarray(from_course_deg, dtype=float))


def evaluate_colregs(
    own: Kinematics,
    target: Kinematics,
    params: ColregsParams,
    course_judged_above_kn: float = 0.0,
) -> ColregsEvaluation:
    """G_a: situation and roles for each step of own ship and target (see module docstring).

    A step where either vessel's course is her COG and she is slower than
    ``course_judged_above_kn`` is ambiguous too: her COG is GPS noise there, so the bearings
    that decide the sectors are.
    """
    beta = relative_bearing_deg(
        own.north_m, own.east_m, own.course_deg(params.course_source), target.north_m, target.east_m
    )
    beta_prime = relative_bearing_deg(
        target.north_m,
        target.east_m,
        target.course_deg(params.course_source),
        own.north_m,
        own.east_m,
    )
    own_vn, own_ve = velocity_mps(own.speed_mps, own.cog_deg)
    tgt_vn, tgt_ve = velocity_mps(target.speed_mps, target.cog_deg)
    rel_n = np.asarray(target.north_m, dtype=float) - np.asarray(own.north_m, dtype=float)
    rel_e = np.asarray(target.east_m, dtype=float) - np.asarray(own.east_m, dtype=float)
    closing = (rel_n * (tgt_vn - own_vn) + rel_e * (tgt_ve - own_ve)) < 0.0
    result = classify(beta, beta_prime, closing, params)
    noisy_course = own.course_from_noisy_cog(
        params.course_source, course_judged_above_kn
    ) | target.course_from_noisy_cog(params.course_source, course_judged_above_kn)
    return dataclasses.replace(
        result, ambiguous=result.ambiguous | (noisy_course & (result.situation != Situation.NONE))
    )


@dataclass(frozen=True)
class _Sectors:
    """The situation code (index into ``_SITUATIONS``), who gives way, and the basis code."""

    situation: NDArray[np.int64]
    own_gives_way: NDArray[np.bool_]
    target_gives_way: NDArray[np.bool_]
    basis: NDArray[np.int64]


def _sectors(
    beta: NDArray[np.float64],
    beta_prime: NDArray[np.float64],
    closing: NDArray[np.bool_],
    params: ColregsParams,
) -> _Sectors:
    """The rules of the module docstring on bearings in [0, 360) (NaN: no situation)."""
    known = closing & np.isfinite(beta) & np.isfinite(beta_prime)

    def astern(bearing: NDArray[np.float64]) -> NDArray[np.bool_]:
        return (bearing > params.overtaking_sector_min_deg) & (
            bearing < params.overtaking_sector_max_deg
        )

    def within_of_bow(bearing: NDArray[np.float64], angle_deg: float) -> NDArray[np.bool_]:
        return (bearing <= angle_deg) | (bearing >= 360.0 - angle_deg)

    def side(bearing: NDArray[np.float64]) -> NDArray[np.int64]:
        """+1 starboard, −1 port, 0 on the fore-and-aft line."""
        # An unknown bearing (a vessel at rest without a course) is on neither side.
        sides = np.nan_to_num(np.sign(np.sin(np.radians(bearing))))
        return sides.astype(np.int64) * ((bearing != 0.0) & (bearing != 180.0))

    def off_fore_aft_line(bearing: NDArray[np.float64]) -> NDArray[np.float64]:
        folded = np.mod(bearing, 180.0)
        return np.minimum(folded, 180.0 - folded)

    own_overtakes = known & astern(beta_prime) & ~astern(beta)
    target_overtakes = known & astern(beta) & ~astern(beta_prime)
    overtaking = own_overtakes | target_overtakes
    open_water = known & ~overtaking

    own_side, target_side = side(beta), side(beta_prime)
    opposite = own_side * target_side < 0
    own_distance, target_distance = off_fore_aft_line(beta), off_fore_aft_line(beta_prime)
    head_on_sectors = within_of_bow(beta, params.head_on_half_angle_deg) & within_of_bow(
        beta_prime, params.head_on_half_angle_deg
    )
    doubt = params.head_on_doubt_deg
    near_bow = within_of_bow(beta, doubt), within_of_bow(beta_prime, doubt)
    with np.errstate(invalid="ignore"):
        near_reciprocal = np.abs(signed_angle_deg(beta - beta_prime)) <= doubt
    red_to_red = (own_side < 0) & (target_side < 0)
    in_doubt = ((own_side == target_side) & near_bow[0] & near_bow[1]) | (
        red_to_red & near_reciprocal & (near_bow[0] | near_bow[1])
    )
    tie = ~opposite & (own_distance == target_distance)
    head_on = open_water & (head_on_sectors | in_doubt | tie)
    crossing = open_water & ~head_on

    # The deciding vessel keeps her side; with opposite sides either one decides alike.
    own_decides = opposite | (own_distance > target_distance)
    deciding_side = np.where(own_decides, own_side, target_side)
    own_gives_way_crossing = np.where(own_decides, deciding_side > 0, deciding_side < 0)

    situation = np.select([overtaking, head_on, crossing], [0, 1, 2], default=3)
    own_gives_way = own_overtakes | head_on | (crossing & own_gives_way_crossing)
    target_gives_way = target_overtakes | head_on | (crossing & ~own_gives_way_crossing)
    doubtful_head_on = head_on & ~head_on_sectors
    basis = np.select(
        [~known, doubtful_head_on, crossing & ~opposite], [3, 1, 2], default=0
    ).astype(np.int64)
    return _Sectors(situation, own_gives_way, target_gives_way, basis)


def _in_doubt(
    result: _Sectors,
    could_be_head_on: NDArray[np.bool_],
    could_overtake: tuple[NDArray[np.bool_], NDArray[np.bool_]],
) -> _Sectors:
    """A crossing read as the vessels in doubt must read it (module docstring): head-on
    where a move of the bearings by the margin makes it head-on (rule 14(c)), else an
    overtaking where such a move makes one vessel, and only one, the overtaking one
    (rule 13(c))."""
    crossing = result.situation == 2
    head_on = crossing & could_be_head_on
    own_overtakes, target_overtakes = could_overtake
    overtaking = crossing & ~head_on & (own_overtakes != target_overtakes)
    return _Sectors(
        situation=np.where(head_on, 1, np.where(overtaking, 0, result.situation)),
        own_gives_way=np.where(
            head_on, True, np.where(overtaking, own_overtakes, result.own_gives_way)
        ),
        target_gives_way=np.where(
            head_on, True, np.where(overtaking, target_overtakes, result.target_gives_way)
        ),
        basis=np.where(head_on, 1, np.where(overtaking, 4, result.basis)),
    )


def classify(
    beta_deg: ArrayLike, beta_prime_deg: ArrayLike, closing: ArrayLike, params: ColregsParams
) -> ColregsEvaluation:
    """The pair model of the module docstring on given bearings and closing flags."""
    beta = np.atleast_1d(np.asarray(beta_deg, dtype=float))
    beta_prime = np.atleast_1d(np.asarray(beta_prime_deg, dtype=float))
    closing_now = np.atleast_1d(np.asarray(closing, dtype=bool))
    beta, beta_prime, closing_now = np.broadcast_arrays(beta, beta_prime, closing_now)
    beta, beta_prime = wrap_deg(beta), wrap_deg(beta_prime)
    result = _sectors(beta, beta_prime, closing_now, params)

    ambiguous = np.zeros(result.situation.shape, dtype=bool)
    could_be_head_on = np.zeros(result.situation.shape, dtype=bool)
    could_overtake = (
        np.zeros(result.situation.shape, dtype=bool),
        np.zeros(result.situation.shape, dtype=bool),
    )
    margin = params.ambiguity_margin_deg
    if margin > 0.0:
        for shift, shift_prime in itertools.product((-margin, 0.0, margin), repeat=2):
            if shift == shift_prime == 0.0:
                continue
            moved = _sectors(
                wrap_deg(beta + shift), wrap_deg(beta_prime + shift_prime), closing_now, params
            )
            ambiguous |= (
                (moved.situation != result.situation)
                | (moved.own_gives_way != result.own_gives_way)
                | (moved.target_gives_way != result.target_gives_way)
            )
            # only the head-on sectors themselves: a move into the wider same-bow doubt
            # would stack one tolerance on another (a bearing 2° over the bow, moved across
            # it, put a crossing 19° off the other's bow into the doubt)
            could_be_head_on |= (moved.situation == 1) & (moved.basis == 0)
            could_overtake[0][...] |= (moved.situation == 0) & moved.own_gives_way
            could_overtake[1][...] |= (moved.situation == 0) & moved.target_gives_way
    ambiguous &= result.situation != 3
    result = _in_doubt(result, could_be_head_on, could_overtake)

    def role(gives_way: NDArray[np.bool_]) -> NDArray[np.object_]:
        return _ROLES[np.where(result.situation == 3, 2, np.where(gives_way, 0, 1))]

    own_overtaking = (result.situation == 0) & result.own_gives_way
    return ColregsEvaluation(
        situation=_SITUATIONS[result.situation],
        own_role=role(result.own_gives_way),
        target_role=role(result.target_gives_way),
        own_overtaking=own_overtaking,
        ambiguous=ambiguous,
        basis=_BASES[result.basis],
        beta_deg=beta,
        beta_prime_deg=beta_prime,
        closing=closing_now,
    )
