"""`colregs9 ingest` and dataset input: layout, idempotence, appending a day, the same
`stats` and positions as the files, pushdown that really skips row groups, bad input."""

from __future__ import annotations

import gzip
import json
import re
import warnings
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from colregs9_cli.ais import counting
from colregs9_cli.ais.dataset_scan import MANIFEST_NAME, Dataset, position_filter
from colregs9_cli.ais.load import AisData, count_ais, load_ais
from colregs9_cli.ais.schema import CANONICAL_SCHEMA, STATS_POSITION_COLUMNS
from colregs9_cli.cli import app
from colregs9_cli.errors import InputFileError, NoDataError
from colregs9_cli.jobs.ingest import (
    dataset_time_range,
    ingest,
    is_dataset,
    read_dataset_window,
)
from colregs9_cli.query import Query, Region, TimeWindow, VesselFilter, load_query

from fixture_files import DMA22, DMA26, MARINECADASTRE, NMEA, ROOT

LIMFJORDEN = ROOT / "queries" / "limfjorden.toml"


@pytest.fixture(scope="module")
def nmea(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The first 70 s of the NMEA fixture (6130 positions, 50 static reports): quicker."""
    path = tmp_path_factory.mktemp("nmea") / "dma_nmea_70s.txt.gz"
    lines = gzip.decompress(NMEA.read_bytes()).splitlines(keepends=True)
    path.write_bytes(gzip.compress(b"".join(lines[:20000])))
    return path


@pytest.fixture(scope="module")
def files(nmea: Path) -> list[Path]:
    return [DMA26, DMA22, nmea]


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory, files: list[Path]) -> Path:
    """The three fixtures ingested, in small row groups (so that there are some to skip)."""
    out = tmp_path_factory.mktemp("dataset") / "ais"
    ingest(files, out, row_group_rows=500)
    return out


@pytest.fixture(scope="module")
def from_files(files: list[Path]) -> AisData:
    return load_ais(files)


def _snapshot(directory: Path) -> dict[str, tuple[bytes, int]]:
    return {
        str(p.relative_to(directory)): (p.read_bytes(), p.stat().st_mtime_ns)
        for p in sorted(directory.rglob("*"))
        if p.is_file()
    }


def _assert_same(got: AisData, want: AisData) -> None:
    pd.testing.assert_frame_equal(got.positions, want.positions)
    pd.testing.assert_frame_equal(got.dimension_reports, want.dimension_reports)


def test_layout_manifest_and_ledger(dataset: Path, files: list[Path]) -> None:
    assert is_dataset(dataset) and not is_dataset(dataset.parent) and not is_dataset(DMA26)
    manifest = json.loads((dataset / MANIFEST_NAME).read_text())
    assert manifest["format"] == "colregs9-dataset" and len(manifest["inputs"]) == 3
    for entry, path in zip(manifest["inputs"], files, strict=True):
        alone = load_ais([path])
        assert entry["ledger"] == alone.ledger.to_dict()  # the same cleaning and ledger
        assert entry["rows_written"] == alone.ledger.rows_used
        (file,) = entry["files"]
        assert file["path"] == f"date={file['date']}/part-{entry['sha256'][:16]}-0.parquet"
        parquet = pq.ParquetFile(dataset / file["path"])
        assert parquet.schema_arrow.equals(CANONICAL_SCHEMA)
        assert parquet.metadata.row_group(0).column(0).compression == "ZSTD"
        assert (
            max(parquet.metadata.row_group(i).num_rows for i in range(parquet.num_row_groups))
            <= 500
        )
        table = parquet.read()
        static = table.column("lat_deg").is_null().to_numpy(zero_copy_only=False)
        # Static reports kept (with null lat/lon), after the positions.
        assert static.sum() == file["static_rows"] > 0
        assert not static[: len(static) - static.sum()].any()
        positions = table.slice(0, len(static) - int(static.sum())).to_pandas()
        keys = pd.DataFrame(
            {
                "hour": positions["timestamp"].dt.floor("h"),
                "lat": np.floor(positions["lat_deg"]),
                "lon": np.floor(positions["lon_deg"]),
                "mmsi": positions["mmsi"],
                "timestamp": positions["timestamp"],
            }
        )
        assert keys.equals(keys.sort_values(list(keys.columns), kind="stable"))
    assert not list(dataset.glob(".ingest-*"))  # staging removed


def test_ingest_again_adds_nothing(dataset: Path, nmea: Path) -> None:
    before = _snapshot(dataset)
    result = ingest([DMA26, nmea], dataset)
    assert [item.already for item in result.inputs] == [True, True]
    assert "already ingested" in result.text
    assert _snapshot(dataset) == before


def test_a_new_day_appends_a_partition(tmp_path: Path) -> None:
    next_day = tmp_path / "aisdk_2024-09-10.csv"
    next_day.write_text(DMA26.read_text().replace("09/09/2024", "10/09/2024"))
    out = tmp_path / "ais"
    ingest([DMA26], out)
    before = _snapshot(out)
    result = ingest([DMA26, next_day], out)
    assert [item.already for item in result.inputs] == [True, False]
    assert list(result.inputs[1].partitions) == ["2024-09-10"]
    assert sorted(p.name for p in out.glob("date=*")) == ["date=2024-09-09", "date=2024-09-10"]
    after = _snapshot(out)
    assert {k: v for k, v in after.items() if k in before and k != MANIFEST_NAME} == {
        k: v for k, v in before.items() if k != MANIFEST_NAME
    }
    _assert_same(load_ais([out]), load_ais([DMA26, next_day]))


def test_ingest_with_a_query_keeps_its_rows(tmp_path: Path, nmea: Path) -> None:
    result = ingest([nmea], tmp_path / "ais", query_path=LIMFJORDEN)
    query = load_query(LIMFJORDEN)
    want = load_ais([nmea], query)
    assert result.inputs[0].ledger.to_dict() == want.ledger.to_dict()
    _assert_same(load_ais([tmp_path / "ais"], query), want)


def test_an_interrupted_ingest_leaves_nothing_behind(tmp_path: Path) -> None:
    out = tmp_path / "ais"
    ingest([DMA22], out)
    (written,) = out.glob("date=*/part-*.parquet")
    leftover = out / "date=2024-09-09" / f"{written.stem[:21]}-7.parquet"
    leftover.parent.mkdir()
    leftover.write_bytes(written.read_bytes())
    with pytest.raises(InputFileError, match="does not list"):
        Dataset.open(out)
    (out / MANIFEST_NAME).write_text(
        json.dumps({**json.loads((out / MANIFEST_NAME).read_text()), "inputs": []})
    )
    ingest([DMA22], out)  # the same input again: its leftover is replaced
    assert not leftover.exists()
    _assert_same(load_ais([out]), load_ais([DMA22]))


QUERIES = {
    "region": Query("region", region=Region(56.5, 57.2, 8.2, 10.4)),
    "region and window": Query(
        "window",
        region=Region(54.5, 56.0, 10.0, 13.0),
        time=TimeWindow(
            datetime(2013, 11, 12, 12, 0, 20, tzinfo=UTC),
            datetime(2013, 11, 12, 12, 0, 50, tzinfo=UTC),
        ),
    ),
    "vessels": Query(
        "vessels",
        time=TimeWindow(end=datetime(2013, 11, 12, 12, 1, tzinfo=UTC)),
        vessels=VesselFilter(
            mobile_types=frozenset({"Class A"}),
            ship_types=frozenset({"Cargo", "Tanker"}),
            length_min_m=50.0,
            mmsi_exclude=frozenset({219000000}),
        ),
    ),
    "mmsi": Query("mmsi", vessels=VesselFilter(mmsi_include=frozenset({219281000, 257739000}))),
}


@pytest.mark.parametrize("name", ["everything", *QUERIES])
def test_the_dataset_gives_the_positions_of_the_files(
    dataset: Path, files: list[Path], from_files: AisData, name: str
) -> None:
    query = QUERIES.get(name)
    got = load_ais([dataset], query)
    want = from_files if query is None else load_ais(files, query)
    _assert_same(got, want)
    assert got.ledger.balanced
    if query is None:
        assert got.ledger.to_dict() == want.ledger.to_dict()
    assert [i.sha256 for i in got.inputs] == [i.sha256 for i in want.inputs]


def test_the_ledger_counts_what_the_pushdown_skipped(tmp_path: Path, nmea: Path) -> None:
    ingest([nmea], tmp_path / "ais")  # no duplicates: the ledgers agree to the row
    query = QUERIES["region and window"]
    got = load_ais([tmp_path / "ais"], query).ledger.to_dict()
    assert got == load_ais([nmea], query).ledger.to_dict()


@pytest.mark.parametrize(
    "args", [["--by", "ship_type"], ["--per", "message"], ["--query", str(LIMFJORDEN)]]
)
def test_stats_over_the_dataset_equals_stats_over_the_files(
    dataset: Path, files: list[Path], tmp_path: Path, args: list[str]
) -> None:
    outputs = []
    for name, inputs in (("dataset", [str(dataset)]), ("files", [str(f) for f in files])):
        out = tmp_path / name
        result = CliRunner().invoke(app, ["stats", *inputs, *args, "--out", str(out), "--quiet"])
        assert result.exit_code == 0, result.output
        outputs.append((result.stdout, (out / "dimension_stats.csv").read_text()))
    assert outputs[0] == outputs[1]


def _counted_by_pandas(data: AisData) -> pd.DataFrame:
    """The positions counted by their MMSI, ship type and dimensions, with pandas."""
    keys = list(STATS_POSITION_COLUMNS)
    counts = data.positions[keys].groupby(keys, dropna=False).size()
    return counts.rename("n_positions").reset_index()


@pytest.fixture(scope="module")
def nmea_dataset(tmp_path_factory: pytest.TempPathFactory, nmea: Path) -> Path:
    """The NMEA excerpt alone, in small row groups: a dataset without duplicates."""
    out = tmp_path_factory.mktemp("nmea_dataset") / "ais"
    ingest([nmea], out, row_group_rows=500)
    return out


@pytest.mark.parametrize("chunk_rows", [700, 1 << 20])
@pytest.mark.parametrize("name", ["everything", *QUERIES])
def test_a_dataset_is_counted_as_it_is_scanned(
    nmea_dataset: Path, nmea: Path, name: str, chunk_rows: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Counted in chunks of any size, the positions of a dataset read alone are those of the
    file, counted; the reports and the ledger are the file's too."""
    assert Dataset.open(nmea_dataset).duplicate_free  # so no position row is held
    monkeypatch.setattr(counting, "COUNT_CHUNK_ROWS", chunk_rows)
    query = QUERIES.get(name)
    try:
        want = load_ais([nmea], query)
    except NoDataError as error:  # the query 'mmsi' selects none of the excerpt's vessels
        with pytest.raises(NoDataError, match=re.escape(str(error))):
            count_ais([nmea_dataset], query)
        return
    got = count_ais([nmea_dataset], query)
    pd.testing.assert_frame_equal(got.position_counts, _counted_by_pandas(want))
    pd.testing.assert_frame_equal(got.dimension_reports, want.dimension_reports)
    assert got.ledger.to_dict() == want.ledger.to_dict()
    assert got.rows_in_query == want.rows_in_query == got.position_counts["n_positions"].sum()
    assert [i.sha256 for i in got.inputs] == [i.sha256 for i in want.inputs]


@pytest.mark.parametrize("inputs", ["files", "dataset"])
def test_files_are_counted_after_the_load(
    dataset: Path, files: list[Path], from_files: AisData, inputs: str
) -> None:
    """Files (in which duplicates are sought across inputs) are loaded, then counted; a
    dataset of the same files is counted as it is scanned: the same counts."""
    got = count_ais(files if inputs == "files" else [dataset])
    pd.testing.assert_frame_equal(got.position_counts, _counted_by_pandas(from_files))
    pd.testing.assert_frame_equal(got.dimension_reports, from_files.dimension_reports)
    assert got.ledger.to_dict() == from_files.ledger.to_dict()
    assert got.rows_in_query == from_files.rows_in_query


def _corrupt_skipped_row_groups(directory: Path, query: Query) -> int:
    """Overwrite, in every row group the query's pushdown skips, the pages of a column no
    scan of that query needs but the positions' (sog_kn); the number of row groups."""
    opened = Dataset.open(directory)
    expression = position_filter(query)
    column = CANONICAL_SCHEMA.get_field_index("sog_kn")
    corrupted = 0
    for fragment in opened.arrow.get_fragments():
        kept = {
            piece.row_groups[0].id
            for piece in fragment.split_by_row_group(expression, schema=opened.arrow.schema)
        }
        metadata = fragment.metadata
        with open(fragment.path, "r+b") as handle:
            for index in set(range(metadata.num_row_groups)) - kept:
                chunk = metadata.row_group(index).column(column)
                start = min(o for o in (chunk.dictionary_page_offset, chunk.data_page_offset) if o)
                handle.seek(start)
                handle.write(b"\xff" * chunk.total_compressed_size)
                corrupted += 1
    return corrupted


def test_the_pushdown_skips_row_groups(tmp_path: Path, nmea: Path) -> None:
    out = tmp_path / "ais"
    ingest([nmea], out, row_group_rows=200)
    total = sum(f.num_row_groups for f in Dataset.open(out).arrow.get_fragments())
    query = QUERIES["region"]
    corrupted = _corrupt_skipped_row_groups(out, query)
    assert corrupted > total / 2
    # The corrupted pages are never read: the query's positions are all there...
    _assert_same(load_ais([out], query), load_ais([nmea], query))
    # ... and reading them fails, so they would have been noticed.
    with pytest.raises(InputFileError, match="cannot read the dataset"):
        load_ais([out])


def test_read_dataset_window_and_time_range(
    dataset: Path, files: list[Path], from_files: AisData
) -> None:
    start = datetime(2013, 11, 12, 12, 0, 30, tzinfo=UTC)
    end = datetime(2013, 11, 12, 12, 1, tzinfo=UTC)
    query = QUERIES["region"]
    window = read_dataset_window(dataset, query, start, end)
    assert window.schema.equals(CANONICAL_SCHEMA)
    positions = load_ais(files, query).positions
    want = positions[(positions["timestamp"] >= start) & (positions["timestamp"] < end)]
    got = window.to_pandas()
    assert len(got) == len(want) > 0
    for column in ("mmsi", "timestamp", "lat_deg", "lon_deg", "sog_kn"):
        assert got[column].reset_index(drop=True).equals(want[column].reset_index(drop=True))
    first, last = dataset_time_range(dataset)
    stamps = from_files.positions["timestamp"]
    assert (first, last) == (stamps.min(), stamps.max())


def _foreign(directory: Path) -> str:
    pq.write_table(pa.table({"x": [1]}), directory / "date=2024-09-09" / "other.parquet")
    return "other.parquet"


def _wrong_schema(directory: Path) -> str:
    (path,) = directory.glob("date=*/part-*.parquet")
    table = pq.read_table(path)
    pq.write_table(table.set_column(2, "lat_deg", table.column("lat_deg").cast(pa.float32())), path)
    return "lat_deg"


def _no_manifest(directory: Path) -> str:
    (directory / MANIFEST_NAME).unlink()
    return "not a colregs9 dataset"


def _corrupt_manifest(directory: Path) -> str:
    (directory / MANIFEST_NAME).write_text('{"format": "colregs9-dataset", ')
    return "not valid JSON"


def _no_partitions(directory: Path) -> str:
    manifest = json.loads((directory / MANIFEST_NAME).read_text())
    del manifest["inputs"][0]["partitions"]
    (directory / MANIFEST_NAME).write_text(json.dumps(manifest))
    return "input 1 of the manifest is malformed"


@pytest.mark.parametrize("command", ["stats", "ingest"])
@pytest.mark.parametrize(
    "spoil", [_foreign, _wrong_schema, _no_manifest, _corrupt_manifest, _no_partitions]
)
def test_a_bad_dataset_gives_one_error_line(tmp_path: Path, spoil, command: str) -> None:  # type: ignore[no-untyped-def]
    """stats reads the dataset, ingest adds to it (a new input and one already in it): each
    checks it whole first, and ingest leaves it as it was."""
    out = tmp_path / "ais"
    ingest([DMA26], out)
    needle = spoil(out)
    before = _snapshot(tmp_path)
    runs = (
        [["stats", str(out), "--out", str(tmp_path / "s")]]
        if command == "stats"
        else [["ingest", str(path), "--out", str(out), "--quiet"] for path in (DMA22, DMA26)]
    )
    for args in runs:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            result = CliRunner().invoke(app, args)
        assert result.exit_code == 2, result.output
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
        assert needle in lines[0] and str(out) in lines[0]
    if command == "ingest":
        assert _snapshot(tmp_path) == before


def test_ingest_refuses_an_input_without_any_usable_row(tmp_path: Path) -> None:
    """As stats and replay refuse it: one Error line naming the file (exit 2), and nothing
    of it in the dataset; the inputs before it stay ingested."""
    gps_only = tmp_path / "gps.nmea"
    gps_only.write_text("$GPGGA,120000,5700.000,N,01000.000,E,1,08,0.9,10.0,M,,M,,*4F\n")
    out = tmp_path / "ais"
    result = CliRunner().invoke(
        app, ["ingest", str(DMA26), str(gps_only), "--out", str(out), "--quiet"]
    )
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"Error: {gps_only}: no valid AIS position")
    (item,) = Dataset.open(out).inputs
    assert Path(item.path) == DMA26
    assert not list(out.glob(".ingest-*"))


