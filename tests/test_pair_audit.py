"""Report gaps over a passing (core/pair_audit.py): hand-worked cases."""

from __future__ import annotations

import pandas as pd
import pytest

from colregs9_cli.core.audit import INSUFFICIENT_CONDUCT
from colregs9_cli.core.pair_audit import PairAudit, ReportGaps, report_gaps


def _window(gaps_s: list[float], speeds_mps: list[float]) -> pd.DataFrame:
    return pd.DataFrame({"own_report_gap_s": gaps_s, "own_speed_mps": speeds_mps})


def test_largest_gap_and_farthest_unseen_run() -> None:
    # A 60 s gap at 5 m/s (300 m unseen) and a 90 s gap at 2 m/s (180 m): the longest gap
    # is not where she ran farthest.
    gaps = report_gaps(_window([0, 60, 60, 0, 90, 0], [5, 5, 5, 2, 2, 2]), "own_")
    assert gaps == ReportGaps(largest_gap_s=90.0, run_unseen_m=300.0)


def test_no_rows_no_gaps() -> None:
    assert report_gaps(_window([], []), "own_") is None


def test_at_every_report_no_gap() -> None:
    assert report_gaps(_window([0, 0, 0], [7, 7, 7]), "own_") == ReportGaps(0.0, 0.0)


@pytest.mark.parametrize(("least_m", "sparse"), [(299.0, True), (300.0, False), (None, None)])
def test_sparse_when_she_ran_farther_unseen_than_the_least_separation(
    least_m: float | None, sparse: bool | None
) -> None:
    audit = PairAudit(
        least_m is not None,
        least_m,
        None,
        (INSUFFICIENT_CONDUCT, INSUFFICIENT_CONDUCT),
        (None, None),
        report_gaps=(ReportGaps(90.0, 300.0), None),
    )
    assert audit.reports_sparse(0) is sparse
    assert audit.reports_sparse(1) is None
