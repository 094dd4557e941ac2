"""COLREGs rules 13–15: the situation and the roles (the paper's automaton G_a, DESIGN §5).

Angles: β is the relative bearing of the target from own ship and β' that of own ship from
the target, each measured clockwise from the observer's course, in [0, 360). The course is
COG or heading (``ColregsParams.course_source``). "Closing" means the range is decreasing:
``p·v < 0`` for the target's relative position p and relative velocity v (over ground).

The rules, in order of precedence (all sector bounds inclusive; the parameter ranges keep the
head-on and overtaking sectors apart, so only "none first" and "crossing last" matter):

1. **none**: not closing (range opening or steady, or unknown motion). Roles: none.
2. **overtaking**: one vessel is in the other's astern sector
   [``overtaking_sector_min_deg``, ``overtaking_sector_max_deg``] (default 112.5°–247.5°,
   "more than 22.5° abaft her beam") while the other is not in hers. The vessel coming up
   from astern gives way (rule 13), the other stands on. ``own_overtaking`` says which.
3. **head-on**: each is within ±``head_on_half_angle_deg`` of the other's bow (β and β' in
   [360−θ, 360) ∪ [0, θ]). Both give way (rule 14).
4. **crossing**: everything else (also two vessels each in the other's astern sector). Each
   vessel gives way when the other is on her starboard side (rule 15): bearing in (0°, 180°).
   Dead ahead (0°) and dead astern (180°) are not a side; a vessel with the other exactly
   there gives way unless she herself is on the other's starboard side. So exactly one vessel
   gives way in an ordinary crossing; two vessels passing starboard to starboard (each on the
   other's starboard side) both give way, and two passing port to port both stand on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from .config import dataclass_from_table
from .encounters import velocity_mps
from .errors import ParameterError
from .replay_params import CourseSource
from .units import wrap_deg


class Situation(StrEnum):
    HEAD_ON = "head-on"
    CROSSING = "crossing"
    OVERTAKING = "overtaking"
    NONE = "none"


class Role(StrEnum):
    GIVE_WAY = "give-way"
    STAND_ON = "stand-on"
    NONE = "none"

    def inverted(self) -> Role:
        """Give-way ↔ stand-on (rule 9's inversion); none stays none."""
        return _INVERSE_ROLE[self]


# Lookup tables that turn integer codes into enum members, vectorised.
_SITUATIONS = np.array(
    [Situation.OVERTAKING, Situation.HEAD_ON, Situation.CROSSING, Situation.NONE], dtype=object
)
_ROLES = np.array([Role.GIVE_WAY, Role.STAND_ON, Role.NONE], dtype=object)
_INVERSE_ROLE = {Role.GIVE_WAY: Role.STAND_ON, Role.STAND_ON: Role.GIVE_WAY, Role.NONE: Role.NONE}


@dataclass(frozen=True)
class ColregsParams:
    """The ``[colregs]`` table: sector angles (degrees) and the course source."""

    head_on_half_angle_deg: float = 6.0
    overtaking_sector_min_deg: float = 112.5
    overtaking_sector_max_deg: float = 247.5
    course_source: CourseSource = CourseSource.COG

    def __post_init__(self) -> None:
        theta = self.head_on_half_angle_deg
        if not (math.isfinite(theta) and 0.0 <= theta < 90.0):
            raise ParameterError(
                f"[colregs] head_on_half_angle_deg = {theta!r}: give an angle in [0, 90)"
            )
        low, high = self.overtaking_sector_min_deg, self.overtaking_sector_max_deg
        if not (math.isfinite(low) and math.isfinite(high) and 90.0 < low < 180.0 < high < 270.0):
            raise ParameterError(
                f"[colregs] overtaking sector [{low!r}, {high!r}]: the sector must lie abaft "
                "the beam and contain dead astern, 90 < overtaking_sector_min_deg < 180 < "
                "overtaking_sector_max_deg < 270"
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
    def from_frame(cls, frame: pd.DataFrame, prefix: str) -> Kinematics:
        """From columns ``<prefix>north_m`` … (e.g. ``encounter_series`` with ``own_``).

        Courses are taken in the frame's grid north (``<prefix>cog_grid_deg``), because the
        bearings between vessels are measured on grid positions; true courses would put every
        sector boundary off by the meridian convergence.
        """
        return cls(
            north_m=frame[f"{prefix}north_m"].to_numpy(dtype=float),
            east_m=frame[f"{prefix}east_m"].to_numpy(dtype=float),
            cog_deg=frame[f"{prefix}cog_grid_deg"].to_numpy(dtype=float),
            heading_deg=frame[f"{prefix}heading_grid_deg"].to_numpy(dtype=float),
            speed_mps=frame[f"{prefix}speed_mps"].to_numpy(dtype=float),
        )

    def course_deg(self, source: CourseSource) -> NDArray[np.float64]:
        cog = np.asarray(self.cog_deg, dtype=float)
        if source is CourseSource.COG:
            return cog
        heading = np.asarray(self.heading_deg, dtype=float)
        return np.where(np.isnan(heading), cog, heading)


@dataclass(frozen=True)
class ColregsEvaluation:
    """G_a's output per step (arrays of equal length)."""

    situation: NDArray[np.object_]  # Situation
    own_role: NDArray[np.object_]  # Role
    target_role: NDArray[np.object_]  # Role
    own_overtaking: NDArray[np.bool_]  # True only in overtaking with own ship astern
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
    own: Kinematics, target: Kinematics, params: ColregsParams
) -> ColregsEvaluation:
    """G_a: situation and roles for each step of own ship and target (see module docstring)."""
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
    return classify(beta, beta_prime, closing, params)


def classify(
    beta_deg: ArrayLike, beta_prime_deg: ArrayLike, closing: ArrayLike, params: ColregsParams
) -> ColregsEvaluation:
    """The rules of the module docstring on given bearings and closing flags."""
    beta = np.atleast_1d(np.asarray(beta_deg, dtype=float))
    beta_prime = np.atleast_1d(np.asarray(beta_prime_deg, dtype=float))
    closing_now = np.atleast_1d(np.asarray(closing, dtype=bool))
    beta, beta_prime, closing_now = np.broadcast_arrays(beta, beta_prime, closing_now)

    def astern(bearing: NDArray[np.float64]) -> NDArray[np.bool_]:
        return (bearing >= params.overtaking_sector_min_deg) & (
            bearing <= params.overtaking_sector_max_deg
        )

    def near_bow(bearing: NDArray[np.float64]) -> NDArray[np.bool_]:
        theta = params.head_on_half_angle_deg
        return (bearing <= theta) | (bearing >= 360.0 - theta)

    def gives_way_crossing(
        bearing: NDArray[np.float64], other_bearing: NDArray[np.float64]
    ) -> NDArray[np.bool_]:
        def on_starboard(b: NDArray[np.float64]) -> NDArray[np.bool_]:
            return (b > 0.0) & (b < 180.0)

        on_fore_aft_line = (bearing == 0.0) | (bearing == 180.0)
        return on_starboard(bearing) | (on_fore_aft_line & ~on_starboard(other_bearing))

    own_overtakes = closing_now & astern(beta_prime) & ~astern(beta)
    target_overtakes = closing_now & astern(beta) & ~astern(beta_prime)
    overtaking = own_overtakes | target_overtakes
    head_on = closing_now & ~overtaking & near_bow(beta) & near_bow(beta_prime)
    crossing = closing_now & ~overtaking & ~head_on

    situation_code = np.select([overtaking, head_on, crossing], [0, 1, 2], default=3)
    own_gives_way = own_overtakes | head_on | (crossing & gives_way_crossing(beta, beta_prime))
    target_gives_way = (
        target_overtakes | head_on | (crossing & gives_way_crossing(beta_prime, beta))
    )

    def role(gives_way: NDArray[np.bool_]) -> NDArray[np.object_]:
        return _ROLES[np.where(closing_now, np.where(gives_way, 0, 1), 2)]

    return ColregsEvaluation(
        situation=_SITUATIONS[situation_code],
        own_role=role(own_gives_way),
        target_role=role(target_gives_way),
        own_overtaking=own_overtakes,
        beta_deg=beta,
        beta_prime_deg=beta_prime,
        closing=closing_now,
    )