def test_ingest_keeps_an_input_whose_rows_are_all_outside_its_query(tmp_path: Path) -> None:
    """Valid AIS that the ingest query does not select is no error (its static reports,
    which have no position, are kept)."""
    query = tmp_path / "elsewhere.toml"
    query.write_text(
        'name = "elsewhere"\n[region]\nlat_min = -10.0\nlat_max = -9.0\n'
        "lon_min = 0.0\nlon_max = 1.0\n"
    )
    result = CliRunner().invoke(
        app, ["ingest", str(DMA26), "--query", str(query), "--out", str(tmp_path / "ais")]
    )
    assert result.exit_code == 0, result.output
    (item,) = Dataset.open(tmp_path / "ais").inputs
    assert item.ledger.rows_outside_query > 0
    assert item.ledger.rows_used == sum(f.rows for f in item.files)


@pytest.mark.parametrize("target", ["file", "foreign directory"])
def test_ingest_refuses_an_out_that_is_not_a_dataset(tmp_path: Path, target: str) -> None:
    out = tmp_path / "out"
    if target == "file":
        out.write_text("x")
    else:
        out.mkdir()
        (out / "notes.txt").write_text("x")
    before = _snapshot(tmp_path)
    result = CliRunner().invoke(app, ["ingest", str(DMA26), "--out", str(out), "--quiet"])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"Error: {out}: --out "), result.output
    assert _snapshot(tmp_path) == before


