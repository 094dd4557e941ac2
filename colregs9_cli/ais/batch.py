"""What a reader yields: position reports in the canonical schema, plus static reports.

A DMA CSV row carries both, so its reader puts dimensions on the position rows and yields an
empty ``statics`` table (a DMA row with static fields but no position is a static report).
NMEA keeps them apart (message types 5, 19, 24); its reader joins them to positions by MMSI
and also yields them in ``statics``, because per-vessel statistics count static reports.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pyarrow as pa

from .schema import ANTENNA_OFFSETS, CANONICAL_SCHEMA

STATIC_SCHEMA = pa.schema(
    [
        CANONICAL_SCHEMA.field(name)
        for name in (
            "timestamp",
            "mmsi",
            "ship_type",
            "length_m",
            "breadth_m",
            *ANTENNA_OFFSETS,
            "draught_m",
            "name",
            "callsign",
            "imo",
        )
    ]
)


@dataclass(frozen=True)
class AisBatch:
    positions: pa.Table  # CANONICAL_SCHEMA
    statics: pa.Table  # STATIC_SCHEMA
    # The line of the input each row of ``positions`` and ``statics`` comes from, where the
    # reader knows it (NMEA: the first sentence of the message), for reject examples.
    position_lines: np.ndarray | None = field(default=None, compare=False)
    static_lines: np.ndarray | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        if not self.positions.schema.equals(CANONICAL_SCHEMA):
            raise TypeError(
                f"positions do not follow the canonical schema:\n{self.positions.schema}"
            )
        if not self.statics.schema.equals(STATIC_SCHEMA):
            raise TypeError(f"statics do not follow the static schema:\n{self.statics.schema}")


def empty_statics() -> pa.Table:
    return STATIC_SCHEMA.empty_table()
