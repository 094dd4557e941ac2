"""A dataset keeps its static reports whatever its ingest query, and the NMEA files of one
ingest lend each other their static messages: `stats` and `replay` on a dataset give what
they give on the files (issue 31 §3)."""

from __future__ import annotations

import gzip
import itertools
import json
import math
import shutil
import tempfile
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from colregs9_cli.ais.dataset_scan import MANIFEST_NAME, REPORTS_DIR, Dataset
from colregs9_cli.ais.load import load_ais
from colregs9_cli.ais.schema import CANONICAL_SCHEMA
from colregs9_cli.ais.static_join import fill_statics
from colregs9_cli.cli import app
from colregs9_cli.jobs.ingest import ingest

from fixture_files import NMEA

DMA_HEADER = (
    "# Timestamp,Type of mobile,MMSI,Latitude,Longitude,Navigational status,ROT,SOG,COG,"
    "Heading,IMO,Callsign,Name,Ship type,Cargo type,Width,Length,Type of position fixing "
    "device,Draught,Destination,ETA,Data source type,A,B,C,D"
)
SPEED_MPS = 10 * 1852 / 3600
METRES_PER_DEG_LAT = 111_200.0
METRES_PER_DEG_LON = METRES_PER_DEG_LAT * math.cos(math.radians(55.0))
QUERIES = {
    "time": 'name = "jan1"\n[time]\nstart = "2024-01-01T00:00:00Z"\nend = "2024-01-02T00:00:00Z"\n',
    "region": 'name = "box"\n[region]\nlat_min = 54.5\nlat_max = 55.5\nlon_min = 9.5\n'
    "lon_max = 10.5\n",
}


def _dma_row(stamp: str, mmsi: int, lat: float, lon: float, cog: float, dims: str = "") -> str:
    """A DMA 26-column row at 10 kn; ``dims``: 'width,length,draught,A,B,C,D', else none."""
    width, length, draught, a, b, c, d = dims.split(",") if dims else [""] * 7
    return (
        f"{stamp},Class A,{mmsi},{lat:.6f},{lon:.6f},Under way using engine,0,10.0,{cog:.1f},"
        f"{int(cog)},,,NAME{mmsi},Cargo,,{width},{length},GPS,{draught},,,AIS,{a},{b},{c},{d}"
    )


