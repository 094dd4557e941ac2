"""Where each vessel of a pair is with respect to the charted channels, and rule 9(a)
(docs/design.md §5, "Rule 9 and rule 10 from the chart").

For one vessel over a passing (the pair's rows from the trigger, ``charts.channel_facts``
at each):

- her place at the trigger and at the least separation: the channel she is in (its name,
  else its class and record id), whether she proceeds along it or crosses it, and her
  offset from its axis, positive to her starboard;
- rule 9(a), "a vessel proceeding along the course of a narrow channel or fairway shall keep
  as near to the outer limit of the channel or fairway which lies on her starboard side as
  is safe and practicable": judged, like the other audit facts, from the trigger to the
  closest approach, on the rows where she proceeds along a channel. ``true`` when she is in
  its starboard half (offset > 0) for at least ``starboard_share`` of them; ``false`` when
  less; ``insufficient-data`` when she proceeds along one for less than
  ``starboard_min_s``, or the data stop before the closest approach; empty when she never
  proceeds along a channel there (the rule does not apply). The offset is taken from the
  axis, so a channel whose axis is its charted ORIENT through the middle, or its derived
  centreline, divides it into halves. What is "safe and practicable" for a deep-draught
  vessel confined to the dredged middle is not judged: read a ``false`` for her against her
  navigable width (``colregs9 chart --draught``).

Rule 9(b)'s "a vessel which can safely navigate only within a narrow channel or fairway",
for a vessel proceeding along a channel at the trigger: ``confinement.py`` judges it over
the same rows; ``rule9.decide_pair`` takes it as d3 beside the estimator.

Rule 10 where a traffic separation scheme is charted (``TSSLPT`` lanes with their
``ORIENT``), over the same rows:

- 10(b)(i), "proceed in the appropriate traffic lane in the general direction of traffic
  flow for that lane": on the rows she proceeds along a lane, ``true`` when she goes its
  ``ORIENT`` way on all but ``1 - starboard_side_share`` of them, else ``false``;
- 10(c), "cross on a heading as nearly as practicable at right angles to the general
  direction of traffic flow": on the rows she crosses a lane (at ``channel_crossing_from_deg``
  or more), ``true`` when her median heading (her COG where she reports none) is within
  ``lane_crossing_within_deg`` (15°) of a right angle to the lane, else ``false``;

each empty where she is in no lane, with its basis.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..charts.channel_facts import ChannelFacts, ChannelParams, ChannelRelation, channel_facts
from ..charts.channels import Channels
from ..charts.s57_classes import ChannelKind
from ..errors import ParameterError
from ..units import signed_angle_deg, wrap_deg
from .audit import Fact
from .confinement import (
    NO_CHART,
    NOT_ALONG,
    ConfinedToChannel,
    ConfinementParams,
    DraughtOnChart,
    confined_to_channel,
)


@dataclass(frozen=True)
class ChannelAuditParams:
    """The angles of ``charts.channel_facts.ChannelParams`` (along within 30°, crossing from
    45°: its docstring gives the reasons) and rule 9(a)'s thresholds: in the starboard half
    for ``starboard_side_share`` (0.8) of the rows she proceeds along a channel, judged
    when those last ``starboard_side_min_s`` (30 s: a speed span, so that a vessel only
    turning through a channel is not judged on it); rule 10(c): a lane crossed within
    ``lane_crossing_within_deg`` (15°) of a right angle, half the 30° that "along" allows,
    as "as nearly as practicable" asks more than a course along; and the thresholds of
    ``confinement.ConfinementParams``. ``[replay]`` keys of the same names."""

    channel_along_within_deg: float = 30.0
    channel_crossing_from_deg: float = 45.0
    starboard_side_share: float = 0.8
    starboard_side_min_s: float = 30.0
    lane_crossing_within_deg: float = 15.0
    channel_confined_within_lengths: float = ConfinementParams.within_lengths
    channel_narrow_within_lengths: float = ConfinementParams.narrow_within_lengths

    def __post_init__(self) -> None:
        if not 0.5 <= self.starboard_side_share <= 1.0:
            raise ParameterError(
                f"[replay] starboard_side_share = {self.starboard_side_share!r}: give a share "
                "from 0.5 to 1"
            )
        if not (np.isfinite(self.starboard_side_min_s) and self.starboard_side_min_s >= 0.0):
            raise ParameterError(
                f"[replay] starboard_side_min_s = {self.starboard_side_min_s!r}: give seconds >= 0"
            )
        if not 0.0 <= self.lane_crossing_within_deg <= 45.0:
            raise ParameterError(
                f"[replay] lane_crossing_within_deg = {self.lane_crossing_within_deg!r}: give "
                "0 to 45 degrees"
            )
        self.angles()  # the angles are checked there
        self.confinement()  # and the confinement's thresholds there

    def confinement(self) -> ConfinementParams:
        return ConfinementParams(
            self.channel_confined_within_lengths, self.channel_narrow_within_lengths
        )

    def angles(self) -> ChannelParams:
        return ChannelParams(self.channel_along_within_deg, self.channel_crossing_from_deg)


@dataclass(frozen=True)
class ChannelPlace:
    """A vessel's place at one moment: the channel (None: in none), how her course lies to
    it, and her offset from its axis (+ to her starboard; None outside or with no course)."""

    channel: str | None
    relation: ChannelRelation
    offset_m: float | None


OUTSIDE = ChannelPlace(None, ChannelRelation.OUTSIDE, None)


@dataclass(frozen=True)
class StarboardSide:
    """Rule 9(a) for one vessel (module docstring): the fact (None: not along a channel) and
    what it was judged on."""

    fact: Fact | None
    basis: str


@dataclass(frozen=True)
class LaneConduct:
    """Rule 10(b)(i) and 10(c) for one vessel (module docstring); None where she is in no
    traffic lane."""

    follows_lane: Fact | None
    crosses_at_right_angles: Fact | None
    basis: str


NO_LANE = LaneConduct(None, None, "in no traffic lane")


@dataclass(frozen=True)
class VesselInChannel:
    """One vessel of a pair and the charted channels over the passing."""

    at_trigger: ChannelPlace
    at_least_separation: ChannelPlace
    keeps_to_starboard_side: StarboardSide
    lane: LaneConduct = NO_LANE
    confined: ConfinedToChannel = NO_CHART
    # From the trigger to the closest approach: how far the axis of the channel she
    # proceeds along has turned since the trigger (0 where she is not along the one she was
    # along at the trigger), so that a turn that follows a bend is not an action.
    bend_deg: np.ndarray = field(default_factory=lambda: np.zeros(0), compare=False)


NOT_CHARTED = VesselInChannel(
    OUTSIDE, OUTSIDE, StarboardSide(None, "no chart"), LaneConduct(None, None, "no chart")
)


def _place(channels: Channels, facts: ChannelFacts, row: int) -> ChannelPlace:
    index = int(facts.channel[row])
    if index < 0:
        return OUTSIDE
    offset = float(facts.offset_m[row])
    return ChannelPlace(
        channels[index].label,
        ChannelRelation(facts.relation[row]),
        offset if np.isfinite(offset) else None,
    )


def starboard_side(
    facts: ChannelFacts,
    channels: Channels,
    rows: slice,
    step_s: float,
    covers_cpa: bool,
    params: ChannelAuditParams,
) -> StarboardSide:
    """Rule 9(a) over ``rows`` (the trigger to the closest approach) of ``facts``."""
    along = facts.relation[rows] == ChannelRelation.ALONG
    if not along.any():
        return StarboardSide(None, NOT_ALONG)
    offsets = facts.offset_m[rows][along]
    fractions = facts.offset_fraction[rows][along]
    names = sorted({channels[int(i)].label for i in facts.channel[rows][along]})
    along_s = float(along.sum()) * step_s
    share = float(np.mean(offsets > 0.0))
    basis = (
        f"along {', '.join(names)} for {along_s:.0f} s, in its starboard half {share:.0%} of "
        f"that time, offset {np.median(offsets):+.0f} m from the axis (median; "
        f"{np.nanmedian(fractions):+.2f} of the half-width)"
    )
    if along_s < params.starboard_side_min_s or not covers_cpa:
        reason = "the data end before the closest approach" if not covers_cpa else "too short"
        return StarboardSide(Fact.INSUFFICIENT, f"{basis}: {reason}")
    return StarboardSide(Fact.of(share >= params.starboard_side_share), basis)


def lane_conduct(
    facts: ChannelFacts,
    channels: Channels,
    heading_grid_deg: np.ndarray,
    step_s: float,
    params: ChannelAuditParams,
) -> LaneConduct:
    """Rule 10(b)(i) and 10(c) over the rows of ``facts`` (the trigger to the closest
    approach); ``heading_grid_deg`` her heading at each (her COG where none)."""
    in_lane = np.array(
        [i >= 0 and channels[int(i)].kind is ChannelKind.TSS_LANE for i in facts.channel]
    )
    if not in_lane.any():
        return NO_LANE
    parts = []
    along = in_lane & (facts.relation == ChannelRelation.ALONG)
    follows: Fact | None = None
    if along.any():
        against = float(np.mean(facts.against_traffic[along]))
        follows = Fact.of(against <= 1.0 - params.starboard_side_share)
        parts.append(
            f"along a lane for {along.sum() * step_s:.0f} s, against its ORIENT {against:.0%} "
            "of that time"
        )
    crossing = in_lane & (facts.relation == ChannelRelation.CROSSING)
    square: Fact | None = None
    if crossing.any():
        axis = facts.axis_grid_deg[crossing]
        to_axis = np.abs(wrap_deg(heading_grid_deg[crossing] - axis + 180.0) - 180.0)
        off_square = float(np.nanmedian(np.abs(90.0 - to_axis)))
        square = Fact.of(off_square <= params.lane_crossing_within_deg)
        parts.append(
            f"crossing a lane for {crossing.sum() * step_s:.0f} s, heading {off_square:.0f}° "
            "from a right angle to it (median)"
        )
    return LaneConduct(
        follows, square, "; ".join(parts) or "in a lane, neither along it nor crossing it"
    )


def vessel_in_channel(
    window: pd.DataFrame,
    prefix: str,
    channels: Channels | None,
    cpa_row: int | None,
    covers_cpa: bool,
    step_s: float,
    params: ChannelAuditParams,
    draught: DraughtOnChart,
) -> VesselInChannel:
    """One vessel (``prefix`` of the pair's series) over ``window`` (rows from the trigger):
    her places at the trigger (row 0) and at the least separation (``cpa_row``), rule 9(a)
    up to it, and whether her ``draught`` confines her to the narrow channel she proceeds
    along at the trigger (``confinement.py``)."""
    if channels is None or window.empty:
        return NOT_CHARTED
    last = len(window) - 1 if cpa_row is None else cpa_row
    rows = window.iloc[: last + 1]
    facts = channel_facts(
        channels,
        rows[f"{prefix}north_m"].to_numpy(dtype=float),
        rows[f"{prefix}east_m"].to_numpy(dtype=float),
        rows[f"{prefix}cog_grid_deg"].to_numpy(dtype=float),
        params.angles(),
    )
    return VesselInChannel(
        at_trigger=_place(channels, facts, 0),
        at_least_separation=OUTSIDE if cpa_row is None else _place(channels, facts, cpa_row),
        keeps_to_starboard_side=starboard_side(
            facts, channels, slice(0, last + 1), step_s, covers_cpa and cpa_row is not None, params
        ),
        lane=lane_conduct(facts, channels, _heading_grid_deg(rows, prefix), step_s, params),
        confined=confined_to_channel(
            channels,
            facts,
            rows[f"{prefix}north_m"].to_numpy(dtype=float),
            rows[f"{prefix}east_m"].to_numpy(dtype=float),
            draught,
            params.confinement(),
        ),
        bend_deg=channel_bend_deg(facts),
    )


def channel_bend_deg(facts: ChannelFacts) -> np.ndarray:
    """At each row, how far the local axis (turned to her way) of the channel she proceeds
    along at the first row has turned since then, while she still proceeds along it; 0
    elsewhere."""
    bend = np.zeros(len(facts.channel))
    if not len(bend) or facts.relation[0] != ChannelRelation.ALONG:
        return bend
    along = (facts.relation == ChannelRelation.ALONG) & (facts.channel == facts.channel[0])
    turned = signed_angle_deg(facts.axis_grid_deg - facts.axis_grid_deg[0])
    bend[along] = np.nan_to_num(turned[along])
    return bend


def _heading_grid_deg(rows: pd.DataFrame, prefix: str) -> np.ndarray:
    heading = rows[f"{prefix}heading_grid_deg"].to_numpy(dtype=float)
    return np.where(np.isfinite(heading), heading, rows[f"{prefix}cog_grid_deg"].to_numpy(float))


def meeting_along_a_channel(
    vessels: tuple[VesselInChannel, VesselInChannel], courses_deg: tuple[float, float]
) -> bool:
    """Whether the two vessels proceed along the same charted channel in opposite
    directions at the trigger (courses over ground more than 90° apart, each within the
    along tolerance of the axis): they meet, whatever the channel's bends make of their
    bearings, and a crossing is read as head-on (rule 14; rule 9(a) keeps each to her
    starboard side)."""
    a, b = (v.at_trigger for v in vessels)
    along = a.relation is ChannelRelation.ALONG and b.relation is ChannelRelation.ALONG
    apart_deg = abs(float(signed_angle_deg(courses_deg[0] - courses_deg[1])))
    return along and a.channel is not None and a.channel == b.channel and apart_deg > 90.0
