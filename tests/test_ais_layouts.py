"""The CSV layouts read through column maps (MarineCadastre 2015-2017 and 2025, exactEarth/
Spire, --columns maps), header-less chunks, and NMEA logs without any time."""

from __future__ import annotations

import csv
import gzip
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pytest

from colregs9_cli.ais.column_map import BUILTIN_MAPS, load_column_map, map_layout
from colregs9_cli.ais.detect import detect_layout
from colregs9_cli.ais.dispatch import READERS
from colregs9_cli.ais.layouts import (
    DMA22_COLUMNS,
    DMA26_COLUMNS,
    DMA_COLUMNS,
    LAYOUTS,
    ReadAs,
    find_layout,
)
from colregs9_cli.ais.load import load_ais
from colregs9_cli.ais.sources import inspect_source, read_head
from colregs9_cli.errors import InputFileError, ParameterError
from colregs9_cli.jobs.ingest import ingest
from colregs9_cli.jobs.stats import run_stats

from fixture_files import AIS_FIXTURES, DMA22, DMA26, MARINECADASTRE, NMEA, ROOT

MC2015 = AIS_FIXTURES / "marinecadastre2015_sample.csv"
MC2025 = AIS_FIXTURES / "marinecadastre2025_sample.csv.zst"
EXACTEARTH = AIS_FIXTURES / "exactearth_sample.csv"
AISHUB = AIS_FIXTURES / "aishub_sample.csv"
KYSTVERKET = AIS_FIXTURES / "kystverket_sample.csv"
MAPS = ROOT / "examples" / "column_maps"
SOURCE_ROWS = 40  # the MarineCadastre rows each sample was made from (scripts/)


def _source() -> pd.DataFrame:
    """The rows scripts/make_layout_samples.py takes: the first 34 and 6 Class B after."""
    source = pd.read_csv(MARINECADASTRE)
    later_b = source.index[(source.index >= 34) & (source["TransceiverClass"] == "B")][:6]
    return source.loc[sorted([*range(34), *later_b])]


def _positions_key(frame: pd.DataFrame) -> list[tuple[int, float, float]]:
    return sorted(
        (int(m), round(float(a), 5), round(float(o), 5))
        for m, a, o in zip(frame["mmsi"], frame["lat_deg"], frame["lon_deg"], strict=True)
    )


def _source_key() -> list[tuple[int, float, float]]:
    source = _source()
    return sorted(
        (int(m), round(float(a), 5), round(float(o), 5))
        for m, a, o in zip(source["MMSI"], source["LAT"], source["LON"], strict=True)
    )


@pytest.mark.parametrize(
    ("path", "layout", "rejects"),
    [
        (MC2015, "marinecadastre2015", {"invalid_mmsi": 1, "position_not_available": 1}),
        (MC2025, "marinecadastre2025", {"duplicate": 1, "unparseable": 1}),
        (EXACTEARTH, "exactearth", {"not_a_vessel": 1, "unsupported_message_type": 1}),
    ],
    ids=["marinecadastre2015", "marinecadastre2025", "exactearth"],
)
def test_layout_detected_and_ledger_exact(path: Path, layout: str, rejects: dict) -> None:
    data = load_ais([path])
    assert data.inputs[0].layout == layout
    ledger = data.ledger
    assert dict(ledger.rejects) == rejects
    assert ledger.balanced and ledger.rows_outside_query == 0
    # every sample holds the 40 source positions, at their own places (never lat/lon swapped)
    assert _positions_key(data.positions) == _source_key()


def test_marinecadastre2015_class_unknown_but_vessels() -> None:
    data = load_ais([MC2015])
    assert data.positions["mobile_type"].isna().all()
    assert data.positions["timestamp"].min() == pd.Timestamp("2016-01-11", tz="UTC")
    row = data.positions.loc[data.positions["mmsi"] == 636021061].iloc[0]
    assert (row["ship_type"], row["length_m"], row["imo"]) == ("Cargo", 208.0, 9307839)


def test_marinecadastre2015_mobile_filter_leaves_unknown_class_out(tmp_path: Path) -> None:
    query = tmp_path / "class_a.toml"
    query.write_text('name = "a"\n[vessels]\nmobile_types = ["Class A"]\n')
    with pytest.raises(Exception, match="selects no vessel positions"):
        run_stats([MC2015], query_path=query, out_dir=tmp_path / "out")


