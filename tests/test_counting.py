"""Rows counted as they stream by (`ais.counting`), and a dataset counted for `stats` in one
scan or two (`ais.dataset_count`)."""

from __future__ import annotations

import shutil
import threading
from pathlib import Path

import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from colregs9_cli.ais import counting
from colregs9_cli.ais.counting import RowCounts, row_runs
from colregs9_cli.ais.dataset_count import DatasetCounts, count_dataset
from colregs9_cli.ais.dataset_scan import Dataset, Positions
from colregs9_cli.ais.duplicates import ROW_ORDER, repeated_rows
from colregs9_cli.ais.load import count_ais, load_ais
from colregs9_cli.cli import app
from colregs9_cli.errors import InputFileError, NoDataError
from colregs9_cli.jobs.ingest import ingest, ingest_with_query
from colregs9_cli.query import Query, Region, everything_query

from fixture_files import DMA22, DMA26

KEYS = ["mmsi", "ship_type", "length_m"]
SCHEMA = pa.schema([("mmsi", pa.int64()), ("ship_type", pa.string()), ("length_m", pa.float64())])

rows = st.lists(
    st.tuples(
        st.sampled_from([1, 2, 3]),
        st.sampled_from([None, "Cargo", "Tanker"]),
        st.sampled_from([None, 0.0, -0.0, float("nan"), 12.5, 200.0]),
    ),
    max_size=60,
)


def _table(values: list[tuple[int, str | None, float | None]]) -> pa.Table:
    return pa.Table.from_pylist([dict(zip(KEYS, v, strict=True)) for v in values], SCHEMA)


def _readable(table: pa.Table) -> list[tuple[str, ...]]:
    """The rows as text: a NaN equals a NaN, and 0.0 is not -0.0."""
    return sorted(tuple(repr(v) for v in row.values()) for row in table.to_pylist())


def _grouped(table: pa.Table) -> list[tuple[str, ...]]:
    counted = table.group_by(KEYS).aggregate([([], "count_all")])
    return _readable(counted.rename_columns([*KEYS, "n"]))


@settings(max_examples=150, deadline=None)
@given(rows, st.lists(st.integers(1, 20), min_size=1, max_size=5), st.booleans(), st.integers(1, 8))
def test_the_counts_are_those_of_arrows_grouping(
    values: list[tuple[int, str | None, float | None]],
    cuts: list[int],
    in_runs: bool,
    chunk_rows: int,
) -> None:
    """In whatever tables and batches the rows come, sorted into runs or not, and however
    often the runs are grouped and merged, the counts are those of one grouping of all the
    rows (nulls, NaN and the sign of zero told apart as it tells them)."""
    if in_runs:
        values = sorted(values, key=repr)
    table = _table(values)
    counts = RowCounts(SCHEMA, "n")
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(counting, "COUNT_CHUNK_ROWS", chunk_rows)
        patch.setattr(counting, "PARTS_BEFORE_MERGE", 2)
        start = 0
        for size in [*cuts, len(values)]:
            counts.add(table.slice(start, size))
            start += size
        got = counts.finish()
    assert _readable(got) == _grouped(table)
    assert got.schema.field("n").type == pa.int64()
    assert got.num_rows == 0 or got.column("mmsi").to_pylist() == sorted(
        got.column("mmsi").to_pylist()
    )


def test_nothing_counted_gives_an_empty_table_of_the_key_types() -> None:
    got = RowCounts(SCHEMA, "n").finish()
    assert got.num_rows == 0
    assert got.schema == pa.schema([*SCHEMA, pa.field("n", pa.int64())])


def test_a_batch_in_runs_gives_one_row_a_run() -> None:
    batch = _table(
        [(1, "Cargo", 12.5)] * 3 + [(1, None, 12.5)] * 2 + [(2, None, None)] * 4 + [(2, None, -0.0)]
    ).to_batches()[0]
    runs = row_runs(batch, "n")
    assert runs.to_pylist() == [
        {"mmsi": 1, "ship_type": "Cargo", "length_m": 12.5, "n": 3},
        {"mmsi": 1, "ship_type": None, "length_m": 12.5, "n": 2},
        {"mmsi": 2, "ship_type": None, "length_m": None, "n": 4},
        {"mmsi": 2, "ship_type": None, "length_m": -0.0, "n": 1},
    ]


