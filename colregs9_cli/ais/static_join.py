"""NMEA static reports joined to the positions of the other NMEA files of one run: a log split
by day (as nmea.py advises for long ones) gives its positions the static data the whole log
would have.

nmea.py joins a file's static reports (types 5, 24, the static part of 19) to its own
positions. ``fill_statics`` then gives each position the static fields it still lacks from
the reports of every NMEA file of the run, by the same rule (nmea.py's docstring, "Static
join"): field by field from the report of her MMSI nearest in time that has it, and the
antenna offsets A, B, C, D together from the nearest report with any of them. A field a
position has (its own, or joined within its file) is kept, so a file's own reports come
first, and the type 19 positions of another file (which only nmea.py sees as such) lend
nothing.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc

from .schema import ANTENNA_OFFSETS

# Joined one by one; the antenna offsets are joined together.
JOINED_FIELDS = ("ship_type", "length_m", "breadth_m", "draught_m", "name", "callsign", "imo")
STATIC_COLUMNS = ("timestamp", "mmsi", *JOINED_FIELDS, *ANTENNA_OFFSETS)
# A row without a time (``stats`` keeps NMEA messages without one) joins as if long before
# every other: nearest to the rows without a time, farthest from the others. Half of int64's
# range, so that no difference of two times overflows.
_NO_TIME_MS = np.iinfo(np.int64).min // 2


def fill_statics(positions: pa.Table, statics: pa.Table) -> pa.Table:
    """``positions`` (canonical) with the static fields they lack taken from ``statics``
    (rows with ``STATIC_COLUMNS``: the static reports of the run's NMEA files)."""
    if positions.num_rows == 0 or statics.num_rows == 0:
        return positions
    keys = pd.DataFrame(
        {
            "timestamp": _ms(positions),
            "mmsi": positions.column("mmsi").to_numpy(),
            "row": np.arange(positions.num_rows),
        }
    ).sort_values("timestamp", kind="stable")
    report_keys = pd.DataFrame(
        {
            "timestamp": _ms(statics),
            "mmsi": statics.column("mmsi").to_numpy(),
            "report": np.arange(statics.num_rows),
        }
    ).sort_values("timestamp", kind="stable")
    for names in (*((name,) for name in JOINED_FIELDS), ANTENNA_OFFSETS):
        lacking = _all_null(positions, names)
        having = ~_all_null(statics, names)
        if not lacking.any() or not having.any():
            continue
        nearest = pd.merge_asof(
            keys[lacking[keys["row"].to_numpy()]],
            report_keys[having[report_keys["report"].to_numpy()]],
            on="timestamp",
            by="mmsi",
            direction="nearest",
        ).dropna(subset=["report"])
        if nearest.empty:
            continue
        pick = np.zeros(positions.num_rows, dtype=np.int64)
        found = np.zeros(positions.num_rows, dtype=bool)
        pick[nearest["row"].to_numpy()] = nearest["report"].to_numpy(dtype=np.int64)
        found[nearest["row"].to_numpy()] = True
        indices = pa.array(pick, mask=~found)
        for name in names:
            joined = statics.column(name).take(indices)
            index = positions.schema.get_field_index(name)
            positions = positions.set_column(
                index, name, pc.coalesce(positions.column(name), joined)
            )
    return positions


def _ms(table: pa.Table) -> np.ndarray:
    """The rows' times in milliseconds since the epoch; ``_NO_TIME_MS`` for none."""
    milliseconds = table.column("timestamp").cast(pa.int64())
    return np.asarray(pc.fill_null(milliseconds, _NO_TIME_MS).to_numpy(), dtype=np.int64)


def _all_null(table: pa.Table, names: tuple[str, ...]) -> np.ndarray:
    """Rows of ``table`` in which every column of ``names`` is null."""
    null = np.ones(table.num_rows, dtype=bool)
    for name in names:
        null &= np.asarray(table.column(name).is_null().to_numpy(zero_copy_only=False))
    return null
