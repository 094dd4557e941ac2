"""run.json's sha256 of every input is the sha256 of the file as stored, for every kind of
input, every time (a hash taken on a worker thread from a buffer the reader had already
refilled once made it wrong and different on every run for plain files)."""

from __future__ import annotations

import gzip
import hashlib
import zipfile
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from colregs9_cli.ais.load import load_ais
from colregs9_cli.ais.sources import inspect_source, open_data
from colregs9_cli.charts.provenance import charts_manifest

from fixture_files import DMA26, MARINECADASTRE, MODELLED_CHART, NMEA, SANDIEGO_ENC

REPEATS = 3


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _big_plain_nmea(tmp_path: Path) -> Path:
    """About 12 MB of NMEA, a dozen times the 1 MB read unit: the real DMA log (3 MB), then
    time sentences, which the reader reads and skips (decoding the log four times over
    took three times as long)."""
    text = gzip.decompress(NMEA.read_bytes())
    filler = b"$GPZDA,120500.00,12,11,2013,00,00*6E\r\n"
    path = tmp_path / "big.nmea"
    path.write_bytes(text + filler * (9_000_000 // len(filler)))
    assert path.stat().st_size > 8 * (1 << 20)
    return path


def _big_plain_csv(tmp_path: Path) -> Path:
    header, rows = DMA26.read_bytes().split(b"\n", 1)
    path = tmp_path / "big.csv"
    path.write_bytes(header + b"\n" + rows * 8000)
    assert path.stat().st_size > 20 * (1 << 20)
    return path


def _gzip(source: Path, tmp_path: Path) -> Path:
    path = tmp_path / f"{source.name}.gz"
    path.write_bytes(gzip.compress(source.read_bytes()))
    return path


def _zip(source: Path, tmp_path: Path) -> Path:
    path = tmp_path / f"{source.name}.zip"
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        archive.write(source, source.name)
    return path


def _parquet(tmp_path: Path) -> Path:
    data = load_ais([DMA26])
    path = tmp_path / "positions.parquet"
    import pyarrow as pa

    from colregs9_cli.ais.schema import CANONICAL_SCHEMA

    pq.write_table(pa.Table.from_pandas(data.positions, schema=CANONICAL_SCHEMA), path)
    return path


KINDS = {
    "dma csv": lambda tmp: DMA26,
    "dma csv, 20 MB": _big_plain_csv,
    "dma csv.gz": lambda tmp: _gzip(DMA26, tmp),
    "dma csv.zip": lambda tmp: _zip(DMA26, tmp),
    "marinecadastre csv": lambda tmp: MARINECADASTRE,
    "nmea.gz": lambda tmp: NMEA,
    "plain nmea, 12 MB": _big_plain_nmea,
    "parquet": _parquet,
}


@pytest.mark.parametrize("kind", list(KINDS))
def test_input_sha256_is_the_files_every_time(tmp_path: Path, kind: str) -> None:
    path = KINDS[kind](tmp_path)
    expected = _sha256(path)
    for _ in range(REPEATS):
        (recorded,) = load_ais([path]).inputs
        assert recorded.sha256 == expected


@pytest.mark.parametrize("compressed", [False, True])
def test_the_hash_does_not_see_a_buffer_the_reader_refills(
    tmp_path: Path, compressed: bool
) -> None:
    """A reader that scribbles over its buffer as soon as each read returns (as line readers
    and the CSV chunker may) leaves the file's sha256 as it is."""
    path = _big_plain_nmea(tmp_path)
    if compressed:
        path = _gzip(path, tmp_path)
    expected = _sha256(path)
    for _ in range(REPEATS):
        buffer = bytearray(3 << 20)
        with open_data(inspect_source(path)) as opened:
            while opened.stream.readinto(buffer):  # type: ignore[attr-defined]
                buffer[:] = bytes(len(buffer))
            assert opened.finish() == expected


def test_charts_are_recorded_with_every_file_and_its_hash() -> None:
    (cell,) = charts_manifest([SANDIEGO_ENC])
    assert cell["path"] == str(SANDIEGO_ENC)
    names = [Path(f["path"]).name for f in cell["files"]]
    assert names == ["US5CA72M.000", "US5CA72M.001", "US5CA72M.002"]
    assert all(f["applied"] for f in cell["files"]) and cell["missing_updates"] == []
    for item in cell["files"]:
        assert item["sha256"] == _sha256(Path(item["path"]))
    (modelled,) = charts_manifest([MODELLED_CHART])
    assert [f["sha256"] for f in modelled["files"]] == [_sha256(MODELLED_CHART)]