column_values = st.one_of(
    st.lists(st.sampled_from([None, 0.0, -0.0, float("nan"), 12.5, 200.0])).map(
        lambda v: pa.array(v, pa.float64())
    ),
    st.lists(st.sampled_from([None, "Cargo", "Tanker", ""])).map(lambda v: pa.array(v)),
    st.lists(st.sampled_from([None, "Cargo", "Tanker"])).map(
        lambda v: pa.array(v, pa.string()).dictionary_encode()
    ),
    st.lists(st.sampled_from([None, -3, 0, 7])).map(lambda v: pa.array(v, pa.int8())),
    st.lists(st.sampled_from([None, 0, 1000])).map(
        lambda v: pa.array(v, pa.timestamp("ms", tz="UTC"))
    ),
    st.lists(st.sampled_from([None, True, False])).map(lambda v: pa.array(v, pa.bool_())),
)


@settings(max_examples=200, deadline=None)
@given(column_values, st.integers(0, 5), st.integers(0, 5))
def test_a_row_changes_where_the_grouping_tells_it_from_the_row_before(
    column: pa.Array, start: int, end: int
) -> None:
    """``changes`` (over Arrow's buffers, a slice of them too) marks a row exactly where it
    and the row before fall in two groups of Arrow's hash grouping (a null equals a null, a
    NaN a NaN, 0.0 is not -0.0)."""
    column = column.slice(start, max(len(column) - start - end, 0))
    groups = pa.table({"v": column, "row": range(len(column))}).group_by("v")
    numbered = groups.aggregate([("row", "list")]).column("row_list").to_pylist()
    group_of = {row: number for number, rows in enumerate(numbered) for row in rows}
    want = [group_of[row] != group_of[row - 1] for row in range(1, len(column))]
    assert counting.changes(column).tolist() == want


def test_rows_that_change_at_every_row_are_kept_as_they_are() -> None:
    """Rows in time order (the vessels interleaved) make a run of every row: counting their
    runs would cost more than it saves, so each row stands for itself."""
    batch = _table([(1 + i % 3, "Cargo", 12.5) for i in range(9)]).to_batches()[0]
    runs = row_runs(batch, "n")
    assert runs.num_rows == 9
    assert runs.column("n").to_pylist() == [1] * 9
    assert runs.drop_columns(["n"]).equals(pa.Table.from_batches([batch]))


