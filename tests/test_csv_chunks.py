"""The chunked CSV reader: chunk edges, line numbers, the rows cut out again, and fallbacks.

Each case reads a real fixture in altered form and compares with the plain read of the
fixture, whose counts tests/test_ais_readers.py checks independently.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from colregs9_cli.ais import csv_chunks, row_pipeline
from colregs9_cli.ais.layouts import LAYOUTS
from colregs9_cli.ais.load import AisData, load_ais
from colregs9_cli.errors import InputFileError
from colregs9_cli.query import Query, Region, load_query

from fixture_files import DMA22, DMA26, MARINECADASTRE, NMEA


def _counts(data: AisData) -> dict[str, object]:
    """The ledger without its examples, which depend on the blocks (one per reason and block)."""
    return {k: v for k, v in data.ledger.to_dict().items() if k != "reject_examples"}


def _same(a: AisData, b: AisData) -> None:
    """Same positions, dimension reports, counts, and first example (file name aside)."""
    pd.testing.assert_frame_equal(a.positions, b.positions)
    pd.testing.assert_frame_equal(a.dimension_reports, b.dimension_reports)
    assert _counts(a) == _counts(b)
    name_a, name_b = a.inputs[0].path.name, b.inputs[0].path.name
    for reason, examples in b.ledger.examples.items():
        assert (
            a.ledger.examples[reason][0].split(name_a)[-1].removeprefix("!aisdk.csv")
            == (examples[0].split(name_b)[-1])
        )


def _box_query(tmp_path: Path) -> Path:
    """Part of the Kattegat: 6 of the fixture's position rows (one a duplicate)."""
    path = tmp_path / "kattegat.toml"
    path.write_text(
        'name = "kattegat"\n[region]\nlat_min = 57.0\nlat_max = 58.0\n'
        "lon_min = 9.0\nlon_max = 12.5\n"
    )
    return path


@pytest.mark.parametrize("chunk_bytes", [1, 97, 400, 4096])
@pytest.mark.parametrize("fixture", [DMA26, MARINECADASTRE])
def test_any_chunk_size_reads_the_same(
    monkeypatch: pytest.MonkeyPatch, fixture: Path, chunk_bytes: int
) -> None:
    """Chunks shorter than a line, a few lines, and the whole file give the same result."""
    whole = load_ais([fixture])
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
    _same(load_ais([fixture]), whole)


@pytest.mark.parametrize("workers", [1, 3])
def test_chunks_parsed_side_by_side_come_in_file_order(
    monkeypatch: pytest.MonkeyPatch, workers: int
) -> None:
    """One worker or several, small chunks give the rows, counts and line numbers of one
    whole chunk."""
    whole = load_ais([DMA26])
    monkeypatch.setattr(csv_chunks, "parse_workers", lambda: workers)
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", 300)
    chunks = _chunks_of(DMA26)
    assert len(chunks) > 10
    assert [chunk.line_of(0) for chunk in chunks] == sorted({c.line_of(0) for c in chunks})
    _same(load_ais([DMA26]), whole)


