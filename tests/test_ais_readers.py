"""Every reader on the real fixtures, with counts checked independently (see each comment)."""

from __future__ import annotations

import gzip
import hashlib
import math
import shutil
import zipfile
from pathlib import Path

import pandas as pd
import pytest

from colregs9_cli.ais import csv_chunks
from colregs9_cli.ais.clean import nav_status_code
from colregs9_cli.ais.load import load_ais
from colregs9_cli.errors import InputFileError, ParameterError
from colregs9_cli.query import load_query

from fixture_files import DMA22, DMA26, MARINECADASTRE, NMEA, ROOT


def row_of(data, mmsi: int) -> pd.Series:
    rows = data.positions[data.positions["mmsi"] == mmsi]
    assert len(rows) == 1
    return rows.iloc[0]


def test_dma26_counts_and_rejects() -> None:
    # Cross-check: `sort | uniq -d` finds 1 duplicated line (HUMBRIA SEAWAYS); `cut -d, -f2`
    # shows one AtoN; `awk -F, '$4>90'` finds 3 rows with lat 91, all carrying dimensions
    # (static reports, used). 20 rows = 15 positions + 3 static + 1 AtoN + 1 duplicate.
    data = load_ais([DMA26])
    ledger = data.ledger
    assert ledger.rows_read == 20
    assert dict(ledger.rejects) == {"not_a_vessel": 1, "duplicate": 1}
    assert ledger.rows_used == 18
    assert data.rows_in_query == len(data.positions) == 15
    assert ledger.balanced
    assert data.inputs[0].layout == "dma26"
    assert data.inputs[0].sha256 == hashlib.sha256(DMA26.read_bytes()).hexdigest()
    assert "mobile type 'AtoN'" in ledger.examples["not_a_vessel"][0]
    assert ":13:" in ledger.examples["not_a_vessel"][0]  # the AtoN is on line 13
    assert list(data.positions.sort_values(["mmsi", "timestamp"])["mmsi"]) == list(
        data.positions["mmsi"]
    )


def test_dma26_values_sentinels_and_a_plus_b() -> None:
    data = load_ais([DMA26])
    tanker = row_of(data, 257739000)  # A,B,C,D = 223,65,25,24; Length 288, Width 49
    assert tanker["length_m"] == 288.0 and tanker["breadth_m"] == 49.0
    assert tanker["draught_m"] == 11.4
    assert tanker["timestamp"] == pd.Timestamp("2024-09-09 00:00:33", tz="UTC")
    assert tanker["imo"] == 9271248 and tanker["nav_status"] == 0
    assert tanker["ship_type"] == "Tanker" and tanker["name"] == "ARCTIC PRINCESS"
    unknown = row_of(data, 244130689)  # IMO/Callsign/Destination "Unknown", Undefined type
    assert pd.isna(unknown["imo"]) and pd.isna(unknown["callsign"])
    assert pd.isna(unknown["ship_type"]) and math.isnan(unknown["length_m"])
    assert row_of(data, 371420000)["rot_deg_per_min"] == 0.0  # ROT "-0"
    sar = row_of(data, 219019010)  # heading empty, draught empty
    assert math.isnan(sar["heading_deg"]) and math.isnan(sar["draught_m"])
    assert row_of(data, 248886000)["nav_status"] == 15  # "Unknown value"
    assert row_of(data, 219004128)["nav_status"] == 7  # "Engaged in fishing"


def test_dma26_static_reports_feed_dimension_reports(tmp_path: Path) -> None:
    # A position of 219000179 plus its real static report (lat 91, A+B 25, C+D 6, draught 2.5).
    lines = DMA26.read_text().splitlines()
    static = next(line for line in lines if ",219000179," in line)
    position = static.replace(",91,0,", ",57.05,9.95,")
    path = tmp_path / "one.csv"
    path.write_text("\n".join([lines[0], static, position]) + "\n")
    data = load_ais([path])
    assert data.ledger.rows_used == 2 and data.rows_in_query == 1
    reports = data.dimension_reports
    assert reports.to_dict("records") == [
        {"mmsi": 219000179, "length_m": 25.0, "breadth_m": 6.0, "draught_m": 2.5, "n_reports": 2}
    ]


