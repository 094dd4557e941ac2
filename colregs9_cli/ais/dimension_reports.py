"""Dimension reports: how often each vessel reported each distinct (length, breadth, draught),
the ``dimension_reports`` of ``load.AisData`` (what counts as a report: load.py's docstring).

Counted block by block as rows are read (``count_reports``), from a dataset's stored counts
(``cleaned_reports``), summed into one row per combination (``sum_counts``), taken back for
rows rejected later (``subtract_counts``), and counted from cleaned canonical rows
(``rows_reports``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc

from ..vessels import DIMENSIONS
from .clean import (
    DimensionColumns,
    Dimensions,
    any_dimension,
    implausible,
    plausible,
    to_numpy_float,
)
from .counting import sum_by

DIMENSION_REPORT_COLUMNS = ("mmsi", *DIMENSIONS, "n_reports")


def canonical_dimensions(table: pa.Table) -> Dimensions:
    """The canonical columns as numbers, before the plausibility limits."""
    length_m, breadth_m, draught_m = (to_numpy_float(table.column(name)) for name in DIMENSIONS)
    return length_m, breadth_m, draught_m


def report_rows(
    mmsi: np.ndarray,
    length_m: np.ndarray,
    breadth_m: np.ndarray,
    draught_m: np.ndarray,
    times: np.ndarray | None = None,
) -> pa.Table:
    """Reports as rows of ``DIMENSION_REPORT_COLUMNS``, each counting ``times`` (default
    once); NaN dimensions become null. A combination may take several rows until the rows
    are summed (``sum_counts``)."""
    return pa.table(
        {
            "mmsi": pa.array(mmsi, pa.int64()),
            "length_m": pa.array(length_m, pa.float64(), from_pandas=True),
            "breadth_m": pa.array(breadth_m, pa.float64(), from_pandas=True),
            "draught_m": pa.array(draught_m, pa.float64(), from_pandas=True),
            "n_reports": pa.array(np.ones(len(mmsi)) if times is None else times, pa.int64()),
        }
    )


# No report, with the columns and types of ``report_rows``.
NO_REPORTS = report_rows(np.empty(0), np.empty(0), np.empty(0), np.empty(0))


def sum_counts(parts: Sequence[pa.Table]) -> pa.Table:
    """Counts of (mmsi, dimensions) from several parts combined into one per combination.

    Arrow's hash grouping, faster than pandas' (tests/benchmarks/README.md, "Figures moved
    from code comments"); on the calling thread, as the CSV reader keeps pyarrow's thread
    pool busy.
    """
    return sum_by(parts, ["mmsi", *DIMENSIONS], "n_reports", use_threads=False)


def count_reports(
    mmsi: np.ndarray, dimensions: DimensionColumns, rows: np.ndarray
) -> tuple[pa.Table, int]:
    """The reports (``report_rows``) of the cleaned dimensions of ``rows``, without the
    rows that report none, and how many of ``rows`` have a dimension dropped as implausible.
    The rows are grouped as read first, and only the groups are cleaned; groups that clean
    alike are summed later."""
    key = "mmsi"
    while key in dimensions.table.column_names:
        key = f"_{key}"
    keyed = dimensions.table.append_column(key, pa.array(np.where(rows, mmsi, -1), pa.int64()))
    groups = keyed.group_by(keyed.column_names, use_threads=False).aggregate([([], "count_all")])
    groups = groups.filter(pc.not_equal(groups.column(key), -1))
    measured = dimensions.measure(groups)
    length_m, breadth_m, draught_m = plausible(measured)
    reported = any_dimension(length_m, breadth_m, draught_m)
    times = groups.column("count_all").to_numpy()
    implausible_count = int(times[implausible(measured)].sum())
    counts = report_rows(
        groups.column(key).to_numpy()[reported],
        length_m[reported],
        breadth_m[reported],
        draught_m[reported],
        times[reported],
    )
    return counts, implausible_count


def cleaned_reports(groups: pa.Table) -> pa.Table:
    """The dimension reports counted as stored (``mmsi``, the dimensions, ``n_reports``),
    cleaned as a file's are (``count_reports``): rows that report no plausible dimension
    go, and raw values that clean alike (implausible ones become null) are summed."""
    length_m, breadth_m, draught_m = plausible(canonical_dimensions(groups))
    reported = any_dimension(length_m, breadth_m, draught_m)
    return sum_counts(
        [
            report_rows(
                groups.column("mmsi").to_numpy()[reported],
                length_m[reported],
                breadth_m[reported],
                draught_m[reported],
                groups.column("n_reports").to_numpy()[reported],
            )
        ]
    )


def subtract_counts(counts: pa.Table, dropped: pa.Table) -> pa.Table:
    """``counts`` less the dimension reports of the ``dropped`` rows."""
    return sum_counts([counts, rows_reports(dropped, -1)])


def rows_reports(rows: pa.Table, times: int = 1) -> pa.Table:
    """The dimension reports (``report_rows``) of canonical ``rows``, whose dimensions are
    cleaned already, each counting ``times``; rows that report none are left out."""
    length_m, breadth_m, draught_m = (to_numpy_float(rows.column(d)) for d in DIMENSIONS)
    reported = any_dimension(length_m, breadth_m, draught_m)
    return report_rows(
        rows.column("mmsi").to_numpy()[reported],
        length_m[reported],
        breadth_m[reported],
        draught_m[reported],
        times=np.full(int(reported.sum()), times),
    )


def reports_frame(counts: pa.Table, vessels: np.ndarray) -> pd.DataFrame:
    """``AisData.dimension_reports``: the counted reports of ``vessels``, sorted."""
    frame = counts.to_pandas()
    reports = frame[frame["mmsi"].isin(vessels) & (frame["n_reports"] > 0)]
    reports = reports.sort_values(["mmsi", *DIMENSIONS], ignore_index=True)
    reports["n_reports"] = reports["n_reports"].astype(np.int64)
    return reports[list(DIMENSION_REPORT_COLUMNS)]
