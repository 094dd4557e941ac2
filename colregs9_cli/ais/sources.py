"""Opening AIS input files: plain, gzip, bzip2, xz, zstd or zip (one data file inside), hashed
while read.

The compression is told by the file's first bytes, not its name; every kind is read as a
stream (the standard library's gzip, bz2 and lzma, pyarrow's zstd codec). A zip must hold exactly
one CSV (DMA ships one per zip); a zip without a CSV may hold exactly one other file (an
NMEA log). The sha256 is of the file as stored (the .gz or .zip itself) and is computed
while the data is read, so a multi-GB file is read from disk once. Decompression failures
(a truncated or corrupt gzip or zip) become ``InputFileError`` naming the file.
"""

from __future__ import annotations

import bz2
import gzip
import hashlib
import io
import lzma
import stat
import zipfile
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import pyarrow as pa

from ..errors import InputFileError, input_status
from ..progress import ProgressSink

GZIP_MAGIC = b"\x1f\x8b"
ZIP_MAGIC = b"PK\x03\x04"
# Stream compressions by their magic bytes.
STREAM_MAGIC = {
    GZIP_MAGIC: "gzip",
    b"BZh": "bzip2",
    b"\xfd7zXZ\x00": "xz",
    b"\x28\xb5\x2f\xfd": "zstd",
}
_CHUNK = 1 << 20
# The head read for layout detection; a DMA header line is about 300 bytes.
HEAD_BYTES = 64 * 1024
_DECOMPRESSION_ERRORS = (
    EOFError,
    zlib.error,
    gzip.BadGzipFile,
    zipfile.BadZipFile,
    lzma.LZMAError,
    pa.ArrowException,
    OSError,
)


@dataclass(frozen=True)
class Source:
    """An input file and how its data is stored."""

    path: Path
    compression: str  # "none", "zip" or a STREAM_MAGIC kind ("gzip", "bzip2", "xz", "zstd")
    member: str | None  # the data file inside a zip
    size_bytes: int

    @property
    def name(self) -> str:
        """The name used in messages: the path, plus the zip member."""
        return f"{self.path}!{self.member}" if self.member else str(self.path)


def inspect_source(path: Path) -> Source:
    """Check that ``path`` is a readable, non-empty file and find its compression."""
    path = Path(path)
    status = input_status(path)
    if stat.S_ISDIR(status.st_mode):
        raise InputFileError(f"{path}: not a file; give AIS files, not a directory")
    if not stat.S_ISREG(status.st_mode):
        # Each input is read twice (its sha256, then its rows), which a stream cannot give.
        raise InputFileError(
            f"{path}: a pipe or a device, not a file; give the AIS file itself (compressed or "
            "not: colregs9 decompresses it)"
        )
    size = status.st_size
    if size == 0:
        raise InputFileError(f"{path}: the file is empty; give a file with AIS data")
    with path.open("rb") as handle:
        magic = handle.read(8)
    for prefix, kind in STREAM_MAGIC.items():
        if magic.startswith(prefix):
            return Source(path, kind, None, size)
    if magic.startswith(ZIP_MAGIC):
        return Source(path, "zip", _zip_member(path), size)
    return Source(path, "none", None, size)


# The compression methods Python's zipfile reads.
_ZIP_METHODS = {
    zipfile.ZIP_STORED: "stored",
    zipfile.ZIP_DEFLATED: "deflate",
    zipfile.ZIP_BZIP2: "bzip2",
    zipfile.ZIP_LZMA: "lzma",
}


def _zip_member(path: Path) -> str:
    try:
        with zipfile.ZipFile(path) as archive:
            infos = {
                info.filename: info
                for info in archive.infolist()
                if not info.is_dir() and not info.filename.startswith("__MACOSX/")
            }
    except (zipfile.BadZipFile, OSError, EOFError) as exc:
        raise InputFileError(
            f"{path}: truncated or corrupt zip ({exc}); download the file again"
        ) from None
    member = _only_data_file(path, list(infos))
    info = infos[member]
    if info.flag_bits & 0x1:
        raise InputFileError(
            f"{path}: {member} is encrypted in the zip; unzip it with its password and give "
            "the file itself"
        )
    if info.compress_type not in _ZIP_METHODS:
        raise InputFileError(
            f"{path}: {member} is compressed with zip method {info.compress_type}, which "
            f"colregs9 cannot read ({', '.join(_ZIP_METHODS.values())} only); unzip it with "
            "another tool and give the file itself"
        )
    return member


def _only_data_file(path: Path, names: list[str]) -> str:
    csvs = [n for n in names if n.lower().endswith(".csv")]
    if len(csvs) == 1:
        return csvs[0]
    if len(csvs) > 1:
        raise InputFileError(
            f"{path}: the zip holds {len(csvs)} CSV files ({', '.join(csvs[:3])}"
            f"{', ...' if len(csvs) > 3 else ''}); give one CSV per zip, or unzip it"
        )
    if len(names) == 1:
        return names[0]
    raise InputFileError(
        f"{path}: the zip holds no CSV file"
        + (f" (it holds {len(names)} other files)" if names else " (it is empty)")
        + "; give a zip with exactly one AIS CSV"
    )


