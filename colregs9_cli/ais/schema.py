"""The canonical AIS schema (docs/design.md §4): the one column contract, enforced at ingest.

Every reader yields tables with exactly ``CANONICAL_SCHEMA``. AIS "not available" sentinels
(lat 91, lon 181, SOG 102.3, COG 360, heading 511, dimension 0, draught 0, ``Unknown``) are
turned into nulls by the readers and nowhere else. ``ANTENNA_OFFSETS`` are AIS's A, B, C, D
(ITU-R M.1371, "reference point for reported position"): the antenna's distances to the bow,
stern, port and starboard sides, in metres; null where not reported (``clean.offset_parts``).
"""

from __future__ import annotations

from collections.abc import Iterable

import pyarrow as pa

from ..vessels import DIMENSIONS

CANONICAL_SCHEMA = pa.schema(
    [
        pa.field("timestamp", pa.timestamp("ms", tz="UTC")),
        pa.field("mmsi", pa.int64()),
        pa.field("lat_deg", pa.float64()),
        pa.field("lon_deg", pa.float64()),
        pa.field("sog_kn", pa.float64()),
        pa.field("cog_deg", pa.float64()),
        pa.field("heading_deg", pa.float64()),
        pa.field("rot_deg_per_min", pa.float64()),
        pa.field("nav_status", pa.int8()),
        pa.field("ship_type", pa.string()),
        pa.field("mobile_type", pa.string()),
        pa.field("length_m", pa.float64()),
        pa.field("breadth_m", pa.float64()),
        pa.field("to_bow_m", pa.float64()),
        pa.field("to_stern_m", pa.float64()),
        pa.field("to_port_m", pa.float64()),
        pa.field("to_starboard_m", pa.float64()),
        pa.field("draught_m", pa.float64()),
        pa.field("name", pa.string()),
        pa.field("callsign", pa.string()),
        pa.field("imo", pa.int64()),
    ]
)

CANONICAL_COLUMNS: tuple[str, ...] = tuple(CANONICAL_SCHEMA.names)

# AIS A, B, C, D: the antenna's distances to the bow, stern, port and starboard sides.
ANTENNA_OFFSETS: tuple[str, ...] = ("to_bow_m", "to_stern_m", "to_port_m", "to_starboard_m")

# The columns of the positions the dimension statistics use: a dataset is read for these alone.
STATS_POSITION_COLUMNS: tuple[str, ...] = ("mmsi", "ship_type", *DIMENSIONS)


def canonical_fields(names: Iterable[str]) -> pa.Schema:
    """The canonical fields of ``names``, in that order."""
    return pa.schema([CANONICAL_SCHEMA.field(name) for name in names])