def test_dma22_counts() -> None:
    # Cross-check with awk: `cut -d, -f2 | sort | uniq -c` gives 8 Base Station + 4 AtoN;
    # `awk -F, '($2=="Class A"||$2=="Class B") && !($3>=201000000 && $3<=775999999)'` finds
    # one vessel row (MMSI 999999000). `awk -F, '$4>90'` finds 10 vessel rows with lat 91 /
    # lon 181: that one, 220226000 (no name, call sign, ship type or dimension: no position)
    # and 8 static reports (used). No duplicated lines. 138 - 12 - 1 - 1 - 8 = 116 positions.
    data = load_ais([DMA22])
    ledger = data.ledger
    assert ledger.rows_read == 138
    assert dict(ledger.rejects) == {
        "not_a_vessel": 12,
        "invalid_mmsi": 1,
        "position_not_available": 1,
    }
    assert ledger.rows_used == 124 and data.rows_in_query == 116
    assert ledger.balanced and data.inputs[0].layout == "dma22"
    assert data.positions["lat_deg"].max() <= 90 and data.positions["lon_deg"].max() <= 180
    restricted = data.positions[data.positions["nav_status"] == 3]
    assert len(restricted) == 2  # "Restricted maneuverability", two rows (uniq -c)
    assert (data.positions["nav_status"] == 4).sum() == 1  # "Constrained by her draught"


def test_marinecadastre_counts_and_mapping() -> None:
    # pandas: 1,000 rows; 2 MMSIs outside 201-775 MIDs (3669882, 36926403); no duplicates,
    # no missing positions; Heading == 511 in 426 rows, SOG >= 102.3 in 4, COG == 360 in 90.
    data = load_ais([MARINECADASTRE])
    ledger = data.ledger
    assert (ledger.rows_read, ledger.rows_used, dict(ledger.rejects)) == (
        1000,
        998,
        {"invalid_mmsi": 2},
    )
    raw = pd.read_csv(MARINECADASTRE)
    raw = raw[~raw["MMSI"].isin([3669882, 36926403])]
    positions = data.positions
    assert positions["heading_deg"].isna().sum() == (raw["Heading"] == 511).sum()
    assert positions["sog_kn"].isna().sum() == (raw["SOG"] >= 102.3).sum()
    assert positions["cog_deg"].isna().sum() == (raw["COG"] == 360).sum()
    assert positions["heading_deg"].max() < 360
    msc = row_of(data, 636021061)  # VesselType 70, Status 8, IMO9307839, class A
    assert (msc["ship_type"], msc["nav_status"], msc["imo"], msc["mobile_type"]) == (
        "Cargo",
        8,
        9307839,
        "Class A",
    )
    assert (msc["length_m"], msc["breadth_m"], msc["draught_m"]) == (208.0, 30.0, 8.0)
    counts = positions["mobile_type"].value_counts().to_dict()
    assert counts == {"Class A": 952, "Class B": 46}  # TransceiverClass A 954 minus 2 invalid
    type31 = positions[positions["mmsi"] == 367752440].iloc[0]
    assert type31["ship_type"] == "Towing"


def test_nmea_through_limfjorden_query() -> None:
    # Independent count: read_nmea's raw positions in the box are 2,160 rows from 127 MMSIs
    # (fixtures/SOURCES.md); one of them, MMSI 11388, is invalid, leaving 2,159 from 126.
    # All 130 static messages are used (none has an invalid MMSI).
    data = load_ais([NMEA], query=load_query(ROOT / "queries" / "limfjorden.toml"))
    assert data.rows_in_query == 2159
    assert data.positions["mmsi"].nunique() == 126
    assert data.ledger.rows_read == 26077
    assert data.ledger.rejects["not_a_vessel"] == 1259
    assert data.ledger.rows_used == 2159 + 130
    assert data.ledger.balanced
    assert data.inputs[0].layout == "nmea"
    assert set(data.dimension_reports["mmsi"]) <= set(data.positions["mmsi"])


@pytest.mark.parametrize("chunk_bytes", [333, csv_chunks.CHUNK_BYTES])
@pytest.mark.parametrize("kind", ["gz", "zip"])
def test_compressed_variants_read_the_same(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str, chunk_bytes: int
) -> None:
    """Also in chunks of a few lines: decompressing readers return short reads."""
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
    if kind == "gz":
        path = tmp_path / "aisdk.csv.gz"
        path.write_bytes(gzip.compress(DMA22.read_bytes()))
    else:
        path = tmp_path / "aisdk.zip"
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
            archive.write(DMA22, "aisdk-2018-06-01.csv")
    plain, packed = load_ais([DMA22]), load_ais([path])
    pd.testing.assert_frame_equal(plain.positions, packed.positions)
    assert (
        plain.ledger.to_dict()["rejects_by_reason"] == packed.ledger.to_dict()["rejects_by_reason"]
    )
    assert packed.inputs[0].sha256 == hashlib.sha256(path.read_bytes()).hexdigest()


