"""Dimension statistics on a small hand-computed case, and the report writers."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.patches import Rectangle

from colregs9_cli.core.dimensions import (
    GroupBy,
    Per,
    dimension_stats,
    vessel_medians,
    vessel_ship_types,
    weighted_median,
)
from colregs9_cli.report.stats_report import (
    HISTOGRAM_MAX_BINS,
    format_markdown,
    format_text,
    histogram_bins,
    histogram_figure,
    write_stats_reports,
)

A, B, C, D, E, F = 219000001, 219000002, 219000003, 219000004, 219000005, 219000006
NAN = math.nan

# The distinct reports over the whole input, with how often each was sent.
#   A: length [100,100,100,102,130] -> median 100 (the mean would be 106.4);
#      breadth [20,20,20,20,22] -> 20; draught [5.0,5.0,5.0,5.4,6.0] -> 5.0
#   B: two reports, an even count: length (50+60)/2 = 55, breadth (10+12)/2 = 11,
#      draught (3.0+4.0)/2 = 3.5
#   C: length 12, breadth 4, never a draught
#   D: length [15,15,16] -> 15; breadth [5,5,5] -> 5; draught [2.0,2.0,1.0] -> 2.0
#      (the report with only a draught counts for draught and nothing else)
#   E: has reports but no position in the query, so it is not counted
#   F: has positions in the query but never reported a dimension
DIMENSION_REPORTS = pd.DataFrame(
    [
        (A, 100.0, 20.0, 5.0, 3),
        (A, 102.0, 20.0, 5.4, 1),
        (A, 130.0, 22.0, 6.0, 1),
        (B, 50.0, 10.0, 3.0, 1),
        (B, 60.0, 12.0, 4.0, 1),
        (C, 12.0, 4.0, NAN, 4),
        (D, 15.0, 5.0, 2.0, 2),
        (D, 16.0, 5.0, NAN, 1),
        (D, NAN, NAN, 1.0, 1),
        (E, 300.0, 40.0, 12.0, 5),
    ],
    columns=["mmsi", "length_m", "breadth_m", "draught_m", "n_reports"],
)

# The position rows inside the query (9 messages from 5 vessels).
POSITIONS = pd.DataFrame(
    [
        (A, "Cargo", 100.0, 20.0, 5.0),
        (A, "Cargo", 130.0, 22.0, 6.0),
        (B, "Cargo", 50.0, 10.0, 3.0),
        (C, "Fishing", 12.0, 4.0, NAN),
        (C, "Fishing", 12.0, 4.0, NAN),
        (D, "Pilot", 15.0, 5.0, 2.0),
        (D, "Pilot", 15.0, 5.0, 2.0),
        (D, None, 16.0, 5.0, NAN),
        (F, None, NAN, NAN, NAN),
    ],
    columns=["mmsi", "ship_type", "length_m", "breadth_m", "draught_m"],
).assign(n_positions=1)


def _check(row, count, missing, mean, median, std, low, high) -> None:  # type: ignore[no-untyped-def]
    assert (row.count, row.missing) == (count, missing)
    got = (row.mean, row.median, row.std, row.min, row.max)
    want = (mean, median, std, low, high)
    for g, w in zip(got, want, strict=True):
        if math.isnan(w):
            assert math.isnan(g)
        else:
            assert g == pytest.approx(w, rel=1e-12)


def test_weighted_median_by_hand() -> None:
    assert weighted_median(np.array([3.0, 1.0, 2.0]), np.array([1, 1, 1])) == 2.0
    assert weighted_median(np.array([1.0, 10.0]), np.array([3, 1])) == 1.0  # [1,1,1,10]
    assert weighted_median(np.array([1.0, 10.0]), np.array([1, 1])) == 5.5
    assert weighted_median(np.array([1.0, 10.0, NAN]), np.array([1, 2, 7])) == 10.0
    assert math.isnan(weighted_median(np.array([NAN]), np.array([3])))
    assert math.isnan(weighted_median(np.array([]), np.array([], dtype=np.int64)))


@given(st.lists(st.tuples(st.integers(1, 400), st.integers(1, 6)), min_size=1, max_size=30))
def test_weighted_median_is_the_median_of_the_expanded_reports(
    reports: list[tuple[int, int]],
) -> None:
    values = np.array([v / 10 for v, _ in reports])
    weights = np.array([w for _, w in reports])
    assert weighted_median(values, weights) == pytest.approx(
        float(np.median(np.repeat(values, weights)))
    )


@given(
    st.lists(
        st.tuples(st.integers(0, 3), st.integers(1, 400), st.integers(1, 6)),
        min_size=1,
        max_size=40,
    )
)
def test_vessel_medians_match_weighted_median_per_vessel(
    reports: list[tuple[int, int, int]],
) -> None:
    frame = pd.DataFrame(
        [(201000000 + vessel, float(v), float(v) / 5, NAN, w) for vessel, v, w in reports],
        columns=["mmsi", "length_m", "breadth_m", "draught_m", "n_reports"],
    )
    medians = vessel_medians(frame)
    for mmsi, group in frame.groupby("mmsi"):
        want = weighted_median(group["length_m"].to_numpy(), group["n_reports"].to_numpy())
        assert medians.loc[mmsi, "length_m"] == pytest.approx(want)
        assert math.isnan(medians.loc[mmsi, "draught_m"])


def test_vessel_medians_by_hand() -> None:
    medians = vessel_medians(DIMENSION_REPORTS)
    assert medians.loc[A].tolist() == [100.0, 20.0, 5.0]
    assert medians.loc[B].tolist() == [55.0, 11.0, 3.5]
    assert medians.loc[C, "length_m"] == 12.0 and math.isnan(medians.loc[C, "draught_m"])
    assert medians.loc[D].tolist() == [15.0, 5.0, 2.0]


def test_ship_type_is_the_most_frequent_one() -> None:
    types = vessel_ship_types(POSITIONS)
    assert types.to_dict() == {A: "Cargo", B: "Cargo", C: "Fishing", D: "Pilot", F: "Unknown"}
    tie = pd.DataFrame(
        {"mmsi": [A, A, A], "ship_type": ["Tug", "Pilot", None], "n_positions": [1, 1, 1]}
    )
    assert vessel_ship_types(tie).loc[A] == "Pilot"  # a tie goes to the first alphabetically


def test_per_vessel_by_hand() -> None:
    result = dimension_stats(POSITIONS, DIMENSION_REPORTS, per=Per.VESSEL)
    assert (result.vessels, result.messages, result.overall.units) == (5, 9, 5)
    assert E not in set(result.samples["mmsi"])
    # length: A 100, B 55, C 12, D 15, F none. mean 182/4 = 45.5; median (15+55)/2 = 35;
    # squared deviations 54.5² + 9.5² + 33.5² + 30.5² = 5113, std = sqrt(5113/3).
    _check(result.overall.row("length_m"), 4, 1, 45.5, 35.0, math.sqrt(5113 / 3), 12, 100)
    # breadth: 20, 11, 4, 5. mean 10; median (5+11)/2 = 8; 10² + 1² + 6² + 5² = 162, /3 = 54.
    _check(result.overall.row("breadth_m"), 4, 1, 10.0, 8.0, math.sqrt(54), 4, 20)
    # draught: 5.0, 3.5, 2.0 (C and F have none). mean 3.5; 1.5² + 0 + 1.5² = 4.5, /2.
    _check(result.overall.row("draught_m"), 3, 2, 3.5, 3.5, 1.5, 2, 5)


def test_per_message_by_hand() -> None:
    result = dimension_stats(POSITIONS, DIMENSION_REPORTS, per=Per.MESSAGE)
    assert result.overall.units == 9
    # length: 100 130 50 12 12 15 15 16 (F's row has none). sum 350, mean 43.75;
    # sorted 12 12 15 15 16 50 100 130 -> median (15+16)/2; Σx² = 10000+16900+2500+144
    # +144+225+225+256 = 30394, minus 350²/8 = 15312.5 gives 15081.5, /7 = 2154.5.
    _check(result.overall.row("length_m"), 8, 1, 43.75, 15.5, math.sqrt(2154.5), 12, 130)
    # breadth: 20 22 10 4 4 5 5 5. sum 75, mean 9.375; median 5; Σx² = 1091,
    # 1091 - 75²/8 = 387.875, /7.
    _check(result.overall.row("breadth_m"), 8, 1, 9.375, 5.0, math.sqrt(387.875 / 7), 4, 22)
    # draught: 5 6 3 2 2. mean 3.6; median 3; Σx² = 78, 78 - 18²/5 = 13.2, /4 = 3.3.
    _check(result.overall.row("draught_m"), 5, 4, 3.6, 3.0, math.sqrt(3.3), 2, 6)


def test_by_ship_type_per_vessel() -> None:
    result = dimension_stats(POSITIONS, DIMENSION_REPORTS, by=GroupBy.SHIP_TYPE)
    groups = {table.group: table for table in result.groups}
    assert list(groups) == ["Cargo", "Fishing", "Pilot", "Unknown"]
    assert {g: t.units for g, t in groups.items()} == {
        "Cargo": 2,
        "Fishing": 1,
        "Pilot": 1,
        "Unknown": 1,
    }
    # Cargo: A 100 and B 55: mean = median = 77.5, std = sqrt(2 · 22.5² / 1).
    _check(groups["Cargo"].row("length_m"), 2, 0, 77.5, 77.5, math.sqrt(1012.5), 55, 100)
    # One value: std is undefined (NaN), not 0.
    _check(groups["Fishing"].row("length_m"), 1, 0, 12, 12, NAN, 12, 12)
    _check(groups["Fishing"].row("draught_m"), 0, 1, NAN, NAN, NAN, NAN, NAN)
    _check(groups["Unknown"].row("breadth_m"), 0, 1, NAN, NAN, NAN, NAN, NAN)
    # The overall table is the same as without grouping.
    assert result.overall == dimension_stats(POSITIONS, DIMENSION_REPORTS).overall

    frame = result.to_frame()
    assert list(frame.columns) == [
        "ship_type",
        "dimension",
        "count",
        "mean",
        "median",
        "std",
        "min",
        "max",
    ]
    # the overall rows first, then each ship type's
    assert len(frame) == (1 + 4) * 3
    assert frame["ship_type"].iloc[:3].tolist() == ["(all)"] * 3
    overall = frame[frame["ship_type"] == "(all)"].drop(columns="ship_type")
    pd.testing.assert_frame_equal(
        overall.reset_index(drop=True), dimension_stats(POSITIONS, DIMENSION_REPORTS).to_frame()
    )
    assert frame.loc[frame["ship_type"] == "Cargo", "count"].tolist() == [2, 2, 2]


def test_by_ship_type_per_message_uses_the_vessel_type() -> None:
    result = dimension_stats(POSITIONS, DIMENSION_REPORTS, per=Per.MESSAGE, by=GroupBy.SHIP_TYPE)
    groups = {table.group: table for table in result.groups}
    # D's row without a ship type still counts as Pilot, D's most frequent type.
    assert groups["Pilot"].units == 3
    # lengths 15 15 16: mean 46/3; deviations -1/3 -1/3 2/3, Σ² = 6/9, /2 = 1/3.
    _check(groups["Pilot"].row("length_m"), 3, 0, 46 / 3, 15, math.sqrt(1 / 3), 15, 16)


def test_reports_lay_out_the_table(tmp_path: Path) -> None:
    result = dimension_stats(POSITIONS, DIMENSION_REPORTS)
    frame = result.to_frame()
    assert list(frame.columns) == ["dimension", "count", "mean", "median", "std", "min", "max"]
    assert frame["dimension"].tolist() == ["length_m", "breadth_m", "draught_m"]

    markdown = format_markdown(result, "hand")
    # One decimal, like the paper: std sqrt(5113/3) = 41.28...
    assert "| Length (m) | 45.5 | 35.0 | 41.3 | 12.0 | 100.0 | 4 | 1 |" in markdown
    assert "| Draught (m) | 3.5 | 3.5 | 1.5 | 2.0 | 5.0 | 3 | 2 |" in markdown

    text = format_text(result, "hand").splitlines()
    assert text[0] == "Vessel dimensions, query 'hand', per vessel (5 vessels)"
    assert text[1].split() == [
        "dimension",
        "count",
        "mean",
        "median",
        "std",
        "min",
        "max",
        "missing",
    ]
    assert text[2].split() == ["length_m", "4", "45.50", "35.00", "41.28", "12.00", "100.00", "1"]

    files = write_stats_reports(tmp_path / "out", result, "hand", {"per": "vessel"})
    assert [f.name for f in files] == [
        "dimension_stats.csv",
        "dimension_stats.md",
        "dimension_histograms.png",
        "index.html",
        "run.json",
    ]
    assert (tmp_path / "out" / "dimension_stats.csv").read_text().splitlines()[0] == (
        "dimension,count,mean,median,std,min,max"
    )
    assert (tmp_path / "out" / "dimension_histograms.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list((tmp_path / "out").glob(".*.tmp"))


def test_one_value_gives_an_empty_std_cell(tmp_path: Path) -> None:
    result = dimension_stats(POSITIONS[POSITIONS["mmsi"] == C], DIMENSION_REPORTS)
    write_stats_reports(tmp_path, result, "one", {})
    lines = (tmp_path / "dimension_stats.csv").read_text().splitlines()
    assert lines[1] == "length_m,1,12.0,12.0,,12.0,12.0"
    assert lines[3] == "draught_m,0,,,,,"


def test_histograms_plot_every_counted_value() -> None:
    result = dimension_stats(POSITIONS, DIMENSION_REPORTS, per=Per.MESSAGE)
    figure = histogram_figure(result, "hand")
    axes = figure.axes
    assert [axis.get_xlabel() for axis in axes] == ["Length (m)", "Breadth (m)", "Draught (m)"]
    for axis, dimension in zip(axes, ("length_m", "breadth_m", "draught_m"), strict=True):
        bars = [p for p in axis.patches if isinstance(p, Rectangle)]
        assert sum(bar.get_height() for bar in bars) == result.overall.row(dimension).count
        lefts = [bar.get_x() for bar in bars]
        assert min(lefts) == pytest.approx(result.overall.row(dimension).min)
    FigureCanvasAgg(figure).draw()  # smoke render


# Position messages: (vessel, ship type, length in dm or none, how many such rows).
MESSAGES = st.lists(
    st.tuples(
        st.integers(0, 4),
        st.sampled_from(["Cargo", "Tanker", None]),
        st.one_of(st.none(), st.integers(50, 3000)),
        st.integers(1, 4),
    ),
    min_size=1,
    max_size=30,
)


def _messages_frame(messages: list[tuple[int, str | None, int | None, int]]) -> pd.DataFrame:
    """One row per message: each drawn row repeated its count of times."""
    rows = [
        (201000000 + vessel, ship_type, NAN if length is None else length / 10, 5.0, NAN)
        for vessel, ship_type, length, times in messages
        for _ in range(times)
    ]
    frame = pd.DataFrame(rows, columns=["mmsi", "ship_type", "length_m", "breadth_m", "draught_m"])
    return frame.assign(n_positions=1)


def _reports_of(frame: pd.DataFrame) -> pd.DataFrame:
    reports = frame.drop(columns=["ship_type", "n_positions"]).dropna(subset=["length_m"])
    return reports.assign(n_reports=1)


@given(MESSAGES, st.sampled_from(list(Per)), st.sampled_from([None, GroupBy.SHIP_TYPE]))
def test_counted_positions_give_the_statistics_of_their_messages(
    messages: list[tuple[int, str | None, int | None, int]], per: Per, by: GroupBy | None
) -> None:
    """Rows standing for several messages each (``n_positions``) give the statistics of the
    messages one row each: per vessel and per message, overall and by ship type."""
    one_each = _messages_frame(messages)
    keys = ["mmsi", "ship_type", "length_m", "breadth_m", "draught_m"]
    counted = (
        one_each.groupby(keys, dropna=False)["n_positions"].sum().reset_index().sample(frac=1.0)
    )
    reports = _reports_of(one_each)
    want = dimension_stats(one_each, reports, per=per, by=by)
    got = dimension_stats(counted, reports, per=per, by=by)
    assert (
        (got.vessels, got.messages)
        == (want.vessels, want.messages)
        == (
            one_each["mmsi"].nunique(),
            len(one_each),
        )
    )
    for got_table, want_table in zip(
        (got.overall, *got.groups), (want.overall, *want.groups), strict=True
    ):
        assert (got_table.group, got_table.units) == (want_table.group, want_table.units)
        for got_row, want_row in zip(got_table.rows, want_table.rows, strict=True):
            assert (got_row.count, got_row.missing) == (want_row.count, want_row.missing)
            for name in ("mean", "median", "std", "min", "max"):
                assert getattr(got_row, name) == pytest.approx(
                    getattr(want_row, name), rel=1e-12, nan_ok=True
                )


@given(st.lists(st.tuples(st.integers(0, 3000), st.integers(1, 50)), min_size=1, max_size=40))
def test_histogram_bins_count_every_unit(values_and_units: list[tuple[int, int]]) -> None:
    """A row standing for k units bins as k rows of one unit; one value takes one bin."""
    frame = pd.DataFrame(values_and_units, columns=["value", "units"]).sort_values("value")
    values, units = frame["value"].to_numpy(dtype=float) / 10, frame["units"].to_numpy()
    expanded = np.repeat(values, units)
    bins = histogram_bins(values, units)
    assert bins == histogram_bins(expanded, np.ones(expanded.size, dtype=np.int64))
    assert 1 <= bins <= HISTOGRAM_MAX_BINS
    if values[0] == values[-1]:
        assert bins == 1
    else:  # at least Sturges' count of bins
        assert bins >= min(HISTOGRAM_MAX_BINS, math.ceil(math.log2(expanded.size) + 1))


def test_histogram_bins_by_hand() -> None:
    # 8 units over 0..7: Sturges gives ceil(log2 8 + 1) = 4; quartiles 1 and 5 (sorted units
    # 0..7 at places 1 and 5), Freedman-Diaconis width 2 · 4 · 8^(-1/3) = 4, 7/4 -> 2 bins.
    assert histogram_bins(np.arange(8.0), np.ones(8, dtype=np.int64)) == 4
    # 1,000 units at 0 and 1,000 at 10: the quartiles 0 and 10 make FD 10 / (20 / 2000^(1/3))
    # = 6.3 -> 7 bins, below Sturges' ceil(log2 2000 + 1) = 12.
    assert histogram_bins(np.array([0.0, 10.0]), np.array([1000, 1000])) == 12
    # Many units spread evenly: FD asks for more than the cap.
    assert histogram_bins(np.arange(2000.0), np.full(2000, 100)) == HISTOGRAM_MAX_BINS


def test_histograms_weigh_each_row_by_its_units() -> None:
    counted = POSITIONS.assign(n_positions=[1, 2, 3, 1, 1, 1, 1, 1, 1])
    result = dimension_stats(counted, DIMENSION_REPORTS, per=Per.MESSAGE, by=GroupBy.SHIP_TYPE)
    assert result.messages == 12
    figure = histogram_figure(result, "counted")
    for axis, dimension in zip(figure.axes, ("length_m", "breadth_m", "draught_m"), strict=True):
        bars = [p for p in axis.patches if isinstance(p, Rectangle)]
        # stacked: each type's bars stand on the others'; the top of each column is the total
        tops: dict[float, float] = {}
        for bar in bars:
            tops[bar.get_x()] = max(tops.get(bar.get_x(), 0.0), bar.get_y() + bar.get_height())
        assert sum(tops.values()) == result.overall.row(dimension).count
        assert axis.get_title() == f"{axis.get_xlabel()}: n = {result.overall.row(dimension).count}"
    FigureCanvasAgg(figure).draw()  # smoke render


def test_no_ship_type_at_all_is_unknown_without_a_warning() -> None:
    untyped = POSITIONS.assign(ship_type=None)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        types = vessel_ship_types(untyped)
        result = dimension_stats(untyped, DIMENSION_REPORTS, by=GroupBy.SHIP_TYPE)
    assert set(types) == {"Unknown"}
    assert [table.group for table in result.groups] == ["Unknown"]
