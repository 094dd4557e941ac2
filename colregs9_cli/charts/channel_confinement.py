"""Whether a vessel's draught confines her to the charted channel she proceeds along: rule
9(b) and (c)'s "a vessel which can safely navigate only within a narrow channel or fairway".

Through her position, square to the channel's local axis, the section is cut twice: by the
channel's area (its limits on her port and starboard hands) and by the chart's water
navigable for her draught plus an under-keel clearance (``Chart.navigable_water``: the depth
areas at least that deep, less land and the hazards that block). The piece of navigable water
that holds her ends somewhere on each side; how far that is beyond the channel's limit is the
room she has outside the channel on that side (0 where the water ends at or inside the
limit, as where the dredged cut is the only deep water). She can safely navigate only within
the channel when that room is less than ``within_m`` on both sides: the caller passes her
length, as a vessel cannot turn, or even lie, in less water than that.

A side is unknown (NaN) where the navigable water ends at the edge of the chart's coverage
(what lies beyond is not charted here), and both are unknown where her position itself is
not in water the chart gives as navigable for her draught (the chart or the draught is
wrong there, and neither can be judged).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .channels import Channels, section_extents
from .water import Chart

# A point this far past where the navigable water ends tells whether it ended inside the
# chart's coverage (charted shoal, land or hazard) or at its edge.
_PAST_THE_END_M = 1.0


@dataclass(frozen=True)
class WaterBeyondLimits:
    """Per position: the navigable water beyond the channel's limit on her port and on her
    starboard hand (capped at the ``within_m`` asked; NaN unknown, module docstring), and
    the channel's limits from her (NaN outside a channel or without a direction)."""

    port_m: NDArray[np.float64]
    starboard_m: NDArray[np.float64]
    channel_port_m: NDArray[np.float64]
    channel_starboard_m: NDArray[np.float64]


def water_beyond_limits(
    channels: Channels,
    chart: Chart,
    north_m: ArrayLike,
    east_m: ArrayLike,
    index: ArrayLike,
    direction_grid_deg: ArrayLike,
    draught_m: float,
    ukc_m: float,
    within_m: ArrayLike,
) -> WaterBeyondLimits:
    """For each position in channel ``index[i]`` heading ``direction_grid_deg[i]`` (her way
    along its axis): the water ``chart`` gives as navigable for ``draught_m + ukc_m`` beyond
    the channel's port and starboard limits, looked for up to ``within_m[i]`` past each
    (module docstring). ``chart`` is the one the channels were read from, in their frame."""
    north, east, index_b, bearing, within = np.broadcast_arrays(
        np.atleast_1d(np.asarray(north_m, dtype=float)),
        np.atleast_1d(np.asarray(east_m, dtype=float)),
        np.atleast_1d(np.asarray(index, dtype=np.int64)),
        np.atleast_1d(np.asarray(direction_grid_deg, dtype=float)),
        np.atleast_1d(np.asarray(within_m, dtype=float)),
    )
    limits = channels.sections(north, east, index_b, bearing)
    n = len(north)
    port, starboard = np.full(n, np.nan), np.full(n, np.nan)
    q = np.flatnonzero(np.isfinite(limits.left_m + limits.right_m) & np.isfinite(within))
    if len(q) == 0:
        return WaterBeyondLimits(port, starboard, limits.left_m, limits.right_m)
    centre = np.column_stack([east[q], north[q]])
    radians = np.radians(bearing[q])
    right_unit = np.column_stack([np.cos(radians), -np.sin(radians)])
    # Past the limit by the room asked and a metre, so that water reaching that far is open.
    reach_port = limits.left_m[q] + within[q] + _PAST_THE_END_M
    reach_starboard = limits.right_m[q] + within[q] + _PAST_THE_END_M
    water = np.full(len(q), chart.navigable_water(draught_m, ukc_m), dtype=object)
    to_port, to_starboard = section_extents(
        centre, right_unit, (reach_port, reach_starboard), water
    )
    for side, extent, limit, reach, sign in (
        (port, to_port, limits.left_m[q], reach_port, -1.0),
        (starboard, to_starboard, limits.right_m[q], reach_starboard, 1.0),
    ):
        beyond = np.clip(extent - limit, 0.0, within[q])
        # Where the water ends short of the reach, what stops it must be charted.
        ends = np.isfinite(extent) & (extent < reach - _PAST_THE_END_M / 2.0)
        past = centre + (sign * (extent + _PAST_THE_END_M))[:, None] * right_unit
        charted = np.ones(len(q), dtype=bool)
        if ends.any():
            charted[ends] = chart.covers(past[ends, 1], past[ends, 0])
        side[q] = np.where(charted, beyond, np.nan)
    return WaterBeyondLimits(port, starboard, limits.left_m, limits.right_m)
