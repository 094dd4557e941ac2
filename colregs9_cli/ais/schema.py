"""The canonical AIS schema (DESIGN §4): the one column contract, enforced at ingest.

Every reader yields tables with exactly ``CANONICAL_SCHEMA``. AIS "not available" sentinels
(lat 91, lon 181, SOG 102.3, COG 360, heading 511, dimension 0, draught 0, ``Unknown``) are
turned into nulls by the readers and nowhere else.
"""

from __future__ import annotations

from collections.abc import Iterable

import pyarrow as pa

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
        pa.field("draught_m", pa.float64()),
        pa.field("name", pa.string()),
        pa.field("callsign", pa.string()),
        pa.field("imo", pa.int64()),
    ]
)

CANONICAL_COLUMNS: tuple[str, ...] = tuple(CANONICAL_SCHEMA.names)

# The vessel dimensions.
DIMENSIONS: tuple[str, ...] = ("length_m", "breadth_m", "draught_m")
# The columns of the positions the dimension statistics use: a dataset is read for these alone.
STATS_POSITION_COLUMNS: tuple[str, ...] = ("mmsi", "ship_type", *DIMENSIONS)


def canonical_fields(names: Iterable[str]) -> pa.Schema:
    """The canonical fields of ``names``, in that order."""
    return pa.schema([CANONICAL_SCHEMA.field(name) for name in names])


# ITU-R M.1371 navigational status codes.
NAV_STATUS_CODES: dict[int, str] = {
    0: "Under way using engine",
    1: "At anchor",
    2: "Not under command",
    3: "Restricted manoeuvrability",
    4: "Constrained by her draught",
    5: "Moored",
    6: "Aground",
    7: "Engaged in fishing",
    8: "Under way sailing",
    9: "Reserved for HSC",
    10: "Reserved for WIG",
    11: "Power-driven vessel towing astern",
    12: "Power-driven vessel pushing ahead or towing alongside",
    13: "Reserved for future use",
    14: "AIS-SART",
    15: "Undefined",
}

# The ``mobile_type`` values; only these are vessels.
VESSEL_MOBILE_TYPES = frozenset({"Class A", "Class B"})