@pytest.fixture(scope="module")
def crossing(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Three vessels on 1 January 2024 00:00-00:10 near 55 N 10 E: 219000001 east at 100 m
    (dimensions on every row), 219000002 north across her track, whose only dimensions (12 m)
    come on a row of 31 December (inside the box), and 219000003 south across it, whose only
    dimensions (50 m) come on a row of 1 January 05:00 at 57 N, outside the box."""
    rows = [DMA_HEADER]
    for s in range(0, 601, 10):
        stamp = f"01/01/2024 00:{s // 60:02d}:{s % 60:02d}"
        east = 10.0 + SPEED_MPS * s / METRES_PER_DEG_LON
        rows.append(_dma_row(stamp, 219000001, 55.0, east, 90, "16,100,6.0,80,20,8,8"))
        north = 55.0 + SPEED_MPS * (s - 300) / METRES_PER_DEG_LAT
        rows.append(_dma_row(stamp, 219000002, north, 10.0 + 1543 / METRES_PER_DEG_LON, 0))
        south = 55.0 - SPEED_MPS * (s - 400) / METRES_PER_DEG_LAT
        rows.append(_dma_row(stamp, 219000003, south, 10.0 + 2058 / METRES_PER_DEG_LON, 180))
    rows.append(_dma_row("31/12/2023 23:50:00", 219000002, 54.98, 10.0, 0, "4,12,1.5,6,6,2,2"))
    rows.append(_dma_row("01/01/2024 05:00:00", 219000003, 57.0, 10.0, 0, "10,50,3.0,40,10,5,5"))
    path = tmp_path_factory.mktemp("crossing") / "crossing.csv"
    path.write_text("\n".join(rows) + "\n")
    return path


def _query(directory: Path, name: str) -> Path:
    path = directory / f"{name}.toml"
    path.write_text(QUERIES[name])
    return path


def _run(*args: str) -> str:
    result = CliRunner().invoke(app, [*args, "--quiet"])
    assert result.exit_code == 0, result.output
    return result.stdout


def _stats(out: Path, *args: str) -> tuple[str, str, dict[str, object]]:
    """``colregs9 stats``: the table printed, dimension_stats.csv and run.json's ledger."""
    text = _run("stats", *args, "--out", str(out))
    ledger = json.loads((out / "run.json").read_text())["ledger"]
    return text, (out / "dimension_stats.csv").read_text(), ledger


@pytest.mark.parametrize("name", list(QUERIES))
def test_stats_on_a_dataset_ingested_through_a_query_equals_stats_on_the_file(
    crossing: Path, tmp_path: Path, name: str
) -> None:
    """The 12 m sent on 31 December (time query) and the 50 m sent outside the box (region
    query) count on the dataset as in the file: per vessel 100, 12 and 50 m."""
    query = _query(tmp_path, name)
    dataset = tmp_path / "ais"
    _run("ingest", str(crossing), "--query", str(query), "--out", str(dataset))
    want = _stats(tmp_path / "files", str(crossing), "--query", str(query))
    assert "length_m       3  54.00   50.00" in want[0]  # (100 + 12 + 50) / 3, median 50
    got = _stats(tmp_path / "dataset", str(dataset), "--query", str(query))
    assert got == want
    assert _stats(tmp_path / "alone", str(dataset))[1] == want[1]  # the ingest query only
    (item,) = Dataset.open(dataset).inputs
    assert item.outside_query_reports is not None and item.outside_query_reports.rows == 1
    assert item.ledger.rows_outside_query == 1  # the row is outside, its report kept apart
    assert item.ledger.balanced and item.ledger.rows_used == sum(f.rows for f in item.files)


@pytest.mark.parametrize(
    ("name", "lengths"),
    [
        ("time", {219000001: 100.0, 219000002: None, 219000003: 50.0}),
        ("region", {219000001: 100.0, 219000002: 12.0, 219000003: None}),
    ],
)
def test_replay_on_the_dataset_equals_replay_on_the_file(
    crossing: Path, tmp_path: Path, name: str, lengths: dict[int, float | None]
) -> None:
    """Replay takes a vessel's dimensions from her positions in the query, on the file as on
    the dataset: the vessel without any in the query has the defaults (None here)."""
    query = _query(tmp_path, name)
    dataset = tmp_path / "ais"
    _run("ingest", str(crossing), "--query", str(query), "--out", str(dataset))
    outputs = []
    for read in (crossing, dataset):
        out = tmp_path / f"replay-{read.name}"
        _run("replay", str(read), "--query", str(query), "--out", str(out), "--no-plots")
        outputs.append([(out / f).read_text() for f in ("pairs.csv", "encounters.csv")])
    assert outputs[0] == outputs[1]
    pairs = pd.read_csv(tmp_path / "replay-ais" / "pairs.csv", keep_default_na=False)
    got = {}
    for seat in ("a", "b"):
        for mmsi, length_m, defaulted in zip(
            pairs[f"mmsi_{seat}"],
            pairs[f"length_m_{seat}"],
            pairs[f"defaulted_dimensions_{seat}"],
            strict=True,
        ):
            got[mmsi] = float(length_m) if defaulted == "" else None
    assert got == lengths


def _units(lines: list[bytes]) -> list[list[bytes]]:
    """The lines of the DMA NMEA log cut before each tag block line: each unit holds a
    tag block, its $PGHP and the sentences they time (a message's fragments together)."""
    units: list[list[bytes]] = [[]]
    for line in lines:
        if line.startswith(b"\\") and units[-1]:
            units.append([])
        units[-1].append(line)
    return units


def _static(unit: list[bytes]) -> bool:
    """Whether the unit holds the first sentence of a static message (type 5 or 24: the
    payload's first character is '5' or 'H')."""
    for line in unit:
        fields = line.split(b",")
        first = line[3:6] == b"VDM" and len(fields) > 5 and fields[2] == b"1"
        if first and fields[5][:1] in (b"5", b"H"):
            return True
    return False


@pytest.fixture(scope="module")
def all_units() -> list[list[bytes]]:
    """The NMEA fixture (5 min) by unit."""
    return _units(gzip.decompress(NMEA.read_bytes()).splitlines(keepends=True))


@pytest.fixture(scope="module")
def log_units(all_units: list[list[bytes]]) -> list[list[bytes]]:
    """Its first 100 s (about 8,000 messages)."""
    return all_units[:8700]


def _split(units: list[list[bytes]], directory: Path) -> tuple[Path, Path, Path]:
    """The log whole, then in two files: the first with its static messages (types 5, 24)
    and its first 100 other messages (so that it holds positions), the second with the rest:
    the vessels' static messages lie in the first file, all but a second of their positions
    in the second."""
    whole, first, second = (directory / n for n in ("whole.txt", "first.txt", "second.txt"))
    whole.write_bytes(b"".join(line for unit in units for line in unit))
    statics = [unit for unit in units if _static(unit)]
    others = [unit for unit in units if not _static(unit)]
    first.write_bytes(b"".join(line for unit in [*statics, *others[:100]] for line in unit))
    second.write_bytes(b"".join(line for unit in others[100:] for line in unit))
    return whole, first, second


@pytest.fixture(scope="module")
def split_log(
    tmp_path_factory: pytest.TempPathFactory, log_units: list[list[bytes]]
) -> tuple[Path, Path, Path]:
    return _split(log_units, tmp_path_factory.mktemp("split"))


def _sorted(positions: pd.DataFrame) -> pd.DataFrame:
    return positions.sort_values(["mmsi", "timestamp"], kind="stable", ignore_index=True)


def test_static_messages_join_across_the_files_of_one_ingest(
    split_log: tuple[Path, Path, Path], tmp_path: Path
) -> None:
    whole, first, second = split_log
    want = load_ais([whole])
    # Each file alone: the second's positions lack the static fields of the first's reports.
    lengths = sum(load_ais([f]).positions["length_m"].notna().sum() for f in (first, second))
    assert lengths < want.positions["length_m"].notna().sum() - 100
    dataset = tmp_path / "ais"
    ingest([first, second], dataset)
    for got in (load_ais([dataset]), load_ais([first, second])):
        pd.testing.assert_frame_equal(_sorted(got.positions), _sorted(want.positions))
        pd.testing.assert_frame_equal(got.dimension_reports, want.dimension_reports)
    for args in ([], ["--per", "message"], ["--by", "ship_type"]):
        tables = {
            name: _stats(tmp_path / f"{name}{len(args)}", *read, *args)[:2]
            for name, read in (
                ("whole", [str(whole)]),
                ("dataset", [str(dataset)]),
                ("files", [str(first), str(second)]),
            )
        }
        assert tables["dataset"] == tables["whole"] == tables["files"]


def test_replay_of_a_split_log_equals_replay_of_the_whole(
    all_units: list[list[bytes]], tmp_path: Path
) -> None:
    """Over the 5 minutes, three seats of the triggered pairs have their vessel's reported
    dimensions, sent in static messages that the split puts in the first file alone."""
    whole, first, second = _split(all_units, tmp_path)
    outputs = []
    for read in ([whole], [first, second]):
        out = tmp_path / f"replay-{read[0].stem}"
        _run("replay", *map(str, read), "--out", str(out), "--no-plots")
        outputs.append([(out / f).read_text() for f in ("pairs.csv", "encounters.csv")])
    assert outputs[0] == outputs[1]
    pairs = pd.read_csv(tmp_path / "replay-whole" / "pairs.csv")
    reported = pairs[["defaulted_dimensions_a", "defaulted_dimensions_b"]].isna()
    assert reported.to_numpy().sum() == 3


# Cuts between messages of the first 3,000 units, at least 100 units (about 100 positions)
# from each other and from the ends: ingest refuses a part without any position.
CUTS = (
    st.lists(st.integers(100, 2900), min_size=1, max_size=3, unique=True)
    .map(sorted)
    .filter(lambda cuts: all(b - a >= 100 for a, b in itertools.pairwise(cuts)))
)


@settings(max_examples=8, deadline=None)
@given(cuts=CUTS)
def test_any_split_of_a_log_ingested_together_gives_the_whole_logs_tables(
    log_units: list[list[bytes]], cuts: list[int]
) -> None:
    """A log cut between messages into parts, ingested together: the positions (with their
    static fields) and the dimension reports, all that the stats tables are made of, are the
    whole log's."""
    units = log_units[:3000]  # about 35 s: quick to ingest
    bounds = [0, *cuts, len(units)]
    with tempfile.TemporaryDirectory() as scratch:
        directory = Path(scratch)
        parts = []
        for number, (start, end) in enumerate(itertools.pairwise(bounds)):
            part = directory / f"part{number}.txt"
            part.write_bytes(b"".join(line for unit in units[start:end] for line in unit))
            parts.append(part)
        whole = directory / "whole.txt"
        whole.write_bytes(b"".join(part.read_bytes() for part in parts))
        want = load_ais([whole])
        ingest(parts, directory / "ais")
        got = load_ais([directory / "ais"])
    pd.testing.assert_frame_equal(_sorted(got.positions), _sorted(want.positions))
    pd.testing.assert_frame_equal(got.dimension_reports, want.dimension_reports)


def _as_version_2(dataset: Path) -> None:
    """Make ``dataset`` what colregs9 wrote before format version 3: no reports outside the
    ingest query (neither the files nor the manifest's key)."""
    manifest = json.loads((dataset / MANIFEST_NAME).read_text())
    for entry in manifest["inputs"]:
        entry["format_version"] = 2
        del entry["outside_query_reports"]
    manifest["format_version"] = 2
    del manifest["outside_query_reports"]
    (dataset / MANIFEST_NAME).write_text(json.dumps(manifest))
    shutil.rmtree(dataset / REPORTS_DIR)


def test_a_version_2_dataset_is_read_and_upgraded(crossing: Path, tmp_path: Path) -> None:
    """A dataset of format version 2 is read as before (without the reports its ingest query
    left out: the mean length of two vessels, 75 m); an ingest into it adds version 3."""
    query = _query(tmp_path, "time")
    dataset = tmp_path / "ais"
    _run("ingest", str(crossing), "--query", str(query), "--out", str(dataset))
    _as_version_2(dataset)
    text = _stats(tmp_path / "v2", str(dataset))[0]
    assert "length_m       2  75.00   75.00" in text and "(3 vessels)" in text
    later = tmp_path / "later.csv"
    later.write_text(crossing.read_text().replace("/2024 00:", "/2024 01:"))
    ingest([later], dataset, query_path=query)
    manifest = json.loads((dataset / MANIFEST_NAME).read_text())
    assert manifest["format_version"] == 3
    assert [entry["format_version"] for entry in manifest["inputs"]] == [2, 3]
    assert [i.outside_query_reports is None for i in Dataset.open(dataset).inputs] == [
        True,
        False,
    ]


def test_a_missing_file_of_reports_is_one_error_line(crossing: Path, tmp_path: Path) -> None:
    query = _query(tmp_path, "region")
    dataset = tmp_path / "ais"
    _run("ingest", str(crossing), "--query", str(query), "--out", str(dataset))
    (reports,) = (dataset / REPORTS_DIR).iterdir()
    reports.unlink()
    result = CliRunner().invoke(app, ["stats", str(dataset), "--out", str(tmp_path / "s")])
    assert result.exit_code == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0] == (
        f"Error: {reports}: listed in the dataset manifest but missing; re-create the dataset "
        "with colregs9 ingest"
    )


