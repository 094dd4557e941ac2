"""The water on either hand of a vessel proceeding along a charted channel, for her draught:
what rule 9(b) and (c)'s "a vessel which can safely navigate only within a narrow channel or
fairway" reads from the chart (``core.confinement.confined_to_channel`` judges it).

Through her position, square to the channel's local axis, the section is cut twice:

- by the charted channel areas it meets (``Channels.section_limits``: fairways, dredged
  areas, deep-water routes, traffic lanes and separation zones, joined, so that a cut
  charted as two one-way fairways, or a dredged centre between dredged toes, is one channel
  and the other half is not "room outside" it): its limits on her port and starboard hands;
- by the chart's water navigable for her draught plus an under-keel clearance
  (``Chart.navigable_water``: the depth areas at least that deep, less land and the hazards
  that block).

The piece of navigable water that holds her ends somewhere on each hand. How far that is
beyond the channel's limit is the room she has outside it on that hand (0 where the water
ends at the limit or inside it, as where the dredged cut is the only deep water); the part
of the piece inside the limits is the channel's width navigable for her there.

A hand is unknown (NaN) where the navigable water ends at the edge of the chart's coverage
(what lies beyond is not charted here). Both are unknown, and ``held`` false, where her
position is not in water the chart gives as navigable for her draught (the chart, the
draught or the position is wrong there, and nothing can be judged).
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
    """Per position: the navigable water beyond the channel's limits on her port and on her
    starboard hand (capped at the ``within_m`` asked; NaN unknown, module docstring), the
    channel's width navigable for her there, whether navigable water holds her, and the
    channel's limits from her."""

    port_m: NDArray[np.float64]
    starboard_m: NDArray[np.float64]
    navigable_width_m: NDArray[np.float64]
    held: NDArray[np.bool_]
    channel_port_m: NDArray[np.float64]
    channel_starboard_m: NDArray[np.float64]


def water_beyond_limits(
    channels: Channels,
    chart: Chart,
    north_m: ArrayLike,
    east_m: ArrayLike,
    direction_grid_deg: ArrayLike,
    draught_m: float,
    ukc_m: float,
    within_m: ArrayLike,
) -> WaterBeyondLimits:
    """For each position in a charted channel area, heading ``direction_grid_deg[i]`` (her
    way along its axis): the water ``chart`` gives as navigable for ``draught_m + ukc_m``
    beyond the channel's port and starboard limits, looked for up to ``within_m[i]`` past
    each (module docstring). ``chart`` is the one the channels were read from, in their
    frame. Positions outside every channel area get NaN."""
    north, east, bearing, within = np.broadcast_arrays(
        np.atleast_1d(np.asarray(north_m, dtype=float)),
        np.atleast_1d(np.asarray(east_m, dtype=float)),
        np.atleast_1d(np.asarray(direction_grid_deg, dtype=float)),
        np.atleast_1d(np.asarray(within_m, dtype=float)),
    )
    n = len(north)
    port_m, starboard_m, width_m = (np.full(n, np.nan) for _ in range(3))
    limit_port_m, limit_starboard_m = np.full(n, np.nan), np.full(n, np.nan)
    held = np.zeros(n, dtype=bool)
    q = np.flatnonzero(np.isfinite(north + east + bearing + within))
    radians = np.radians(bearing[q])
    right_unit = np.column_stack([np.cos(radians), -np.sin(radians)])
    centre = np.column_stack([east[q], north[q]])
    limit_port_m[q], limit_starboard_m[q] = channels.section_limits(centre, right_unit)
    inside = np.isfinite(limit_port_m[q] + limit_starboard_m[q])
    q, centre, right_unit = q[inside], centre[inside], right_unit[inside]
    # Past each limit by the room asked and a metre, so that water reaching that far is open.
    reach_port_m = limit_port_m[q] + within[q] + _PAST_THE_END_M
    reach_starboard_m = limit_starboard_m[q] + within[q] + _PAST_THE_END_M
    water = np.full(len(q), chart.navigable_water(draught_m, ukc_m), dtype=object)
    to_port_m, to_starboard_m = section_extents(
        centre, right_unit, (reach_port_m, reach_starboard_m), water
    )
    held[q] = np.isfinite(to_port_m + to_starboard_m)
    width_m[q] = np.minimum(to_port_m, limit_port_m[q]) + np.minimum(
        to_starboard_m, limit_starboard_m[q]
    )
    for room_m, extent_m, limit_m, reach_m, sign in (
        (port_m, to_port_m, limit_port_m[q], reach_port_m, -1.0),
        (starboard_m, to_starboard_m, limit_starboard_m[q], reach_starboard_m, 1.0),
    ):
        beyond_m = np.clip(extent_m - limit_m, 0.0, within[q])
        # Where the water ends short of the reach, what stops it must be charted.
        ends = np.isfinite(extent_m) & (extent_m < reach_m - _PAST_THE_END_M / 2.0)
        past = centre + (sign * (extent_m + _PAST_THE_END_M))[:, None] * right_unit
        charted = np.ones(len(q), dtype=bool)
        if ends.any():
            charted[ends] = chart.covers(past[ends, 1], past[ends, 0])
        room_m[q] = np.where(charted, beyond_m, np.nan)
    return WaterBeyondLimits(port_m, starboard_m, width_m, held, limit_port_m, limit_starboard_m)
