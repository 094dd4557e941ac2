"""Every compression users have is read as a stream, with the same rows as the plain file:
gzip, zip, bzip2, xz and zstd (told by the first bytes, not the name); a truncated file is
one clear error naming it."""

from __future__ import annotations

import bz2
import gzip
import hashlib
import lzma
from pathlib import Path

import pyarrow as pa
import pytest

from colregs9_cli.ais.load import load_ais
from colregs9_cli.errors import InputFileError

from fixture_files import DMA26, NMEA


def _zstd(data: bytes) -> bytes:
    sink = pa.BufferOutputStream()
    with pa.CompressedOutputStream(sink, "zstd") as stream:
        stream.write(data)
    return sink.getvalue().to_pybytes()


COMPRESS = {"bz2": bz2.compress, "xz": lzma.compress, "zst": _zstd, "gz": gzip.compress}
PLAIN = {"dma": DMA26.read_bytes(), "nmea": gzip.decompress(NMEA.read_bytes())}


@pytest.fixture(scope="module")
def plain_results(tmp_path_factory: pytest.TempPathFactory):
    folder = tmp_path_factory.mktemp("plain")
    results = {}
    for kind, data in PLAIN.items():
        path = folder / f"{kind}.data"
        path.write_bytes(data)
        results[kind] = load_ais([path])
    return results


@pytest.mark.parametrize("suffix", list(COMPRESS))
@pytest.mark.parametrize("kind", list(PLAIN))
def test_a_compressed_file_reads_as_the_plain_one(
    tmp_path: Path, plain_results, kind: str, suffix: str
) -> None:
    # a misleading name: the compression is told by the content
    path = tmp_path / f"{kind}.txt"
    path.write_bytes(COMPRESS[suffix](PLAIN[kind]))
    data = load_ais([path])
    plain = plain_results[kind]
    assert len(data.positions) == len(plain.positions)
    assert data.ledger.to_dict()["rows_read"] == plain.ledger.to_dict()["rows_read"]
    assert data.ledger.balanced
    assert data.inputs[0].sha256 == hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.mark.parametrize("suffix", ["bz2", "xz", "zst"])
def test_a_truncated_file_is_one_clear_error(tmp_path: Path, suffix: str) -> None:
    whole = COMPRESS[suffix](PLAIN["dma"] * 20)
    path = tmp_path / f"cut.csv.{suffix}"
    path.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(InputFileError, match=rf"{path.name}: truncated or corrupt"):
        load_ais([path])


def _zip_with(path: Path, flag_bits: int = 0, method: int | None = None) -> Path:
    """A zip of the DMA fixture, its entry marked encrypted or with another method."""
    import struct
    import zipfile

    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.write(DMA26, "aisdk.csv")
    data = bytearray(path.read_bytes())
    for signature, flags_at, method_at in ((b"PK\x03\x04", 6, 8), (b"PK\x01\x02", 8, 10)):
        at = data.index(signature)
        if flag_bits:
            flags = struct.unpack_from("<H", data, at + flags_at)[0] | flag_bits
            struct.pack_into("<H", data, at + flags_at, flags)
        if method is not None:
            struct.pack_into("<H", data, at + method_at, method)
    path.write_bytes(bytes(data))
    return path


@pytest.mark.parametrize(
    ("flag_bits", "method", "message"),
    [
        (0x1, None, "aisdk.csv is encrypted in the zip"),
        (0, 99, "compressed with zip method 99"),  # AES, as 7-Zip writes it
        (0, 9, "compressed with zip method 9"),  # deflate64
    ],
)
def test_a_zip_that_cannot_be_read_is_one_clear_error(
    tmp_path: Path, flag_bits: int, method: int | None, message: str
) -> None:
    path = _zip_with(tmp_path / "aisdk.zip", flag_bits, method)
    with pytest.raises(InputFileError, match=message):
        load_ais([path])


def test_a_tar_archive_is_refused_clearly(tmp_path: Path) -> None:
    import tarfile

    path = tmp_path / "aisdk.tar.gz"
    with tarfile.open(path, "w:gz") as archive:
        archive.add(DMA26, "aisdk.csv")
    with pytest.raises(InputFileError, match=r"a tar archive; extract it \(tar xf aisdk.tar.gz\)"):
        load_ais([path])
