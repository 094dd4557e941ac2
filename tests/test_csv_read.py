"""Reading the first input ahead (``csv_read.start_reading``): the same result as reading it
in turn, its errors raised on the caller's thread, and nothing left running when stopped."""

from __future__ import annotations

import gzip
import hashlib
import threading
from pathlib import Path

import pandas as pd
import pytest

from colregs9_cli.ais import csv_chunks, csv_read
from colregs9_cli.ais.csv_read import start_reading
from colregs9_cli.ais.load import AisData, load_ais
from colregs9_cli.errors import InputFileError
from colregs9_cli.query import Query, Region

from fixture_files import AIS_FIXTURES, DMA22, DMA26, MARINECADASTRE, NMEA


def _read_ahead(paths: list[Path], query: Query | None = None) -> AisData:
    with start_reading(paths, None) as started:
        assert started is not None
        return load_ais(paths, query=query, started=started)


def _ahead_threads() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name == "colregs9-csv-ahead"]


@pytest.mark.parametrize("fixture", [DMA26, DMA22, MARINECADASTRE])
@pytest.mark.parametrize(("chunk_bytes", "ahead"), [(csv_chunks.CHUNK_BYTES, 8), (300, 1)])
def test_reading_ahead_gives_the_same_result(
    monkeypatch: pytest.MonkeyPatch, fixture: Path, chunk_bytes: int, ahead: int
) -> None:
    """Also in chunks of a few lines through a queue one chunk deep, which fills at once."""
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", chunk_bytes)
    monkeypatch.setattr(csv_read, "AHEAD_CHUNKS", ahead)
    query = Query(name="box", region=Region(54.0, 58.0, 8.0, 13.0))
    plain = load_ais([fixture, DMA22], query=None if fixture == MARINECADASTRE else query)
    early = _read_ahead([fixture, DMA22], query=None if fixture == MARINECADASTRE else query)
    pd.testing.assert_frame_equal(early.positions, plain.positions)
    pd.testing.assert_frame_equal(early.dimension_reports, plain.dimension_reports)
    assert early.ledger.to_dict() == plain.ledger.to_dict()
    assert early.inputs == plain.inputs
    assert early.inputs[0].sha256 == hashlib.sha256(fixture.read_bytes()).hexdigest()
    assert not _ahead_threads()


def test_bytes_read_ahead_reach_the_progress_bar_once_attached() -> None:
    reported: list[float] = []

    class Bar:
        def advance(self, amount: float = 1.0) -> None:
            reported.append(amount)

    with start_reading([DMA26], None) as started:
        assert started is not None
        chunks = list(started.chunks())
        started.attach_progress(Bar())
        started.finish()
    assert sum(chunk.rows.num_rows for chunk in chunks) == 20
    assert sum(reported) == DMA26.stat().st_size


def test_errors_of_the_read_ahead_are_raised_by_load_ais(tmp_path: Path) -> None:
    header, *rows = DMA22.read_bytes().splitlines(keepends=True)
    truncated = tmp_path / "aisdk.csv.gz"  # cut well past the head that detection reads
    truncated.write_bytes(gzip.compress(header + b"".join(rows * 50))[:-200])
    with pytest.raises(InputFileError, match="truncated or corrupt gzip"):
        _read_ahead([truncated])
    latin1 = tmp_path / "latin1.csv"
    latin1.write_bytes(DMA26.read_bytes().replace(b"ARCTIC PRINCESS", b"ARCTIC PRINC\xc9SS"))
    with pytest.raises(InputFileError, match=r"latin1.csv:2: byte 0xc9 .* is not UTF-8"):
        _read_ahead([latin1])
    assert not _ahead_threads()


def test_stopping_before_the_chunks_are_taken_ends_the_thread(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """As when an option turns out bad after the read has started: the queue is full and
    the thread waits on it; leaving the block stops it and closes the file."""
    monkeypatch.setattr(csv_chunks, "CHUNK_BYTES", 200)
    monkeypatch.setattr(csv_read, "AHEAD_CHUNKS", 1)
    with pytest.raises(RuntimeError, match="bad option"), start_reading([DMA22], None) as started:
        assert started is not None and _ahead_threads()
        raise RuntimeError("bad option")
    assert not _ahead_threads()


@pytest.mark.parametrize("path", [NMEA, AIS_FIXTURES / "no_such_file.csv"])
def test_only_a_readable_csv_is_read_ahead(path: Path) -> None:
    """Anything else is left to load_ais, which reads it or reports what is wrong."""
    with start_reading([path], None) as started:
        assert started is None
