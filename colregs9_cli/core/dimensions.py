"""Vessel dimension statistics (the paper's Table "Statistical overview of vessel dimensions").

The computation (``dimension_stats``) is pure: it takes the positions selected by a query and
the dimension reports of the whole input, and returns typed tables. ``colregs9_cli.jobs.stats``
runs it behind ``colregs9 stats``: read, compute, write the reports.

Per vessel, a vessel's value is the median of all its valid reports in the input, each
distinct report weighted by how often it was sent (the median of the expanded list of
reports, the mean of the two middle reports when their number is even). Per message, every
position row in the query that carries a value counts once.

The positions come as counts (``STATS_POSITION_COLUMNS`` and ``n_positions``): each row stands
for ``n_positions`` position messages with its MMSI, ship type and dimensions. A reader can so
count the positions as it scans them (``ais.load.count_ais``) rather than hold them, and
the statistics per message are those of the messages the rows stand for, whatever the
rows: a frame of positions with ``n_positions`` 1 gives the same statistics as its counts.

The sample standard deviation (ddof = 1) is undefined for fewer than two values; it is then
NaN in the tables, an empty cell in the CSV and ``null`` in ``run.json``. The same holds for
every statistic of a dimension with no value at all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np
import pandas as pd

from ..vessels import DIMENSIONS

STAT_COLUMNS: tuple[str, ...] = ("count", "mean", "median", "std", "min", "max")
# Vessels whose ship type is never reported are grouped under this label with ``--by``.
NO_SHIP_TYPE = "Unknown"


# The group name of the overall rows in a grouped CSV: no ship type is written this way.
ALL_GROUPS = "(all)"


class Per(StrEnum):
    VESSEL = "vessel"
    MESSAGE = "message"


class GroupBy(StrEnum):
    SHIP_TYPE = "ship_type"


@dataclass(frozen=True)
class DimensionStats:
    """One row of the table: the statistics of one dimension over the counted units."""

    dimension: str
    count: int
    missing: int
    mean: float
    median: float
    std: float
    min: float
    max: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "dimension": self.dimension,
            "count": self.count,
            "mean": _json_float(self.mean),
            "median": _json_float(self.median),
            "std": _json_float(self.std),
            "min": _json_float(self.min),
            "max": _json_float(self.max),
            "missing": self.missing,
        }


@dataclass(frozen=True)
class StatsTable:
    """The three dimension rows over one set of units (all of them, or one ship type)."""

    group: str | None
    units: int
    rows: tuple[DimensionStats, ...]

    def row(self, dimension: str) -> DimensionStats:
        for row in self.rows:
            if row.dimension == dimension:
                return row
        raise KeyError(dimension)

    def to_dict(self) -> dict[str, Any]:
        return {
            "group": self.group,
            "units": self.units,
            "rows": [row.to_dict() for row in self.rows],
        }


@dataclass(frozen=True)
class StatsResult:
    """Dimension statistics per vessel or per message, overall and optionally per ship type.

    ``samples`` holds the counted units, with ``mmsi``, ``ship_type``, the three dimensions
    and ``units``, how many units the row stands for: one vessel, or ``n_positions`` position
    messages; the histograms are drawn from it.
    """

    per: Per
    by: GroupBy | None
    overall: StatsTable
    groups: tuple[StatsTable, ...]
    vessels: int
    messages: int
    samples: pd.DataFrame = field(repr=False, compare=False)

    @property
    def unit_name(self) -> str:
        return "vessels" if self.per is Per.VESSEL else "messages"

    def to_frame(self) -> pd.DataFrame:
        """The CSV table: ``dimension`` then exactly ``STAT_COLUMNS``. Grouped, ``ship_type``
        comes first, and the overall rows come first as the group ``ALL_GROUPS``."""
        tables = (self.overall, *self.groups) if self.by is not None else (self.overall,)
        records = []
        for table in tables:
            for row in table.rows:
                record: dict[str, Any] = {}
                if self.by is not None:
                    record[self.by.value] = ALL_GROUPS if table is self.overall else table.group
                record["dimension"] = row.dimension
                record.update({name: getattr(row, name) for name in STAT_COLUMNS})
                records.append(record)
        leading = [self.by.value] if self.by is not None else []
        return pd.DataFrame.from_records(
            records, columns=[*leading, "dimension", *STAT_COLUMNS]
        ).astype({"count": "int64"})


def _json_float(value: float) -> float | None:
    return None if math.isnan(value) else float(value)


def weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    """The median of ``values`` each repeated ``weights`` times (NaN if there are none)."""
    values = np.asarray(values, dtype=float)
    weights = np.asarray(weights, dtype=np.int64)
    keep = ~np.isnan(values) & (weights > 0)
    values, weights = values[keep], weights[keep]
    if values.size == 0:
        return math.nan
    order = np.argsort(values, kind="stable")
    return _sorted_median(values[order], np.cumsum(weights[order]))


def _sorted_median(values: np.ndarray, cumulative: np.ndarray) -> float:
    """The weighted median of sorted ``values`` given their running weights."""
    total = int(cumulative[-1])
    lower = values[np.searchsorted(cumulative, (total - 1) // 2, side="right")]
    upper = values[np.searchsorted(cumulative, total // 2, side="right")]
    return float((lower + upper) / 2.0)


def vessel_medians(dimension_reports: pd.DataFrame) -> pd.DataFrame:
    """Each vessel's median of its valid reports, per dimension, weighted by ``n_reports``.

    Returns one row per MMSI (index ``mmsi``) with the three dimensions; NaN where a vessel
    never reported a valid value for that dimension.
    """
    result = pd.DataFrame(index=pd.Index(np.unique(dimension_reports["mmsi"]), name="mmsi"))
    for dimension in DIMENSIONS:
        valid = dimension_reports.loc[
            dimension_reports[dimension].notna() & (dimension_reports["n_reports"] > 0),
            ["mmsi", dimension, "n_reports"],
        ]
        # One row per (vessel, distinct value), sorted, with the running count of reports.
        counts = valid.groupby(["mmsi", dimension], sort=True)["n_reports"].sum().reset_index()
        running = counts.groupby("mmsi")["n_reports"].cumsum()
        total = counts.groupby("mmsi")["n_reports"].transform("sum")
        # 0-based positions of the two middle reports in the vessel's expanded, sorted list;
        # the value at position k is the first whose running count exceeds k.
        lower = counts[running > (total - 1) // 2].groupby("mmsi")[dimension].first()
        upper = counts[running > total // 2].groupby("mmsi")[dimension].first()
        result[dimension] = (lower + upper) / 2.0
    return result


def vessel_ship_types(position_counts: pd.DataFrame) -> pd.Series:
    """Each vessel's most frequent non-null ship type over its position messages (ties:
    alphabetically first)."""
    mmsis = pd.Index(np.unique(position_counts["mmsi"]), name="mmsi")
    typed = position_counts.loc[
        position_counts["ship_type"].notna(), ["mmsi", "ship_type", "n_positions"]
    ]
    counts = typed.groupby(["mmsi", "ship_type"])["n_positions"].sum().rename("n").reset_index()
    counts = counts.sort_values(["mmsi", "n", "ship_type"], ascending=[True, False, True])
    most_frequent = counts.drop_duplicates("mmsi").set_index("mmsi")["ship_type"]
    # object first: with no type reported at all, the empty series would be float
    return most_frequent.astype(object).reindex(mmsis).fillna(NO_SHIP_TYPE).astype(str)


def summarise(samples: pd.DataFrame, group: str | None = None) -> StatsTable:
    """The statistics of each dimension over the units of ``samples``, each row standing for
    ``units`` of them: those of the list of values with each row's repeated ``units`` times."""
    units = samples["units"].to_numpy(dtype=np.int64)
    rows = []
    for dimension in DIMENSIONS:
        values = samples[dimension].to_numpy(dtype=float)
        valid = ~np.isnan(values) & (units > 0)
        # Sorted, so that the sums (mean, std) do not depend on the order of the rows.
        order = np.argsort(values[valid], kind="stable")
        values, weights = values[valid][order], units[valid][order]
        count = int(weights.sum())
        mean = float(np.sum(values * weights) / count) if count else math.nan
        rows.append(
            DimensionStats(
                dimension=dimension,
                count=count,
                missing=int(units.sum()) - count,
                mean=mean,
                median=_sorted_median(values, np.cumsum(weights)) if count else math.nan,
                std=(
                    math.sqrt(float(np.sum(weights * (values - mean) ** 2)) / (count - 1))
                    if count >= 2
                    else math.nan
                ),
                min=float(values[0]) if count else math.nan,
                max=float(values[-1]) if count else math.nan,
            )
        )
    return StatsTable(group=group, units=int(units.sum()), rows=tuple(rows))