def test_marinecadastre2025_same_rows_as_2023_layout() -> None:
    new = load_ais([MC2025]).positions
    old = load_ais([MARINECADASTRE]).positions
    old = old[old["mmsi"].isin(new["mmsi"])]
    columns = ["mmsi", "lat_deg", "lon_deg", "sog_kn", "cog_deg", "mobile_type", "length_m"]
    merged = new[columns].merge(old[columns].drop_duplicates(), how="left", indicator=True)
    assert (merged["_merge"] == "both").all()
    classes = {"A": "Class A", "B": "Class B"}
    assert set(new["mobile_type"]) == {classes[c] for c in _source()["TransceiverClass"]}


def test_headerless_chunk_refused_unless_layout_named(tmp_path: Path) -> None:
    with pa.input_stream(str(MC2025), compression="zstd") as stream:
        text = stream.read().decode()
    chunk = tmp_path / "chunk.csv"
    chunk.write_text("".join(text.splitlines(keepends=True)[1:11]))
    with pytest.raises(InputFileError, match="no header line") as caught:
        load_ais([chunk])
    assert "marinecadastre2025" in str(caught.value) and "--columns" in str(caught.value)
    data = load_ais([chunk], fmt="marinecadastre2025")
    assert data.positions["lat_deg"].between(20, 50).all()  # US waters, not Antarctica
    assert data.positions["lon_deg"].between(-125, -65).all()
    # named as the 2018-2024 layout, it would be read with longitude as latitude (-70 to -80:
    # Antarctica, as the issue saw): which is why the columns are never guessed
    swapped = load_ais([chunk], fmt="marinecadastre").positions
    assert swapped["lat_deg"].lt(-60).all()


def test_headerless_exactearth_and_map_refused(tmp_path: Path) -> None:
    chunk = tmp_path / "chunk.csv"
    chunk.write_text("".join(EXACTEARTH.read_text().splitlines(keepends=True)[1:5]))
    with pytest.raises(InputFileError, match="exactearth files differ"):
        load_ais([chunk], fmt="exactearth")
    headerless = tmp_path / "aishub.csv"
    headerless.write_text("".join(AISHUB.read_text().splitlines(keepends=True)[1:]))
    with pytest.raises(InputFileError, match="names columns, not their order"):
        load_ais([headerless], fmt=map_layout(MAPS / "aishub.toml"))


def test_exactearth_milliseconds_classes_and_statics() -> None:
    data = load_ais([EXACTEARTH])
    positions = data.positions
    milliseconds = positions["timestamp"].dt.microsecond // 1000
    assert milliseconds.nunique() > 10
    raw = pd.read_csv(EXACTEARTH)
    expected = {
        "Class A": (raw["Message_ID"] == 1).sum(),
        "Class B": (raw["Message_ID"] == 18).sum(),
    }
    counts = positions["mobile_type"].value_counts().to_dict()
    assert counts == {k: v for k, v in expected.items() if v}
    # the static messages are static reports: used, their A+B the vessel's length
    statics = int(raw["Message_ID"].isin([5, 24]).sum())
    assert data.ledger.rows_used == len(positions) + statics
    reports = data.dimension_reports.set_index("mmsi")
    assert reports.loc[636021061, "length_m"] == 208.0
    assert reports.loc[636021061, "breadth_m"] == 30.0


def test_exactearth_true_heading_alias(tmp_path: Path) -> None:
    text = EXACTEARTH.read_text().replace(",Heading,", ",True_heading,", 1)
    path = tmp_path / "spire.csv"
    path.write_text(text)
    data = load_ais([path])
    assert (
        data.positions["heading_deg"].notna().sum()
        == load_ais([EXACTEARTH]).positions["heading_deg"].notna().sum()
        > 0
    )


def test_aishub_map_units_and_sentinels() -> None:
    data = load_ais([AISHUB], fmt=map_layout(MAPS / "aishub.toml"))
    assert data.inputs[0].layout.endswith("aishub.toml") and data.ledger.balanced
    assert _positions_key(data.positions) == _source_key()
    assert data.positions["rot_deg_per_min"].isna().all()  # 128: not available
    row = data.positions.loc[data.positions["mmsi"] == 636021061].iloc[0]
    assert (row["length_m"], row["breadth_m"], row["draught_m"]) == (208.0, 30.0, 8.0)
    assert row["timestamp"] == pd.Timestamp("2023-01-11", tz="UTC")