class _CountingReader(io.RawIOBase):
    """A raw binary reader that hashes and reports the bytes read through it.

    The bytes of a read are hashed before the read returns: the caller owns the buffer again
    as soon as it does, and may refill or free it (hashing the caller's buffer on a worker
    thread after the read returned gave a wrong, run-dependent sha256 for plain files).
    Hashing here was also faster than hashing a copy on a thread of its own, and took less
    CPU (figures: tests/benchmarks/README.md, "Figures moved from code comments").
    """

    def __init__(self, raw: BinaryIO, hasher: hashlib._Hash | None, progress: ProgressSink) -> None:
        self._raw = raw
        self._hasher = hasher
        self._progress = progress

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: memoryview | bytearray) -> int:  # type: ignore[override]
        count = self._raw.readinto(buffer)  # type: ignore[attr-defined]
        if count:
            if self._hasher is not None:
                with memoryview(buffer) as view, view[:count] as data:
                    self._hasher.update(data)
            self._progress.advance(count)
        return count or 0

    def drain(self) -> None:
        while self.read(_CHUNK):
            pass


class _Silent:
    def advance(self, amount: float = 1.0) -> None:
        return None

    def describe(self, note: str) -> None:
        return None


def read_head(source: Source, n_bytes: int = HEAD_BYTES) -> bytes:
    """The first ``n_bytes`` of the decompressed data."""
    with open_data(source) as opened:
        return opened.stream.read(n_bytes)


@dataclass
class OpenedData:
    """A decompressed binary stream, and the file's sha256 once the stream is finished."""

    stream: BinaryIO
    _counting: _CountingReader
    _hasher: hashlib._Hash | None
    _path: Path

    def finish(self) -> str:
        """Read what is left of the file (for the hash) and return the file's sha256."""
        self._counting.drain()
        if self._hasher is None:
            return sha256_file(self._path)
        return self._hasher.hexdigest()


@contextmanager
def open_data(source: Source, progress: ProgressSink | None = None) -> Iterator[OpenedData]:
    """Open the decompressed data; decompression errors inside become ``InputFileError``.

    Progress is reported in bytes of the stored file (of the zip member for a zip).
    """
    sink = progress if progress is not None else _Silent()
    try:
        with source.path.open("rb") as raw:
            if source.compression == "zip":
                with (
                    zipfile.ZipFile(raw) as archive,
                    archive.open(source.member or "") as member,
                    _CountingReader(member, None, sink) as counting,  # type: ignore[arg-type]
                ):
                    yield OpenedData(
                        io.BufferedReader(counting, _CHUNK), counting, None, source.path
                    )
                return
            hasher = hashlib.sha256()
            with _CountingReader(raw, hasher, sink) as counting:
                buffered = io.BufferedReader(counting, _CHUNK)
                yield OpenedData(
                    _decompressed(buffered, source.compression), counting, hasher, source.path
                )
    except InputFileError:
        raise
    except _DECOMPRESSION_ERRORS as exc:
        raise decompression_error(source, exc) from None


def _decompressed(buffered: BinaryIO, compression: str) -> BinaryIO:
    """The decompressed stream over the stored bytes."""
    if compression == "gzip":
        return gzip.GzipFile(fileobj=buffered, mode="rb")  # type: ignore[return-value]
    if compression == "bzip2":
        return bz2.BZ2File(buffered, mode="rb")  # type: ignore[return-value]
    if compression == "xz":
        return lzma.LZMAFile(buffered, mode="rb")  # type: ignore[return-value]
    if compression == "zstd":
        return pa.CompressedInputStream(buffered, "zstd")  # type: ignore[return-value]
    return buffered  # type: ignore[return-value]


def decompression_error(source: Source, exc: BaseException) -> InputFileError:
    kind = source.compression if source.compression != "none" else "file"
    return InputFileError(
        f"{source.name}: truncated or corrupt {kind} ({exc}); download or copy the file again"
    )


def sha256_file(path: Path) -> str:
    with path.open("rb") as handle:
        return hashlib.file_digest(handle, "sha256").hexdigest()


def locate_non_utf8(source: Source) -> tuple[int, int, int] | None:
    """(line, byte offset in the decompressed data, byte value) of the first non-UTF-8 byte."""
    offset = 0
    with open_data(source) as opened:
        for line_no, line in enumerate(opened.stream, start=1):
            try:
                line.decode("utf-8")
            except UnicodeDecodeError as exc:
                return line_no, offset + exc.start, line[exc.start]
            offset += len(line)
    return None