def test_every_chunk_owns_its_bytes_whether_kept_or_dropped(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", 300)
    rows = DMA26.read_bytes().split(b"\n", 1)[1]
    # Every chunk kept: each has a buffer of its own, and the bytes of the file.
    chunks = _chunks_of(DMA26)
    assert len({id(chunk._data.obj) for chunk in chunks}) == len(chunks) > 10
    assert b"".join(bytes(chunk._data) for chunk in chunks) == rows
    # Chunks dropped once used: the same bytes (no buffer is refilled while a chunk, a view
    # or a parsed table may still refer to it).
    read = [bytes(chunk._data) for chunk in _read_chunks(DMA26)]
    assert len(read) == len(chunks)
    assert b"".join(read) == rows


def test_parse_workers_follow_the_cores(monkeypatch: pytest.MonkeyPatch) -> None:
    """One per core, up to the blocks of a chunk (16 MB in 4 MB blocks: 4)."""
    for cores, workers in ((1, 1), (2, 2), (4, 4), (16, 4)):
        monkeypatch.setattr(csv_chunks.pa, "cpu_count", lambda cores=cores: cores)
        assert csv_chunks.parse_workers() == workers


def test_a_decimal_in_a_whole_number_column_is_read_as_it_is(tmp_path: Path) -> None:
    """DMA lengths and widths are read as integers; a decimal one makes its chunk text and
    keeps its value."""
    lines = DMA26.read_text().splitlines()
    header = lines[0].lower().lstrip("# ").split(",")
    width, length = header.index("width"), header.index("length")
    a, b = header.index("a"), header.index("b")
    row = next(i for i, line in enumerate(lines[1:], 1) if line.split(",")[length])
    fields = lines[row].split(",")
    fields[length], fields[a], fields[b] = "12.5", "", ""
    fields[width] = "4.25"
    lines[row] = ",".join(fields)
    path = tmp_path / "decimal.csv"
    path.write_text("\n".join(lines) + "\n")
    chunks = _chunks_of(path)
    assert [chunk.text for chunk in chunks] == [True]
    positions = load_ais([path]).positions
    mmsi = int(fields[header.index("mmsi")])
    vessel = positions[positions["mmsi"] == mmsi]
    assert 12.5 in vessel["length_m"].to_list()
    plain = load_ais([DMA26])
    assert len(positions) == len(plain.positions)


@settings(
    max_examples=25,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(chunk_bytes=st.integers(min_value=1, max_value=3000))
def test_chunk_size_never_changes_the_result(
    monkeypatch: pytest.MonkeyPatch, chunk_bytes: int
) -> None:
    whole = load_ais([DMA26])
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
    _same(load_ais([DMA26]), whole)


def test_rows_cut_out_of_a_chunk_are_the_right_rows(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With a query, only some rows of each chunk are parsed again in full: same values."""
    query = load_query(_box_query(tmp_path))
    whole = load_ais([DMA26])
    inside = whole.positions[
        whole.positions["lat_deg"].between(57.0, 58.0)
        & whole.positions["lon_deg"].between(9.0, 12.5)
    ].reset_index(drop=True)
    assert len(inside) == 5  # COLOR MAGIC, HUMBRIA SEAWAYS, KYST-FRB14, TRANS FJELL, FALKSKAR II
    for chunk_bytes in (500, csv_chunks.CHUNK_BYTES):
        monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
        pd.testing.assert_frame_equal(load_ais([DMA26], query=query).positions, inside)


def test_blank_lines_and_crlf_keep_file_line_numbers(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    lines = DMA26.read_text().splitlines()
    edited = [lines[0], "", lines[1] + ",extra", "", lines[2].replace("57.236367", "north")]
    edited += lines[3:]
    path = tmp_path / "blank.csv"
    path.write_bytes(("\r\n".join(edited) + "\r\n").encode())
    for chunk_bytes in (300, csv_chunks.CHUNK_BYTES):
        monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
        data = load_ais([path])
        examples = " | ".join(data.ledger.examples["unparseable"])
        assert f"{path}:3: expected 26 fields, found 27" in examples
        assert f"{path}:5: latitude is not a number: 'north'" in examples
        assert data.ledger.rows_read == 20 and data.ledger.balanced
        kept = load_ais([DMA26]).positions
        assert len(data.positions) == len(kept) - 2  # the two broken rows


def test_lone_carriage_returns_end_lines(tmp_path: Path) -> None:
    """Old Mac line ends: the same rows, and line numbers still count lines."""
    path = tmp_path / "mac.csv"
    path.write_bytes(DMA26.read_bytes().replace(b"\r\n", b"\n").replace(b"\n", b"\r"))
    data, plain = load_ais([path]), load_ais([DMA26])
    pd.testing.assert_frame_equal(data.positions, plain.positions)
    assert _counts(data) == _counts(plain)
    assert data.ledger.examples["not_a_vessel"] == [f"{path}:13: mobile type 'AtoN'"]


def test_rows_that_do_not_match_lines_parse_the_chunk_whole(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The guard for records that match no known layout: the whole chunk, all columns."""
    plain = load_ais([DMA26])
    monkeypatch.setattr(csv_chunks, "_find_records", lambda data, line_ends, count: None)
    for chunk_bytes in (600, csv_chunks.CHUNK_BYTES):
        monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
        data = load_ais([DMA26])
        pd.testing.assert_frame_equal(data.positions, plain.positions)
        pd.testing.assert_frame_equal(data.dimension_reports, plain.dimension_reports)
        assert _counts(data) == _counts(plain)


@pytest.mark.parametrize("chunk_bytes", [7, 50, 333, csv_chunks.CHUNK_BYTES])
def test_crlf_cut_between_cr_and_lf_keeps_line_numbers(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, chunk_bytes: int
) -> None:
    """A read may end on the CR of a CRLF; that CR must not end a line of its own."""
    path = tmp_path / "crlf.csv"
    path.write_bytes(DMA26.read_bytes().replace(b"\r\n", b"\n").replace(b"\n", b"\r\n"))
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
    data = load_ais([path])
    assert data.ledger.examples["not_a_vessel"] == [f"{path}:13: mobile type 'AtoN'"]
    pd.testing.assert_frame_equal(data.positions, load_ais([DMA26]).positions)


def test_mixed_line_ends_cut_after_a_final_cr(monkeypatch: pytest.MonkeyPatch) -> None:
    """Lone CRs, then CRLFs, with a read ending on a CR: rows and lines stay aligned."""
    import io

    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", 12)
    data = b"a,b\r1,x\r2,y\r\n3,z\r\n4\r\n"
    chunks = list(
        csv_chunks.read_chunks(
            io.BytesIO(data), ["a", "b"], True, ["a", "b"], ["a", "b"], numeric=["a"]
        )
    )
    lines = {
        chunk.rows.column("a")[row].as_py(): chunk.line_of(row)
        for chunk in chunks
        for row in range(chunk.rows.num_rows)
    }
    assert lines == {1.0: 2, 2.0: 3, 3.0: 4}
    assert [bad.line for chunk in chunks for bad in chunk.invalid_rows] == [5]


def test_a_quoted_line_end_keeps_rows_and_line_numbers(tmp_path: Path) -> None:
    """pyarrow accepts a line end inside quotes; the record spans two lines of the file."""
    lines = DMA26.read_text().splitlines()
    fields = lines[3].split(",")
    fields[19] = '"HAM\nBURG"'  # Destination, file line 4 becomes lines 4-5
    lines[3] = ",".join(fields)
    lines[14] = lines[14] + ",extra"  # file line 15, now physical line 16
    path = tmp_path / "quoted.csv"
    path.write_text("\n".join(lines) + "\n")
    data = load_ais([path])
    assert data.ledger.examples["not_a_vessel"] == [f"{path}:14: mobile type 'AtoN'"]
    assert f"{path}:16: expected 26 fields, found 27" in data.ledger.examples["unparseable"][0]
    plain = load_ais([DMA26])
    assert data.ledger.rows_read == plain.ledger.rows_read
    assert len(data.positions) == len(plain.positions) - 1  # the malformed row


def test_a_bad_byte_in_a_column_not_converted_is_still_an_error(tmp_path: Path) -> None:
    """Names are converted only for the rows kept; the chunk's bytes are checked whole."""
    query = load_query(_box_query(tmp_path))
    path = tmp_path / "latin1.csv"
    path.write_bytes(DMA26.read_bytes().replace(b"ARRHENIUS", b"ARRH\xe6NIUS"))  # outside
    with pytest.raises(InputFileError, match=r"latin1\.csv:8: byte 0xe6 at offset \d+"):
        load_ais([path], query=query)


def test_text_in_a_column_converted_only_for_kept_rows(tmp_path: Path) -> None:
    """SOG text in a kept row: that row is read again as text, its SOG becomes null."""
    lines = DMA26.read_text().splitlines()
    target = next(i for i, line in enumerate(lines) if ",Class A," in line and i > 0)
    fields = lines[target].split(",")
    fields[7] = "fast"
    lines[target] = ",".join(fields)
    path = tmp_path / "sog.csv"
    path.write_text("\n".join(lines) + "\n")
    data = load_ais([path])
    plain = load_ais([DMA26])
    assert _counts(data) == _counts(plain)
    mmsi = int(fields[2])
    changed = data.positions[data.positions["mmsi"] == mmsi]["sog_kn"]
    assert changed.isna().any()
    assert data.positions.drop(columns="sog_kn").equals(plain.positions.drop(columns="sog_kn"))


def _read_chunks(path: Path) -> Iterator[csv_chunks.CsvChunk]:
    """The chunks of a DMA 26-column file, read as ``load_ais`` reads them, one at a time."""
    names = path.read_text().splitlines()[0].lower().lstrip("# ").split(",")
    columns = LAYOUTS["dma26"].csv_columns
    assert columns is not None
    with path.open("rb") as stream:
        yield from csv_chunks.read_chunks(
            stream,
            names,
            True,
            row_columns=columns.row_columns,
            all_columns=columns.columns,
            numeric=columns.numeric,
            whole=columns.whole,
        )


def _chunks_of(path: Path) -> list[csv_chunks.CsvChunk]:
    return list(_read_chunks(path))


def test_a_bad_row_costs_its_chunk_not_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Text in a number column makes only its chunk parse again, as text; a malformed row
    is skipped with its line number, without a second parse (chunks parse on one thread)."""
    lines = DMA26.read_text().splitlines()
    lines[3] = lines[3].replace("57.459803", "north")  # file line 4
    lines[15] = lines[15] + ",extra"  # file line 16
    path = tmp_path / "bad.csv"
    path.write_text("\n".join(lines) + "\n")
    parses: list[bool] = []
    parse = csv_chunks._parse

    def recording_parse(data, names, types, threads, *args):  # type: ignore[no-untyped-def]
        parses.append(threads)
        return parse(data, names, types, threads, *args)

    monkeypatch.setattr(csv_chunks, "_parse", recording_parse)
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", 700)
    chunks = _chunks_of(path)
    first_lines = [chunk.line_of(0) for chunk in chunks]
    text = [chunk.text for chunk in chunks]
    assert sum(text) == 1 and text[first_lines.index(max(n for n in first_lines if n <= 4))]
    invalid = [bad.line for chunk in chunks for bad in chunk.invalid_rows]
    assert invalid == [16]
    assert parses == [False] * (len(chunks) + 1)  # the chunk with line 4 twice
    assert len(chunks) > 5


@pytest.mark.parametrize("blank", [b"\n", b"\r\n\n", b"\r"])
@pytest.mark.parametrize("chunk_bytes", [1, 600, csv_chunks.CHUNK_BYTES])
def test_blank_lines_before_the_header(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, blank: bytes, chunk_bytes: int
) -> None:
    """The header is the first non-empty line; the blank lines still count as file lines."""
    path = tmp_path / "blank_first.csv"
    path.write_bytes(blank + DMA26.read_bytes())
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
    data = load_ais([path])
    pd.testing.assert_frame_equal(data.positions, load_ais([DMA26]).positions)
    assert "unparseable" not in data.ledger.rejects
    lines_before = blank.replace(b"\r\n", b"\n").replace(b"\r", b"\n").count(b"\n")
    assert data.ledger.examples["not_a_vessel"] == [
        f"{path}:{13 + lines_before}: mobile type 'AtoN'"
    ]


# Boxes that hold some of each fixture's positions: (lat_min, lat_max, lon_min, lon_max).
_BOXES = {
    DMA26: (57.0, 58.0, 9.0, 12.5),
    DMA22: (55.5, 57.0, 10.0, 12.0),
    MARINECADASTRE: (29.0, 31.0, -95.0, -89.0),
    NMEA: (55.5, 57.0, 10.0, 12.0),
}


@pytest.mark.parametrize("boxed", [False, True])
@pytest.mark.parametrize("fixture", list(_BOXES))
def test_rows_set_aside_give_the_same_result_in_any_batch(
    monkeypatch: pytest.MonkeyPatch, fixture: Path, boxed: bool
) -> None:
    """The rows kept and the rows without a position are converted in batches; converting
    them after every chunk of a few lines changes nothing."""
    query = Query(name="box", region=Region(*_BOXES[fixture])) if boxed else None
    whole = load_ais([fixture], query=query)
    assert whole.rows_in_query > 0
    monkeypatch.setattr(row_pipeline, "_SET_ASIDE_BYTES", 1)
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", 400)
    _same(load_ais([fixture], query=query), whole)
