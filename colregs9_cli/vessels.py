"""What a vessel is, for every layer: her dimensions and their plausible limits, the MMSI range
of ships, the AIS mobile types that are vessels, and the navigational status codes.

The readers (``ais/``) enforce these at ingest; the core (``core/vessel_defaults.py``), the
scenarios and the queries check against the same values, so they are written once, here.
"""

from __future__ import annotations

# The vessel dimensions, as the canonical schema names them.
DIMENSIONS: tuple[str, ...] = ("length_m", "breadth_m", "draught_m")

# The largest dimensions a ship has (metres): the longest ships are under 460 m, the widest
# under 70 m, and AIS encodes a draught of at most 25.5 m. Beyond these, or not finite, a
# value is a corrupt field (``inf``, ``1e400``): it is dropped (NaN, as not available), never
# used in a statistic, and counted in the ledger as ``implausible_dimension``
# (``ais.clean.DimensionColumns.implausible``).
MAX_LENGTH_M = 500.0
MAX_BREADTH_M = 80.0
MAX_DRAUGHT_M = 30.0

# A ship's MMSI: nine digits with maritime identification digits (the first three) in 201-775.
MMSI_MIN = 201_000_000  # MID 201: the lowest allocated maritime identification digits
MMSI_MAX = 775_999_999  # MID 775
# Any nine-digit MMSI, as a query may name one (a base station or an AtoN included).
NINE_DIGIT_MMSI_MIN, NINE_DIGIT_MMSI_MAX = 100_000_000, 999_999_999

# The ``mobile_type`` values; only these are vessels.
VESSEL_MOBILE_TYPES = frozenset({"Class A", "Class B"})

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