def dimension_stats(
    position_counts: pd.DataFrame,
    dimension_reports: pd.DataFrame,
    per: Per = Per.VESSEL,
    by: GroupBy | None = None,
) -> StatsResult:
    """Dimension statistics over the vessels (or position messages) of ``position_counts``.

    ``position_counts``: ``STATS_POSITION_COLUMNS`` and ``n_positions``, the position rows selected
    by the query, each row standing for ``n_positions`` of them (see the module docstring).
    ``dimension_reports``: ``mmsi, length_m, breadth_m, draught_m, n_reports``, the distinct
    reported combinations over the whole input with how often each was sent (used per vessel
    only).
    """
    ship_types = vessel_ship_types(position_counts)
    if per is Per.VESSEL:
        medians = vessel_medians(dimension_reports).reindex(ship_types.index)
        samples = medians.assign(ship_type=ship_types, units=1).reset_index()
    else:
        samples = position_counts[["mmsi", *DIMENSIONS]].reset_index(drop=True)
        samples["ship_type"] = samples["mmsi"].map(ship_types)
        samples["units"] = position_counts["n_positions"].to_numpy(dtype=np.int64)
    samples = samples[["mmsi", "ship_type", *DIMENSIONS, "units"]]
    groups: tuple[StatsTable, ...] = ()
    if by is GroupBy.SHIP_TYPE:
        groups = tuple(
            summarise(group_samples, group=str(ship_type))
            for ship_type, group_samples in samples.groupby("ship_type", sort=True)
        )
    return StatsResult(
        per=per,
        by=by,
        overall=summarise(samples),
        groups=groups,
        vessels=len(ship_types),
        messages=int(position_counts["n_positions"].sum()),
        samples=samples,
    )