@pytest.fixture(scope="module")
def two_day_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two real samples without a date in common: a dataset without duplicates."""
    out = tmp_path_factory.mktemp("counting") / "ais"
    ingest([DMA26, DMA22], out, row_group_rows=700)
    assert Dataset.open(out).duplicate_free
    return out


def _as_lists(counts: DatasetCounts) -> tuple[list[dict[str, object]], list[dict[str, object]]]:
    return (counts.position_counts.to_pylist(), counts.report_counts.to_pylist())


def test_a_query_of_everything_counts_as_a_query_that_selects_all(two_day_dataset: Path) -> None:
    """A query of everything is counted in one scan; a region around the whole world, which
    selects the same rows, in two (the positions, then the vessels' reports). They agree."""
    dataset = Dataset.open(two_day_dataset)
    everything = count_dataset(dataset, everything_query())
    world = count_dataset(dataset, Query("world", region=Region(-90.0, 90.0, -180.0, 180.0)))
    assert everything.position_counts.num_rows > 10
    assert _as_lists(everything) == _as_lists(world)
    positions = pc.sum(everything.position_counts.column("n_positions")).as_py()
    assert positions == sum(f.rows for f in dataset.files) - dataset.static_rows


@pytest.mark.parametrize("rewrite", ["statistics left out", "positions and statics mixed"])
def test_row_groups_the_statistics_cannot_sort_are_counted_alike(
    two_day_dataset: Path, tmp_path: Path, rewrite: str
) -> None:
    """A query of everything reads the coordinates only of the row groups whose statistics
    do not tell positions from static reports: files written without statistics, or with
    both in a row group (not as colregs9 writes them), count as the dataset ingest wrote."""
    copy = tmp_path / "ais"
    shutil.copytree(two_day_dataset, copy)
    for path in copy.rglob("date=*/*.parquet"):
        table = pq.read_table(path)
        if rewrite == "statistics left out":
            pq.write_table(table, path, write_statistics=False)
        else:  # by MMSI: a vessel's static reports among its positions
            pq.write_table(table.sort_by("mmsi"), path, row_group_size=700)
    written, rewritten = Dataset.open(two_day_dataset), Dataset.open(copy)
    assert rewritten.static_rows == written.static_rows > 0
    for dataset in (written, rewritten):
        kinds = {kind: _rows(dataset, kind) for kind in Positions}
        assert sum(kinds.values()) == dataset.rows
        assert (kinds[Positions.SOME] > 0) is (dataset is rewritten)
    query = everything_query()
    assert _as_lists(count_dataset(rewritten, query)) == _as_lists(count_dataset(written, query))


def _rows(dataset: Dataset, kind: Positions) -> int:
    return sum(table.num_rows for table in dataset.row_groups(kind, ["mmsi"]))


def test_a_read_left_early_stops_its_thread(two_day_dataset: Path) -> None:
    """The row groups are read one read ahead, on a thread of their own: a caller that
    stops after the first table (an error in its counting, say) leaves no thread behind."""
    before = threading.active_count()
    reads = Dataset.open(two_day_dataset).row_groups(Positions.ALL, ["mmsi"])
    assert next(reads).num_rows > 0
    assert threading.active_count() == before + 1  # the read ahead
    reads.close()
    assert threading.active_count() == before


def test_a_file_damaged_after_the_dataset_opened_is_one_error(
    two_day_dataset: Path, tmp_path: Path
) -> None:
    copy = tmp_path / "ais"
    shutil.copytree(two_day_dataset, copy)
    dataset = Dataset.open(copy)
    (first, *_) = sorted(copy.rglob("date=*/*.parquet"))
    data = first.read_bytes()
    first.write_bytes(data[:4] + bytes(len(data) - 8) + data[-4:])  # the pages zeroed
    with pytest.raises(InputFileError, match="cannot read the dataset"):
        for _ in dataset.row_groups(Positions.ALL, ["mmsi", "length_m"]):
            pass


duplicated_rows = st.lists(
    st.tuples(
        st.sampled_from([1, 2]),
        st.sampled_from([None, 0, 1000]),
        st.sampled_from([None, "Cargo", "Tanker"]),
        st.sampled_from([None, float("nan"), 0.0, -0.0, 12.5]),
    ),
    max_size=40,
)


@settings(max_examples=150, deadline=None)
@given(duplicated_rows)
def test_repeated_rows_are_those_pandas_finds(
    values: list[tuple[int, int | None, str | None, float | None]],
) -> None:
    """Sorted by MMSI and time, a row equal to an earlier one in every column is repeated,
    as pandas' ``duplicated`` has it (a null equals a null or a NaN, -0.0 equals 0.0)."""
    table = pa.table(
        {
            "mmsi": pa.array([v[0] for v in values], pa.int64()),
            "timestamp": pa.array([v[1] for v in values], pa.timestamp("ms", tz="UTC")),
            "ship_type": pa.array([v[2] for v in values], pa.string()),
            "length_m": pa.array([v[3] for v in values], pa.float64()),
        }
    )
    order = pc.sort_indices(table, sort_keys=ROW_ORDER).to_numpy()
    want = table.take(order).to_pandas().duplicated(keep="first").to_numpy()
    assert repeated_rows(table, order).tolist() == want.tolist()


def test_an_empty_dataset_selects_no_positions(tmp_path: Path) -> None:
    """A dataset of no row (its input's rows all outside the ingest query) is counted empty
    in one scan or two; `stats` says the query selects no position (exit 3)."""
    lines = DMA26.read_text(encoding="utf-8").splitlines(keepends=True)
    positioned = tmp_path / "positioned.csv"  # no static report: each row has a position
    positioned.write_text("".join(line for line in lines if ",91,0," not in line))
    nowhere = Query("nowhere", region=Region(-10.0, -9.0, -10.0, -9.0))
    ingest_with_query([positioned], tmp_path / "ais", nowhere)
    dataset = Dataset.open(tmp_path / "ais")
    assert dataset.rows == 0
    for query in (everything_query(), Query("world", region=Region(-90.0, 90.0, -180.0, 180.0))):
        counts = count_dataset(dataset, query)
        assert counts.position_counts.num_rows == counts.report_counts.num_rows == 0
        with pytest.raises(NoDataError, match="selects no vessel positions"):
            count_ais([tmp_path / "ais"], query)
    result = CliRunner().invoke(app, ["stats", str(tmp_path / "ais"), "--out", str(tmp_path / "o")])
    assert result.exit_code == 3, result.output
    assert result.output.startswith("Error: ")


@pytest.mark.parametrize("columns", [["lat_deg", "lon_deg"], ["timestamp", "sog_kn"]])
def test_positions_may_be_read_without_their_mmsi(columns: list[str]) -> None:
    """Files read whole (duplicates sought across them) give the columns asked for, in
    that order, the MMSI among them or not."""
    whole = load_ais([DMA26, DMA22])
    got = load_ais([DMA26, DMA22], columns=columns)
    assert list(got.positions.columns) == columns
    pd.testing.assert_frame_equal(got.positions, whole.positions[columns])