def test_ingest_cli_prints_a_summary(tmp_path: Path) -> None:
    out = tmp_path / "ais"
    result = CliRunner().invoke(app, ["ingest", str(DMA26), "--out", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    assert "date=2024-09-09: 18 rows" in result.stdout
    assert "2 rejected (duplicate 1, not_a_vessel 1)" in result.stdout
    again = CliRunner().invoke(app, ["ingest", str(DMA26), "--out", str(out), "--quiet"])
    assert "already ingested" in again.stdout and "1 input(s), 18 rows" in again.stdout


def test_inputs_sharing_a_date_are_told_apart_from_duplicates(tmp_path: Path) -> None:
    lines = DMA26.read_text().splitlines(keepends=True)
    overlapping = tmp_path / "aisdk_2024-09-09_again.csv"
    overlapping.write_text("".join(lines[:-1]))  # another file, the same rows but one
    out = tmp_path / "ais"
    ingest([DMA26, overlapping], out)
    assert not Dataset.open(out).duplicate_free
    want = load_ais([DMA26, overlapping])
    got = load_ais([out])
    _assert_same(got, want)
    counts = [{**ledger.to_dict(), "reject_examples": None} for ledger in (got.ledger, want.ledger)]
    assert counts[0] == counts[1]  # the examples are each input's own, then the run's
    start, end = datetime(2024, 9, 9, tzinfo=UTC), datetime(2024, 9, 10, tzinfo=UTC)
    window = read_dataset_window(out, Query("all"), start, end, columns=["mmsi", "sog_kn"])
    assert window.column_names == ["mmsi", "sog_kn"]
    assert window.column("mmsi").to_pylist() == want.positions["mmsi"].tolist()


def test_a_file_with_its_columns_in_another_order_reads_the_same(tmp_path: Path) -> None:
    out = tmp_path / "ais"
    ingest([DMA26], out)
    before = dataset_time_range(out)
    (path,) = out.glob("date=*/part-*.parquet")
    table = pq.read_table(path)
    pq.write_table(table.select(list(reversed(table.column_names))), path)
    assert dataset_time_range(out) == before


def test_an_input_already_ingested_under_another_query_is_an_error(tmp_path: Path) -> None:
    query = tmp_path / "elsewhere.toml"
    query.write_text(
        'name = "elsewhere"\n[region]\nlat_min = -10.0\nlat_max = -9.0\n'
        "lon_min = 0.0\nlon_max = 1.0\n"
    )
    out = tmp_path / "ais"
    first = CliRunner().invoke(
        app, ["ingest", str(DMA26), "--query", str(query), "--out", str(out)]
    )
    assert first.exit_code == 0, first.output
    again = CliRunner().invoke(app, ["ingest", str(DMA26), "--out", str(out), "--quiet"])
    assert again.exit_code == 2, again.output
    (line,) = again.stderr.strip().splitlines()
    assert "under the query 'elsewhere', not 'all'" in line and line.startswith("Error: ")
    same = CliRunner().invoke(app, ["ingest", str(DMA26), "--query", str(query), "--out", str(out)])
    assert same.exit_code == 0 and "already ingested" in same.output


def test_ingests_into_one_dataset_at_once_keep_every_input(tmp_path: Path) -> None:
    import threading

    out = tmp_path / "ais"
    ingest([DMA26], out)
    errors: list[BaseException] = []

    def run(path: Path) -> None:
        try:
            ingest([path], out)
        except BaseException as exc:
            errors.append(exc)

    threads = [threading.Thread(target=run, args=(p,)) for p in (DMA22, MARINECADASTRE, NMEA)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert errors == []
    listed = {Path(item.path).name for item in Dataset.open(out).inputs}
    assert listed == {p.name for p in (DMA26, DMA22, MARINECADASTRE, NMEA)}
    assert not list(out.glob(".ingest-*"))


def test_staging_left_by_a_killed_ingest_is_cleared_by_the_next(tmp_path: Path) -> None:
    out = tmp_path / "ais"
    ingest([DMA26], out)
    (out / ".ingest-0123456789ab" / "spill").mkdir(parents=True)
    ingest([DMA22], out)
    assert not list(out.glob(".ingest-*"))
    assert len(Dataset.open(out).inputs) == 2


def test_a_failed_first_ingest_leaves_no_directory(tmp_path: Path) -> None:
    out = tmp_path / "new" / "ais"
    result = CliRunner().invoke(app, ["ingest", str(tmp_path / "nosuch.csv"), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert not out.exists()
    gps_only = tmp_path / "gps.nmea"
    gps_only.write_text("$GPRMC,120000,A,5700.0,N,00955.0,E,0.0,0.0,121113,,*00\n")
    result = CliRunner().invoke(app, ["ingest", str(gps_only), "--out", str(out)])
    assert result.exit_code == 2, result.output
    assert not out.exists()


def test_a_directory_of_dot_files_is_not_a_dataset(tmp_path: Path) -> None:
    out = tmp_path / "repo"
    (out / ".git").mkdir(parents=True)
    result = CliRunner().invoke(app, ["ingest", str(DMA26), "--out", str(out), "--quiet"])
    assert result.exit_code == 2, result.output
    assert "holds files but no colregs9-dataset.json" in result.stderr


@pytest.mark.parametrize("command", ["stats", "replay"])
def test_a_report_on_a_dataset_names_the_query_it_was_ingested_through(
    tmp_path: Path, command: str
) -> None:
    """The dataset holds only what its ingest query kept, so a report on it says which."""
    dataset = tmp_path / "ais"
    ingested = CliRunner().invoke(
        app, ["ingest", str(NMEA), "--query", str(LIMFJORDEN), "--out", str(dataset), "--quiet"]
    )
    assert ingested.exit_code == 0, ingested.output
    out = tmp_path / "report"
    options = ["--no-plots"] if command == "replay" else []
    result = CliRunner().invoke(
        app, [command, str(dataset), "--out", str(out), "--quiet", *options]
    )
    assert result.exit_code == 0, result.output
    (item,) = json.loads((out / "run.json").read_text())["inputs"]
    assert item["dataset"] == str(dataset)
    assert item["ingest_query"]["name"] == load_query(LIMFJORDEN).name
    assert item["ingest_query"] == Dataset.open(dataset).inputs[0].entry["query"]
