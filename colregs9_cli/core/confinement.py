"""Whether a vessel's draught confines her to the narrow channel she proceeds along: rule
9(b) and (c)'s "a vessel which can safely navigate only within a narrow channel or fairway",
read from the chart (docs/design.md, "Charted channels in replay").

She is judged at stations along her own track from the trigger to the closest approach, on
the rows where she proceeds along the charted channel she proceeds along at the trigger (at
most ``MAX_STATIONS``, evenly spaced, the trigger first): at each, on the section square to
the channel's axis (``charts.channel_confinement``),

- *confined* when the water navigable for her draught plus the UKC reaches less than
  ``within_lengths`` (1) of her lengths beyond the channel's limits on both hands, and the
  channel's width navigable for her is under ``narrow_within_lengths`` (5) of her lengths;
- *open* when it reaches that far on either hand, or the channel is that wide for her;
- unknown otherwise (her position not navigable for her on the chart, water that runs to
  the chart's edge).

``true`` when she is confined at more than half of the stations judged, ``false`` when
not; ``insufficient-data`` without a reported draught and length (a default draught is no
evidence of one), without the chart's depths, or with no station judged. Several stations
rather than her position at the trigger alone, so that one wreck abeam, or one slip between
piers, does not decide.

The thresholds are conventions, stated: room of one ship's length outside the limit lets
her leave the channel to let another pass; a channel five lengths wide (IMO MSC.137(76)'s
limit on the tactical diameter) lets her turn round in it, so that it is not narrow for
her. The position is her AIS antenna's: a hull over the bank of a cut barely wider than
she is reads as off the navigable water, and that station as unknown.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..charts.channel_confinement import water_beyond_limits
from ..charts.channel_facts import ChannelFacts, ChannelRelation
from ..charts.channels import Channels
from ..charts.water import Chart
from ..errors import ParameterError
from .audit import Fact
from .vessel_defaults import VesselDimensions

MAX_STATIONS = 9
NOT_ALONG = "not proceeding along a charted channel"


@dataclass(frozen=True)
class ConfinementParams:
    """The module docstring's thresholds, in her lengths (``[replay]``
    ``channel_confined_within_lengths`` and ``channel_narrow_within_lengths``)."""

    within_lengths: float = 1.0
    narrow_within_lengths: float = 5.0

    def __post_init__(self) -> None:
        for key, value in (
            ("channel_confined_within_lengths", self.within_lengths),
            ("channel_narrow_within_lengths", self.narrow_within_lengths),
        ):
            if not (np.isfinite(value) and value > 0.0):
                raise ParameterError(
                    f"[replay] {key} = {value!r}: give a number of her lengths > 0"
                )


@dataclass(frozen=True)
class DraughtOnChart:
    """What the confinement of a vessel reads besides her track: the chart's depths (None:
    no chart), her dimensions and the under-keel clearance she keeps."""

    chart: Chart | None
    dimensions: VesselDimensions
    ukc_m: float


@dataclass(frozen=True)
class ConfinedToChannel:
    """The module docstring's fact (None: not along a channel at the trigger) and what it was
    judged on."""

    fact: Fact | None
    basis: str


NO_CHART = ConfinedToChannel(None, "no chart")


def confined_to_channel(
    channels: Channels,
    facts: ChannelFacts,
    north_m: np.ndarray,
    east_m: np.ndarray,
    draught: DraughtOnChart,
    params: ConfinementParams,
) -> ConfinedToChannel:
    """The fact for a vessel whose positions ``north_m``, ``east_m`` (the trigger first, to
    the closest approach) have the channel ``facts`` of the same rows."""
    if facts.relation[0] != ChannelRelation.ALONG:
        return ConfinedToChannel(None, NOT_ALONG)
    label = channels[int(facts.channel[0])].label
    dimensions, ukc_m = draught.dimensions, draught.ukc_m
    missing = [n.removesuffix("_m") for n in ("draught_m", "length_m") if n in dimensions.defaulted]
    if missing:
        return ConfinedToChannel(
            Fact.INSUFFICIENT, f"along {label}; her {' and '.join(missing)} not reported"
        )
    if draught.chart is None:
        return ConfinedToChannel(Fact.INSUFFICIENT, f"along {label}; no depths charted")
    # Along the channel she was along at the trigger, as the bend of its axis is followed.
    along = np.flatnonzero(
        (facts.relation == ChannelRelation.ALONG) & (facts.channel == facts.channel[0])
    )
    stations = along[np.unique(np.linspace(0, len(along) - 1, MAX_STATIONS).round().astype(int))]
    within_m = params.within_lengths * dimensions.length_m
    narrow_m = params.narrow_within_lengths * dimensions.length_m
    water = water_beyond_limits(
        channels,
        draught.chart,
        north_m[stations],
        east_m[stations],
        facts.axis_grid_deg[stations],
        dimensions.draught_m,
        ukc_m,
        within_m,
    )
    port_m, starboard_m, width_m = water.port_m, water.starboard_m, water.navigable_width_m
    opens = (port_m >= within_m) | (starboard_m >= within_m) | (width_m >= narrow_m)
    shut = (port_m < within_m) & (starboard_m < within_m) & (width_m < narrow_m)
    judged = int(opens.sum() + shut.sum())
    depth = f"her draught {dimensions.draught_m:g} m + UKC {ukc_m:g} m"
    head = f"along {label}, at {len(stations)} stations from the trigger to the closest approach"
    if judged == 0:
        why = (
            "her positions are not in water navigable for"
            if not water.held.any()
            else "the water navigable for it runs to the chart's edge at"
        )
        return ConfinedToChannel(Fact.INSUFFICIENT, f"{head}: {why} {depth}")
    known = opens | shut
    basis = (
        f"{head}: confined at {int(shut.sum())} of the {judged} judged; the water navigable "
        f"for {depth} reaches a median {_room(port_m[known], within_m)} beyond its port-hand "
        f"limit and {_room(starboard_m[known], within_m)} beyond its starboard-hand limit, "
        f"the channel {np.nanmedian(width_m[known]):.0f} m wide for her (confined: under "
        f"{_metres(within_m)} beyond both, {params.within_lengths:g}× her length, in a channel "
        f"under {_metres(narrow_m)}, {params.narrow_within_lengths:g}× her length)"
    )
    return ConfinedToChannel(Fact.of(2 * int(shut.sum()) > judged), basis)


def _room(beyond_m: np.ndarray, within_m: float) -> str:
    """The median room on one hand, as the basis gives it: unknown where every station's is."""
    if not np.isfinite(beyond_m).any():
        return "(to the chart's edge)"
    median_m = float(np.nanmedian(beyond_m))
    return f"{_metres(within_m)} or more" if median_m >= within_m else _metres(median_m)


def _metres(value_m: float) -> str:
    """A distance as the basis gives it: to the metre, or to two figures under 10 m (a
    threshold of a small fraction of her length is not "0 m")."""
    return f"{value_m:.0f} m" if value_m >= 10.0 else f"{value_m:.2g} m"