def _canonical(rows: list[dict[str, object]]) -> pa.Table:
    columns = {f.name: [row.get(f.name) for row in rows] for f in CANONICAL_SCHEMA}
    return pa.Table.from_pydict(columns, schema=CANONICAL_SCHEMA)


def test_each_field_comes_from_the_nearest_report_that_has_it() -> None:
    """Hand-worked: a field a position has is kept; each missing one comes from the nearest
    report of her MMSI that has it, A, B, C, D together from one report."""
    at = [datetime(2024, 1, 1, 0, 0, s, tzinfo=UTC) for s in range(60)]
    positions = _canonical(
        [
            {"timestamp": at[0], "mmsi": 219000001, "lat_deg": 55.0, "lon_deg": 10.0},
            {"timestamp": at[20], "mmsi": 219000001, "lat_deg": 55.0, "length_m": 30.0},
            {"timestamp": at[20], "mmsi": 219000009, "lat_deg": 55.0, "lon_deg": 10.0},
        ]
    )
    statics = _canonical(
        [
            {"timestamp": at[5], "mmsi": 219000001, "name": "EARLY", "length_m": 40.0},
            {"timestamp": at[14], "mmsi": 219000001, "draught_m": 4.0, "to_bow_m": 9.0},
            {
                "timestamp": at[50],
                "mmsi": 219000001,
                "name": "LATE",
                "to_bow_m": 1.0,
                "to_stern_m": 2.0,
                "to_port_m": 3.0,
                "to_starboard_m": 4.0,
            },
        ]
    )
    filled = fill_statics(positions, statics).to_pandas()
    assert filled["name"].tolist()[:2] == ["EARLY", "EARLY"] and pd.isna(filled.loc[2, "name"])
    assert filled["length_m"].tolist()[:2] == [40.0, 30.0]  # her own 30 m is kept
    assert filled["draught_m"].tolist()[:2] == [4.0, 4.0]
    offsets = filled[["to_bow_m", "to_stern_m", "to_port_m", "to_starboard_m"]].to_numpy()
    np.testing.assert_array_equal(offsets[:2], [[9.0, np.nan, np.nan, np.nan]] * 2)
    assert np.isnan(filled.loc[2, ["length_m", "draught_m", "to_bow_m"]].astype(float)).all()