def test_aishub_ais_format_map(tmp_path: Path) -> None:
    frame = pd.read_csv(AISHUB, keep_default_na=False)
    stamps = pd.to_datetime(frame["TIME"].str.removesuffix(" GMT"))
    frame["TIME"] = ((stamps - pd.Timestamp(0)) // pd.Timedelta(seconds=1)).astype(str)
    frame["LONGITUDE"] = (frame["LONGITUDE"].astype(float) * 600000).round().astype(int)
    frame["LATITUDE"] = (frame["LATITUDE"].astype(float) * 600000).round().astype(int)
    frame["SOG"] = (frame["SOG"].astype(float) * 10).round().astype(int)
    frame["COG"] = (frame["COG"].astype(float) * 10).round().astype(int)
    frame["DRAUGHT"] = (frame["DRAUGHT"].astype(float) * 10).round().astype(int)
    path = tmp_path / "aishub_ais.csv"
    frame.to_csv(path, index=False)
    encoded = load_ais([path], fmt=map_layout(MAPS / "aishub_ais_format.toml")).positions
    human = load_ais([AISHUB], fmt=map_layout(MAPS / "aishub.toml")).positions
    for column in ("lat_deg", "lon_deg", "sog_kn", "cog_deg", "draught_m", "timestamp"):
        pd.testing.assert_series_equal(encoded[column], human[column], check_exact=False, atol=1e-5)


def test_kystverket_semicolons_and_message_numbers() -> None:
    data = load_ais([KYSTVERKET], fmt=map_layout(MAPS / "kystverket.toml"))
    assert _positions_key(data.positions) == _source_key()
    source = _source()
    assert (data.positions["mobile_type"] == "Class B").sum() == (
        source["TransceiverClass"] == "B"
    ).sum()
    assert data.ledger.balanced


def _map(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return path


GOOD = '[columns]\nmmsi = "mmsi"\nt = "timestamp"\nlat = "lat_deg"\nlon = "lon_deg"\n'
GOOD_TIME = '[time]\nformat = "%Y"\n'


@pytest.mark.parametrize(
    ("text", "key"),
    [
        (GOOD.replace('"lat_deg"', '"latitude"') + GOOD_TIME, "[columns] 'lat'"),
        (GOOD.replace('lat = "lat_deg"\n', "") + GOOD_TIME, "[columns]: no column is 'lat_deg'"),
        (GOOD + '[time]\nformat = "iso"\n', "[time] format"),
        (GOOD, "[time]: missing"),
        (GOOD + GOOD_TIME + '[units]\nsog_kn = "mph"\n', "[units] sog_kn"),
        (GOOD + GOOD_TIME + '[units]\nname = "m"\n', "[units] name"),
        (GOOD + GOOD_TIME + '[units]\nsog_kn = ["kn"]\n', "[units] sog_kn"),
        (GOOD + GOOD_TIME + "[units]\nsog_kn = { x = 1 }\n", "[units] sog_kn"),
        (GOOD + GOOD_TIME + "[sentinels]\nsog_kn = 102.3\n", "[sentinels] sog_kn"),
        (GOOD + GOOD_TIME + 'colour = "red"\n', "colour: unknown key"),
        ('delimiter = "ab"\n' + GOOD + GOOD_TIME, "delimiter"),
        (GOOD + 'x = "mmsi"\n' + GOOD_TIME, "'mmsi' is already"),
        ("columns = [1, 2]\n" + GOOD_TIME, "columns"),
        ("[columns\n", "not valid TOML"),
    ],
)
def test_map_errors_name_file_and_key(tmp_path: Path, text: str, key: str) -> None:
    path = _map(tmp_path, text)
    load_column_map.cache_clear()
    with pytest.raises(ParameterError) as caught:
        load_column_map(path)
    message = str(caught.value)
    assert str(path) in message and key in message and "\n" not in message


def test_map_column_missing_in_file(tmp_path: Path) -> None:
    text = (MAPS / "aishub.toml").read_text().replace("DRAUGHT =", "DRAFT =")
    path = _map(tmp_path, text)
    with pytest.raises(InputFileError, match="names the column 'draft'"):
        load_ais([AISHUB], fmt=map_layout(path))


def _cli(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "colregs9_cli", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        check=False,
    )


def test_cli_columns_stats_and_errors(tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = _cli(
        "stats",
        str(AISHUB),
        "--columns",
        str(MAPS / "aishub.toml"),
        "--out",
        str(out),
        "--quiet",
        cwd=tmp_path,
    )
    assert done.returncode == 0 and done.stderr == ""
    run = json.loads((out / "run.json").read_text())
    assert run["ledger"]["rows_read"] == SOURCE_ROWS
    bad = _map(tmp_path, GOOD + '[time]\nformat = "when"\n')
    for args in (
        ("--columns", str(bad)),
        ("--columns", str(tmp_path / "none.toml")),
        ("--columns", str(MAPS / "aishub.toml"), "--format", "dma26"),
    ):
        failed = _cli("stats", str(AISHUB), *args, "--out", str(tmp_path / "o2"), cwd=tmp_path)
        lines = failed.stderr.strip().splitlines()
        assert failed.returncode == 2 and len(lines) == 1 and lines[0].startswith("Error: ")
        assert "Traceback" not in failed.stderr


# -- NMEA without timestamps ------------------------------------------------------------------


@pytest.fixture(scope="module")
def timeless(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The DMA log's first 20,000 lines without their $PGHP lines and tag blocks."""
    lines = gzip.decompress(NMEA.read_bytes()).decode().splitlines()[:20000]
    kept = [
        line.split("\\")[-1]
        for line in lines
        if not line.startswith("$PGHP") and line.split("\\")[-1].strip()
    ]
    path = tmp_path_factory.mktemp("nmea") / "notime.nmea"
    path.write_text("\n".join(kept) + "\n")
    return path


def test_stats_reads_nmea_without_time(timeless: Path, tmp_path: Path) -> None:
    run = run_stats([timeless], out_dir=tmp_path / "out")
    ledger = run.manifest["ledger"]
    assert ledger["rows_read"] == (
        ledger["rows_used"] + ledger["rows_outside_query"] + ledger["rows_rejected"]
    )
    assert ledger["time_sources"] == {"none": ledger["rows_read"]}
    assert run.result.to_frame()["count"].sum() > 0
    written = json.loads((tmp_path / "out" / "run.json").read_text())
    assert written["ledger"]["time_sources"] == {"none": ledger["rows_read"]}


def test_time_window_leaves_timeless_rows_outside(timeless: Path, tmp_path: Path) -> None:
    query = tmp_path / "window.toml"
    query.write_text('name = "w"\n[time]\nstart = 2013-11-12T00:00:00Z\n')
    with pytest.raises(Exception, match="selects no vessel positions"):
        run_stats([timeless], query_path=query, out_dir=tmp_path / "out")


def test_replay_and_ingest_refuse_nmea_without_time(timeless: Path, tmp_path: Path) -> None:
    with pytest.raises(InputFileError) as caught:
        load_ais([timeless])
    message = str(caught.value)
    assert str(timeless) in message and "no line has a time" in message
    assert "$PGHP" in message and "tag blocks" in message and "colregs9 stats" in message
    with pytest.raises(InputFileError, match="no line has a time"):
        ingest([timeless], tmp_path / "dataset", quiet=True)


def test_nmea_with_some_times_keeps_rejecting_the_rest(tmp_path: Path) -> None:
    lines = gzip.decompress(NMEA.read_bytes()).decode().splitlines()[:3000]
    path = tmp_path / "mixed.nmea"
    path.write_text("\n".join([*lines, "!AIVDM,1,1,,A,13u?etPv2;0n:dDPwUM1U1Cb069D,0*5C"]) + "\n")
    data = load_ais([path])
    assert data.ledger.rejects["unparseable"] >= 1 and data.ledger.balanced
    assert np.isin(["none"], list(data.ledger.time_sources)).sum() == 0


def test_dma_file_with_every_field_quoted_reads_as_the_original(tmp_path: Path) -> None:

    quoted = tmp_path / "quoted.csv"
    with DMA26.open(encoding="utf-8", newline="") as source, quoted.open("w", newline="") as out:
        csv.writer(out, quoting=csv.QUOTE_ALL).writerows(csv.reader(source))
    assert quoted.read_text().startswith('"# Timestamp","Type of mobile"')
    original, again = load_ais([DMA26]), load_ais([quoted])
    pd.testing.assert_frame_equal(original.positions, again.positions)
    assert again.ledger.rejects == original.ledger.rejects


def test_padded_numbers_beside_null_text_are_numbers(tmp_path: Path) -> None:
    lines = MARINECADASTRE.read_text(encoding="utf-8").splitlines()[:4]
    header = lines[0].split(",")
    draft, length = header.index("Draft"), header.index("Length")
    rows = [line.split(",") for line in lines[1:]]
    rows[0][draft], rows[1][draft], rows[2][draft] = " 8.0", "NULL", "7.5 "
    rows[0][length] = " 99 "
    padded = tmp_path / "padded.csv"
    padded.write_text("\n".join([lines[0], *(",".join(r) for r in rows)]) + "\n")
    data = load_ais([padded])
    by_mmsi = data.dimension_reports.groupby("mmsi").first()
    assert sorted(by_mmsi["draught_m"].dropna()) == [7.5, 8.0]
    assert 99.0 in set(by_mmsi["length_m"])
    assert data.ledger.rejected_total == 0


def test_every_time_unreadable_names_the_first_value(tmp_path: Path) -> None:
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    iso = [lines[0], *(line.replace("09/09/2024 ", "2024-09-09T", 1) for line in lines[1:])]
    path = tmp_path / "iso.csv"
    path.write_text("\n".join(iso) + "\n")
    with pytest.raises(InputFileError) as caught:
        load_ais([path])
    message = str(caught.value)
    assert "the first unparseable row" in message
    assert f"{path}:2: timestamp does not parse" in message and "'2024-09-09T00:00:33'" in message


def test_marinecadastre_times_with_a_zone_or_a_fraction_are_utc(tmp_path: Path) -> None:
    lines = MARINECADASTRE.read_text(encoding="utf-8").splitlines()[:7]
    rows = [line.split(",") for line in lines[1:]]
    written = [
        "2023-01-11T00:00:00Z",
        "2023-01-11T01:00:00+01:00",
        "2023-01-10T19:30:00-0430",
        "2023-01-11 00:00:00.250",
        "2023-01-11T00:00:00.123456+00",
        "2023-02-30T00:00:00",  # no such day: Arrow alone would read 2 March
    ]
    for row, when in zip(rows, written, strict=True):
        row[1] = when
    path = tmp_path / "zones.csv"
    path.write_text("\n".join([lines[0], *(",".join(r) for r in rows)]) + "\n")
    data = load_ais([path])
    midnight = pd.Timestamp("2023-01-11T00:00:00", tz="UTC")
    got = dict(zip(data.positions["mmsi"], data.positions["timestamp"], strict=True))
    expected_ms = [0, 0, 0, 250, 123]
    assert [got[int(r[0])] for r in rows[:5]] == [
        midnight + pd.Timedelta(milliseconds=ms) for ms in expected_ms
    ]
    assert int(rows[5][0]) not in got
    (example,) = data.ledger.examples["unparseable"]
    assert "'2023-02-30T00:00:00'" in example


def test_dma_day_past_the_month_end_is_unparseable(tmp_path: Path) -> None:
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    path = tmp_path / "feb30.csv"
    path.write_text("\n".join([lines[0], lines[1].replace("09/09/2024", "30/02/2024", 1)]) + "\n")
    with pytest.raises(InputFileError, match="'30/02/2024 00:00:33'"):
        load_ais([path])


def test_dma_times_with_any_space_before_the_clock_on_the_first(tmp_path: Path) -> None:
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    rows = [line.replace("09/09/2024 ", "01/09/2024  ", 1) for line in lines[1:]]
    path = tmp_path / "first.csv"
    path.write_text("\n".join([lines[0], *rows]) + "\n")
    assert load_ais([path]).ledger.rejects == load_ais([DMA26]).ledger.rejects


def test_an_iso_zone_no_place_keeps_is_unparseable(tmp_path: Path) -> None:
    lines = MARINECADASTRE.read_text(encoding="utf-8").splitlines()[:3]
    rows = [line.split(",") for line in lines[1:]]
    rows[0][1], rows[1][1] = "2023-01-11T00:00:00+99:99", "2023-01-11T05:30:00+05:30"
    path = tmp_path / "zones.csv"
    path.write_text("\n".join([lines[0], *(",".join(r) for r in rows)]) + "\n")
    data = load_ais([path])
    assert list(data.positions["timestamp"]) == [pd.Timestamp("2023-01-11", tz="UTC")]
    assert "'2023-01-11T00:00:00+99:99'" in data.ledger.examples["unparseable"][0]


def test_exactearth_day_past_the_month_end_is_unparseable(tmp_path: Path) -> None:
    lines = (AIS_FIXTURES / "exactearth_sample.csv").read_text(encoding="utf-8").splitlines()
    path = tmp_path / "feb30.csv"
    moved = [line.replace("20230111_", "20230230_", 1) for line in lines[1:3]]
    path.write_text("\n".join([lines[0], *moved, *lines[3:]]) + "\n")
    data = load_ais([path])
    # The position is unparseable; the static report beside it needs no time (load.py step 4).
    assert data.ledger.rejects["unparseable"] == 1
    assert "'20230230_000000'" in data.ledger.examples["unparseable"][0]
    assert not (data.positions["timestamp"].dt.month == 3).any()


def test_ship_type_categories_are_one_spelling_whatever_the_case(tmp_path: Path) -> None:
    from colregs9_cli.ais.clean import clean_ship_type

    written = pa.array(["Cargo", "CARGO", " cargo ", "towing LONG/wide", "Hovercraft", None, ""])
    assert clean_ship_type(written).to_pylist() == [
        "Cargo",
        "Cargo",
        "Cargo",
        "Towing long/wide",
        "Hovercraft",  # not a category: as written
        None,
        None,
    ]
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    shouted = [lines[0], *(line.replace(",Cargo,", ",CARGO,") for line in lines[1:])]
    path = tmp_path / "shouted.csv"
    path.write_text("\n".join(shouted) + "\n")
    assert set(load_ais([path]).positions["ship_type"].dropna()) == set(
        load_ais([DMA26]).positions["ship_type"].dropna()
    )


def test_an_error_quoting_a_row_with_line_breaks_is_one_line(tmp_path: Path) -> None:
    lines = MARINECADASTRE.read_text(encoding="utf-8").splitlines()
    path = tmp_path / "open_quote.csv"
    path.write_text("\n".join([lines[0], '"' + lines[1], lines[1]]) + "\n")
    with pytest.raises(InputFileError) as caught:
        load_ais([path])
    message = str(caught.value)
    assert "\n" not in message and "a quote left open" in message and "\\n" in message


# -- the registry of layouts (ais/layouts.py) ----------------------------------------------------


@pytest.mark.parametrize("name", list(LAYOUTS))
def test_each_layouts_example_is_detected_as_that_layout(tmp_path: Path, name: str) -> None:
    """The registry's example of a layout's first line is told as that layout: the sniffs,
    tried in their order, single out each one."""
    layout = LAYOUTS[name]
    path = tmp_path / "example"
    path.write_bytes(layout.example.encode() + b"\n")
    source = inspect_source(path)
    assert detect_layout(source, read_head(source)) is layout


def test_every_layout_has_a_reader_and_a_description() -> None:
    assert set(READERS) == set(ReadAs)
    for name, layout in LAYOUTS.items():
        assert layout.name == name and layout.description and layout.example
        assert layout.read_as.is_csv == bool(layout.header), name
        assert (layout.read_as is ReadAs.DMA_CSV) == (layout.csv_columns is not None), name
        assert (layout.read_as is ReadAs.MAPPED_CSV) == (name in BUILTIN_MAPS), name


def test_dma_columns_are_those_of_the_dma_files() -> None:
    """The reader's DMA names come from the header colregs9 writes, which is DMA's own."""
    assert DMA26.read_text(encoding="utf-8").splitlines()[0] == ",".join(DMA_COLUMNS)
    assert DMA22.read_text(encoding="utf-8").splitlines()[0] == ",".join(DMA_COLUMNS[:22])
    assert DMA26_COLUMNS[:22] == DMA22_COLUMNS and DMA26_COLUMNS[22:] == ("a", "b", "c", "d")


def test_find_layout_names_each_layout_or_refuses(tmp_path: Path) -> None:
    assert all(find_layout(name) is layout for name, layout in LAYOUTS.items())
    mapped = find_layout(map_layout(MAPS / "aishub.toml"))
    assert mapped.read_as is ReadAs.MAPPED_CSV and mapped.map_file == MAPS / "aishub.toml"
    with pytest.raises(ParameterError, match="use one of " + ", ".join(LAYOUTS)):
        find_layout("aisdk")


def test_the_dma_writer_writes_exactly_its_columns(tmp_path: Path) -> None:
    writer = LAYOUTS["dma26"].csv_writer()
    row = {column: "x" for column in reversed(DMA_COLUMNS)}
    writer.write(tmp_path / "one.csv", pd.DataFrame([row]))
    assert (tmp_path / "one.csv").read_text().splitlines()[0] == ",".join(DMA_COLUMNS)
    with pytest.raises(ValueError, match="missing"):
        writer.write(tmp_path / "two.csv", pd.DataFrame([row]).drop(columns="A"))
    with pytest.raises(ValueError, match="colregs9 does not write"):
        LAYOUTS["nmea"].csv_writer()