def test_format_override_and_headerless(tmp_path: Path) -> None:
    body = DMA26.read_text().splitlines()[1:]
    path = tmp_path / "noheader.txt"
    path.write_text("\n".join(body) + "\n")
    with pytest.raises(InputFileError, match="no header line; the first line is data"):
        load_ais([path])
    forced = load_ais([path], fmt="dma26")
    assert forced.rows_in_query == 15
    with pytest.raises(InputFileError, match="needs the column 'basedatetime'"):
        load_ais([DMA26], fmt="marinecadastre")
    with pytest.raises(ParameterError, match="--format 'csv'"):
        load_ais([DMA26], fmt="csv")


def test_malformed_rows_go_to_the_ledger(tmp_path: Path) -> None:
    lines = DMA26.read_text().splitlines()
    bad_count = lines[1] + ",extra"
    bad_lat = lines[2].replace("57.236367", "north")
    bad_time = lines[3].replace("09/09/2024 00:00:33", "32/13/2024 99:00:00")
    path = tmp_path / "bad.csv"
    path.write_text("\n".join([lines[0], bad_count, bad_lat, bad_time, *lines[4:]]) + "\n")
    data = load_ais([path])
    assert data.ledger.rejects["unparseable"] == 3
    assert data.ledger.rows_read == 20 and data.ledger.balanced
    examples = " | ".join(data.ledger.examples["unparseable"])
    assert f"{path}:2: expected 26 fields, found 27" in examples
    assert f"{path}:3: latitude is not a number: 'north'" in examples
    bad_time = "timestamp does not parse or lies outside 1980–2099: '32/13/2024 99:00:00'"
    assert f"{path}:4: {bad_time}" in examples


@pytest.mark.parametrize(
    ("text", "code"),
    [
        ("Under way using engine", 0),
        ("Restricted manoeuverability", 3),
        ("Restricted maneuverability", 3),
        ("Restricted manoeuvrability", 3),
        ("Constrained by her draught", 4),
        ("Reserved for future amendment [HSC]", 9),
        ("Power-driven vessel pushing ahead or towing alongside", 12),
        ("AIS-SART", 14),
        ("Unknown value", 15),
        ("something else", None),
        ("", None),
    ],
)
def test_nav_status_text(text: str, code: int | None) -> None:
    assert nav_status_code(text) == code


# -- bad input files ----------------------------------------------------------------------------


def test_missing_and_empty_files(tmp_path: Path) -> None:
    with pytest.raises(InputFileError, match="no such file"):
        load_ais([tmp_path / "nope.csv"])
    empty = tmp_path / "empty.csv"
    empty.write_bytes(b"")
    with pytest.raises(InputFileError, match=r"empty\.csv: the file is empty"):
        load_ais([empty])
    header_only = tmp_path / "header.csv"
    header_only.write_text(DMA26.read_text().splitlines()[0] + "\n\n")
    with pytest.raises(InputFileError, match=r"header\.csv: no data rows after the header"):
        load_ais([header_only])


def test_unknown_layout(tmp_path: Path) -> None:
    path = tmp_path / "other.csv"
    path.write_text("ship,when,where\n" + "x" * 200 + "\n")
    with pytest.raises(InputFileError) as caught:
        load_ais([path])
    message = str(caught.value)
    assert "other.csv: unknown AIS layout" in message and "'ship,when,where'" in message
    layouts = "dma26, dma22, marinecadastre, marinecadastre2015, marinecadastre2025, exactearth"
    assert f"{layouts}, nmea, parquet" in message and "--format" in message
    assert "--columns MAP.toml" in message


