"""The load pipeline: query filtering, no-data errors, and the ledger-balance property."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from colregs9_cli.ais import csv_chunks, row_pipeline
from colregs9_cli.ais.load import load_ais
from colregs9_cli.errors import NoDataError
from colregs9_cli.query import Query, Region, TimeWindow, VesselFilter, load_query

from fixture_files import DMA26, ROOT

HEADER = DMA26.read_text().splitlines()[0]


def test_region_box_filters_and_counts_outside(tmp_path: Path) -> None:
    # Rows with lat 57-58 and lon 9-10 (awk on the fixture): 219281000 (57.504843, 9.463187)
    # and 219019010 (57.594313, 9.95935).
    query = Query(name="box", region=Region(57.0, 58.0, 9.0, 10.0))
    data = load_ais([DMA26], query=query)
    assert sorted(data.positions["mmsi"]) == [219019010, 219281000]
    ledger = data.ledger
    # 15 distinct positions in all, 2 inside; the duplicate of 219281000 is inside too.
    assert ledger.rows_outside_query == 13 and ledger.rejects["duplicate"] == 1
    assert ledger.balanced


def test_time_window_and_vessel_filter() -> None:
    import datetime as dt

    start = dt.datetime(2024, 9, 9, 0, 0, 36, tzinfo=dt.UTC)
    query = Query(
        name="late-cargo",
        time=TimeWindow(start=start),
        vessels=VesselFilter(ship_types=frozenset({"cargo"})),
    )
    data = load_ais([DMA26], query=query)
    # Cargo at 00:00:36: HUMBRIA SEAWAYS (twice, one a duplicate) and AASLI; DIONE is at :33.
    assert sorted(data.positions["mmsi"]) == [219281000, 257740000]
    assert data.ledger.balanced


def test_query_selecting_nothing_is_no_data_error() -> None:
    query = load_query(ROOT / "queries" / "aalborg_fjord.toml")
    with pytest.raises(NoDataError) as caught:
        load_ais([DMA26], query=query)
    message = str(caught.value)
    assert "query 'aalborg_fjord'" in message and "selects no vessel positions" in message
    assert "20 rows read" in message
    assert caught.value.exit_code == 3


def test_static_report_outside_query_still_counts_for_dimensions(tmp_path: Path) -> None:
    lines = DMA26.read_text().splitlines()
    static = next(line for line in lines if ",219000179," in line)
    inside = static.replace(",91,0,", ",57.05,9.95,").replace("00:00:34", "00:01:00")
    far = (
        static.replace(",91,0,", ",55.0,12.0,")
        .replace(",6,25,", ",6,30,")
        .replace(",7,18,2,4", ",7,23,2,4")
    )
    path = tmp_path / "v.csv"
    path.write_text("\n".join([HEADER, static, inside, far]) + "\n")
    query = Query(name="fjord", region=Region(57.0, 57.1, 9.9, 10.0))
    data = load_ais([path], query=query)
    assert data.rows_in_query == 1 and data.ledger.rows_outside_query == 1
    reports = data.dimension_reports.set_index("length_m")["n_reports"].to_dict()
    assert reports == {25.0: 2, 30.0: 1}


def test_duplicate_rows_do_not_count_as_dimension_reports(tmp_path: Path) -> None:
    """A row sent three times is one report; a second file repeating it adds none."""
    lines = DMA26.read_text().splitlines()
    row = next(line for line in lines if ",209183000," in line)  # COPERNICUS, with dimensions
    first, second = tmp_path / "a.csv", tmp_path / "b.csv"
    first.write_text("\n".join([HEADER, row, row, row]) + "\n")
    second.write_text("\n".join([HEADER, row]) + "\n")
    data = load_ais([first, second])
    assert data.ledger.rejects["duplicate"] == 3
    assert data.dimension_reports["n_reports"].tolist() == [1]
    assert data.dimension_reports["mmsi"].tolist() == [209183000]


# -- the ledger always balances ----------------------------------------------------------------

MOBILE = st.sampled_from(["Class A", "Class B", "Base Station", "AtoN", "SAR Airborne"])
MMSI = st.sampled_from(["219000179", "257739000", "992111851", "2190045", "abc", ""])
LAT = st.sampled_from(["57.05", "91", "", "north", "-90", "57.0500"])
LON = st.sampled_from(["9.95", "181", "0", "", "12.5"])
TIME = st.sampled_from(["09/09/2024 00:00:34", "09/09/2024 00:00:35", "31/02/2024 00:00:00", "x"])
DIMS = st.sampled_from(["7,18,2,4", ",,,", "0,0,0,0", "7,,2,"])
EXTRA = st.sampled_from(["", ",extra", ",a,b"])


@st.composite
def dma_row(draw: st.DrawFn) -> str:
    return (
        f"{draw(TIME)},{draw(MOBILE)},{draw(MMSI)},{draw(LAT)},{draw(LON)},Unknown value,0,1.5,"
        f"90,91,Unknown,OVLI,NAME,{draw(st.sampled_from(['Cargo', 'Undefined']))},,6,25,GPS,"
        f"{draw(st.sampled_from(['2.5', '', '0']))},Unknown,,AIS,{draw(DIMS)}{draw(EXTRA)}"
    )


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(rows=st.lists(dma_row(), min_size=1, max_size=30), boxed=st.booleans())
def test_ledger_balances_on_generated_dma(tmp_path: Path, rows: list[str], boxed: bool) -> None:
    # One valid row inside the box guarantees data, so every draw checks the balance.
    anchor = (
        "09/09/2024 00:00:40,Class A,219000179,57.05,9.95,Moored,0,0,90,91,Unknown,OVLI,NAME,"
        "Cargo,,6,25,GPS,2.5,Unknown,,AIS,7,18,2,4"
    )
    rows = [*rows, anchor]
    path = tmp_path / "gen.csv"
    path.write_text("\n".join([HEADER, *rows]) + "\n")
    query = Query(name="q", region=Region(57.0, 57.1, 9.9, 10.0)) if boxed else None
    data = load_ais([path], query=query)
    ledger = data.ledger
    assert ledger.rows_read == len(rows)
    assert ledger.rows_read == ledger.rows_used + ledger.rows_outside_query + ledger.rejected_total
    assert data.rows_in_query == len(data.positions) <= ledger.rows_used
    assert not data.positions.duplicated().any()
    assert data.positions["mmsi"].between(201_000_000, 775_999_999).all()
    assert pd.Series(data.positions["mobile_type"]).isin(["Class A", "Class B"]).all()


def test_dimensions_written_two_ways_are_one_report(tmp_path: Path) -> None:
    """The tanker's 288 m once as A+B (223+65) and once as the Length column only: the
    two rows differ as read but clean to the same report, counted twice."""
    lines = DMA26.read_text().splitlines()
    with_abcd = lines[1]
    without = with_abcd.replace("00:00:33", "00:01:33").replace(",223,65,25,24", ",,,,")
    path = tmp_path / "two_ways.csv"
    path.write_text("\n".join([lines[0], with_abcd, without]) + "\n")
    reports = load_ais([path]).dimension_reports
    assert reports.to_dict("records") == [
        {"mmsi": 257739000, "length_m": 288.0, "breadth_m": 49.0, "draught_m": 11.4, "n_reports": 2}
    ]


def test_kept_row_with_a_bad_timestamp_reports_no_dimensions(tmp_path: Path) -> None:
    """Its block's dimensions are counted before its timestamp is read; the rejected row's
    report is taken back, so the counts equal those of the file without it."""
    lines = DMA26.read_text().splitlines()
    tanker = lines[1]  # ARCTIC PRINCESS, 288 m as A+B (223+65)
    later = tanker.replace("00:00:33", "00:01:33")
    broken = tanker.replace("09/09/2024 00:00:33", "32/13/2024 99:00:00").replace(
        ",223,65,25,24", ",300,65,25,24"
    )
    with_broken, without = tmp_path / "with.csv", tmp_path / "without.csv"
    with_broken.write_text("\n".join([HEADER, tanker, broken, later]) + "\n")
    without.write_text("\n".join([HEADER, tanker, later]) + "\n")
    data = load_ais([with_broken])
    assert data.ledger.rejects["unparseable"] == 1
    assert data.ledger.examples["unparseable"] == [
        f"{with_broken}:3: timestamp does not parse or lies outside 1980–2099: "
        "'32/13/2024 99:00:00'"
    ]
    pd.testing.assert_frame_equal(data.dimension_reports, load_ais([without]).dimension_reports)
    assert data.dimension_reports["length_m"].tolist() == [288.0]
    assert data.dimension_reports["n_reports"].tolist() == [2]


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    rows=st.lists(dma_row(), min_size=1, max_size=30),
    boxed=st.booleans(),
    chunk_bytes=st.integers(min_value=1, max_value=2000),
)
def test_small_chunks_and_batches_change_nothing_on_generated_dma(
    tmp_path: Path, rows: list[str], boxed: bool, chunk_bytes: int
) -> None:
    """Rows cut out of many small chunks and settled after each one give the same positions,
    dimension reports and counts as one chunk settled once."""
    anchor = (
        "09/09/2024 00:00:40,Class A,219000179,57.05,9.95,Moored,0,0,90,91,Unknown,OVLI,NAME,"
        "Cargo,,6,25,GPS,2.5,Unknown,,AIS,7,18,2,4"
    )
    path = tmp_path / "gen.csv"
    path.write_text("\n".join([HEADER, *rows, anchor]) + "\n")
    query = Query(name="q", region=Region(57.0, 57.1, 9.9, 10.0)) if boxed else None
    whole = load_ais([path], query=query)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
        patch.setattr(row_pipeline, "_SET_ASIDE_BYTES", 1)
        pieces = load_ais([path], query=query)
    pd.testing.assert_frame_equal(pieces.positions, whole.positions)
    pd.testing.assert_frame_equal(pieces.dimension_reports, whole.dimension_reports)
    counts = {k: v for k, v in whole.ledger.to_dict().items() if k != "reject_examples"}
    assert {k: v for k, v in pieces.ledger.to_dict().items() if k != "reject_examples"} == counts


def test_a_quote_left_open_costs_its_lines_and_loses_none(tmp_path: Path) -> None:
    # pyarrow reads a quoted field across line ends, so a stray quote in a name swallows the
    # lines after it into one malformed record: each of them is counted read and rejected.
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    header, rows = lines[0], lines[1:21]
    fields = rows[1].split(",")
    fields[7] = '"BROKEN NAME'
    rows[1] = ",".join(fields)
    path = tmp_path / "stray_quote.csv"
    path.write_text("\n".join([header, *rows]) + "\n", encoding="utf-8")
    result = load_ais([path])
    ledger = result.ledger
    assert ledger.rows_read == 20
    assert ledger.balanced
    assert ledger.rejects["unparseable"] == 19
    (example,) = ledger.examples["unparseable"]
    assert f"{path}:3:" in example and "a quote left open: 19 lines" in example
