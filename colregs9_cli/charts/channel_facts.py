"""Where each vessel is with respect to the charted channels: pure functions over arrays.

For positions (run frame, ``north_m, east_m``) and grid courses, ``channel_facts`` gives

- the channel area each position is in (``Channels.channel_at``; -1 outside);
- whether she proceeds along it or crosses it (``ChannelRelation``), from the angle between
  her course and the channel's local axis (an undirected line, so both directions count as
  along; a bend gives the bend's direction);
- her signed offset from the axis, positive to her starboard: measured square to the axis
  and counted positive on the side that is starboard for a vessel going the way she goes
  along it, so that keeping to the starboard side of a channel is positive in either
  direction of travel; and the channel's half-width there, and the distance to its limit on
  her starboard hand, along the same section.

Tolerances (``ChannelParams``). *Along* within 30° of the axis: a vessel keeping a channel
makes good a course within a few degrees of it, plus a drift angle where wind or current
set her across (PIANC WG 121, *Harbour approach channels: design guidelines*, 2014, widens
a channel for this drift; it is a few degrees, rarely above 10–15°), and a yaw; at 30° she
still makes good cos 30° ≈ 0.87 of her speed along it. *Crossing* from 45°: she then makes
more way across the channel than along it (sin ≥ cos). Between the two she is neither
(``oblique``): turning into or out of the channel, or cutting a corner. Rule 10(c) asks a
vessel crossing a traffic lane to do so "on a heading as nearly as practicable at right
angles"; how near she came is the angle, kept in ``angle_to_axis_deg``.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import ParameterError
from ..units import wrap_deg
from .channels import Channels, line_angle_deg


class ChannelRelation(StrEnum):
    """How a vessel's course lies to the channel she is in."""

    OUTSIDE = "outside"  # in no charted channel area
    ALONG = "along"  # within along_within_deg of the axis, either way
    CROSSING = "crossing"  # crossing_from_deg or more from the axis
    OBLIQUE = "oblique"  # in between
    UNKNOWN = "unknown"  # in a channel, but no course (or no axis direction there)


@dataclass(frozen=True)
class ChannelParams:
    """The angles that tell along from crossing (module docstring)."""

    along_within_deg: float = 30.0
    crossing_from_deg: float = 45.0

    def __post_init__(self) -> None:
        if not (0.0 <= self.along_within_deg < self.crossing_from_deg <= 90.0):
            raise ParameterError(
                f"channel tolerances along_within_deg {self.along_within_deg} and "
                f"crossing_from_deg {self.crossing_from_deg}: give 0 <= along_within_deg < "
                "crossing_from_deg <= 90 (degrees from the channel's axis)"
            )


@dataclass(frozen=True)
class ChannelFacts:
    """Per position (arrays of one length): the channel (index into ``Channels``, -1
    outside), how her course lies to it, the angle to its axis (0–90°), the axis's grid
    direction turned to the way she goes along it, her offset from the axis (+ to her
    starboard), the channel's half-width across the axis at her position, the distance from
    her to its limit on her starboard hand, and whether she goes against a one-way channel's
    charted direction. With a draught, ``navigable_width_m`` is the width across the axis of
    the channel's water navigable for it; NaN otherwise. NaN or ``False`` where they do not
    apply."""

    channel: NDArray[np.int64]
    relation: NDArray[np.object_]
    angle_to_axis_deg: NDArray[np.float64]
    axis_grid_deg: NDArray[np.float64]
    offset_m: NDArray[np.float64]
    half_width_m: NDArray[np.float64]
    starboard_limit_m: NDArray[np.float64]
    against_traffic: NDArray[np.bool_]
    navigable_width_m: NDArray[np.float64]

    @property
    def offset_fraction(self) -> NDArray[np.float64]:
        """The offset as a fraction of the half-width: 1 on the starboard-hand limit (for an
        axis in the middle of the section), -1 on the port-hand one."""
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.offset_m / self.half_width_m


def channel_facts(
    channels: Channels,
    north_m: ArrayLike,
    east_m: ArrayLike,
    course_grid_deg: ArrayLike,
    params: ChannelParams | None = None,
    draught_m: float | None = None,
    ukc_m: float = 0.0,
) -> ChannelFacts:
    """The channel facts (``ChannelFacts``) of vessels at these positions on these grid
    courses (NaN: no course)."""
    params = params or ChannelParams()
    north = np.atleast_1d(np.asarray(north_m, dtype=float))
    east = np.atleast_1d(np.asarray(east_m, dtype=float))
    course = np.broadcast_to(np.asarray(course_grid_deg, dtype=float), north.shape)
    channel = channels.channel_at(north, east)
    inside = channel >= 0
    axis = channels.axis_at(north, east, channel)
    angle = line_angle_deg(course, axis.direction_grid_deg)
    # The axis turned to the way she goes: within 90° of her course (a right angle: as drawn).
    reverse = np.abs(wrap_deg(course - axis.direction_grid_deg + 180.0) - 180.0) > 90.0
    sense = np.where(reverse, -1.0, 1.0)
    her_axis = np.where(reverse, wrap_deg(axis.direction_grid_deg + 180.0), axis.direction_grid_deg)
    sections = channels.sections(north, east, channel, axis.direction_grid_deg)
    her_sections = channels.sections(north, east, channel, her_axis)
    relation = np.array([ChannelRelation.OUTSIDE] * len(north), dtype=object)
    known = inside & np.isfinite(angle)
    relation[inside & ~known] = ChannelRelation.UNKNOWN
    relation[known & (angle <= params.along_within_deg)] = ChannelRelation.ALONG
    relation[known & (angle >= params.crossing_from_deg)] = ChannelRelation.CROSSING
    middle = known & (angle > params.along_within_deg) & (angle < params.crossing_from_deg)
    relation[middle] = ChannelRelation.OBLIQUE
    against = np.zeros(len(north), dtype=bool)
    for index in np.unique(channel[inside]):
        item = channels[int(index)]
        if item.one_way and item.orient_deg is not None:
            rows = (channel == index) & (relation == ChannelRelation.ALONG)
            lat_deg, lon_deg = channels.frame.to_geodetic(north[rows], east[rows])
            flow = channels.frame.true_to_grid_deg(item.orient_deg, lat_deg, lon_deg)
            against[rows] = np.abs(wrap_deg(course[rows] - flow + 180.0) - 180.0) > 90.0
    navigable = (
        channels.width_m_at(north, east, channel, draught_m, ukc_m)
        if draught_m is not None
        else np.full(len(north), np.nan)
    )
    return ChannelFacts(
        channel=channel,
        relation=relation,
        angle_to_axis_deg=np.where(inside, angle, np.nan),
        axis_grid_deg=np.where(inside & np.isfinite(course), her_axis, np.nan),
        offset_m=np.where(np.isfinite(course), sense * axis.across_m, np.nan),
        half_width_m=sections.width_m / 2.0,
        starboard_limit_m=np.where(np.isfinite(course), her_sections.right_m, np.nan),
        against_traffic=against,
        navigable_width_m=navigable,
    )