def test_truncated_gzip_csv_and_nmea(tmp_path: Path) -> None:
    csv_gz = tmp_path / "cut.csv.gz"
    packed = gzip.compress((DMA26.read_text() * 200).encode())
    csv_gz.write_bytes(packed[: len(packed) // 2])
    with pytest.raises(InputFileError, match=r"cut\.csv\.gz: truncated or corrupt gzip"):
        load_ais([csv_gz])
    nmea_gz = tmp_path / "cut.txt.gz"
    raw = NMEA.read_bytes()
    nmea_gz.write_bytes(raw[: len(raw) // 2])
    with pytest.raises(InputFileError, match=r"cut\.txt\.gz: truncated or corrupt gzip"):
        load_ais([nmea_gz])


def test_truncated_and_wrong_zips(tmp_path: Path) -> None:
    good = tmp_path / "good.zip"
    with zipfile.ZipFile(good, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.write(DMA22, "a.csv")
    cut = tmp_path / "cut.zip"
    cut.write_bytes(good.read_bytes()[:-40])
    with pytest.raises(InputFileError, match=r"cut\.zip: truncated or corrupt zip"):
        load_ais([cut])
    two = tmp_path / "two.zip"
    with zipfile.ZipFile(two, "w") as archive:
        archive.write(DMA22, "a.csv")
        archive.write(DMA26, "b.csv")
    with pytest.raises(InputFileError, match=r"two\.zip: the zip holds 2 CSV files"):
        load_ais([two])
    none = tmp_path / "none.zip"
    with zipfile.ZipFile(none, "w") as archive:
        archive.writestr("readme.md", "x")
        archive.writestr("notes.md", "y")
    with pytest.raises(InputFileError, match=r"none\.zip: the zip holds no CSV file"):
        load_ais([none])


def test_non_utf8_byte(tmp_path: Path) -> None:
    raw = DMA26.read_bytes().replace(b"ARCTIC PRINCESS", b"ARCTIC PRIN\xe6ESS")
    path = tmp_path / "latin1.csv"
    path.write_bytes(raw)
    offset = raw.index(b"\xe6")
    with pytest.raises(InputFileError) as caught:
        load_ais([path])
    assert f"latin1.csv:2: byte 0xe6 at offset {offset} is not UTF-8" in str(caught.value)


def test_parquet_round_trip_and_missing_column(tmp_path: Path) -> None:
    data = load_ais([DMA26])
    path = tmp_path / "ais.parquet"
    data.positions.to_parquet(path)
    again = load_ais([path])
    assert again.inputs[0].layout == "parquet"
    pd.testing.assert_frame_equal(again.positions, data.positions)
    assert again.ledger.rows_read == 15 and again.ledger.balanced
    broken = tmp_path / "broken.parquet"
    data.positions.drop(columns=["heading_deg"]).to_parquet(broken)
    with pytest.raises(InputFileError, match=r"broken\.parquet: .*column 'heading_deg'"):
        load_ais([broken])


def test_multiple_files_dedupe_across_files(tmp_path: Path) -> None:
    copy = tmp_path / "copy.csv"
    shutil.copy(DMA26, copy)
    data = load_ais([DMA26, copy])
    assert data.ledger.rows_read == 40
    assert data.rows_in_query == 15
    assert data.ledger.rejects["duplicate"] == 2 + 15
    assert [f.rows_read for f in data.inputs] == [20, 20]


@pytest.mark.parametrize("spelling", ["NULL", "N/A", "NaN", "na", " null "])
def test_null_spellings_in_number_columns_are_not_available(tmp_path: Path, spelling: str) -> None:
    """pyarrow's null spellings in a number column mean "not available", not bad text."""
    lines = DMA26.read_text().splitlines()
    lines[1] = lines[1].replace(",GPS,11.4,", f",GPS,{spelling},")  # the tanker's draught
    lines[4] = lines[4].replace("54.702822", spelling)  # 244130689: nothing static either
    path = tmp_path / "nulls.csv"
    path.write_text("\n".join(lines) + "\n")
    data = load_ais([path])
    assert dict(data.ledger.rejects) == {
        "not_a_vessel": 1,
        "duplicate": 1,
        "position_not_available": 1,
    }
    assert math.isnan(row_of(data, 257739000)["draught_m"])
    assert 244130689 not in set(data.positions["mmsi"])


def test_an_mmsi_written_as_a_decimal_reads_the_same(tmp_path: Path) -> None:
    """MMSIs are read as integers; a chunk with "257739000.0" is read as text instead."""
    path = tmp_path / "decimal.csv"
    path.write_text(DMA26.read_text().replace(",257739000,", ",257739000.0,"))
    pd.testing.assert_frame_equal(load_ais([path]).positions, load_ais([DMA26]).positions)
