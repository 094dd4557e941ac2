"""Telling the layout of an AIS file from its content (``--format`` overrides this).

- ``parquet``: the file starts with ``PAR1``.
- ``nmea``: the first non-blank line starts with ``!``, ``$`` or ``\\`` (a tag block).
- ``dma26`` / ``dma22``: a DMA "aisdk" header (``Timestamp`` or ``# Timestamp``, ``Type of
  mobile``, ``MMSI``, ...), with or without the ``A,B,C,D`` columns; or, without a header, a
  first field ``dd/mm/yyyy HH:MM:SS`` and 26 or 22 fields.
- ``marinecadastre``: a header with ``MMSI``, ``BaseDateTime``, ``LAT`` and ``LON``; or,
  without a header, 17 fields with an ISO time in the second.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import InputFileError
from .sources import PARQUET_MAGIC, Source

LAYOUTS = ("dma26", "dma22", "marinecadastre", "nmea", "parquet")
CSV_LAYOUTS = ("dma26", "dma22", "marinecadastre")

DMA22_COLUMNS = (
    "timestamp",
    "type of mobile",
    "mmsi",
    "latitude",
    "longitude",
    "navigational status",
    "rot",
    "sog",
    "cog",
    "heading",
    "imo",
    "callsign",
    "name",
    "ship type",
    "cargo type",
    "width",
    "length",
    "type of position fixing device",
    "draught",
    "destination",
    "eta",
    "data source type",
)
DMA26_COLUMNS = (*DMA22_COLUMNS, "a", "b", "c", "d")
MARINECADASTRE_COLUMNS = (
    "mmsi",
    "basedatetime",
    "lat",
    "lon",
    "sog",
    "cog",
    "heading",
    "vesselname",
    "imo",
    "callsign",
    "vesseltype",
    "status",
    "length",
    "width",
    "draft",
    "cargo",
    "transceiverclass",
)
DEFAULT_COLUMNS: dict[str, tuple[str, ...]] = {
    "dma26": DMA26_COLUMNS,
    "dma22": DMA22_COLUMNS,
    "marinecadastre": MARINECADASTRE_COLUMNS,
}

_DMA_TIME = re.compile(r"^\d{2}/\d{2}/\d{4} \d{2}:\d{2}:\d{2}$")
_ISO_TIME = re.compile(r"^\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}:\d{2}")
_SHOWN_CHARS = 80


@dataclass(frozen=True)
class CsvHeader:
    """The column names of a CSV file (normalised: lower case, no ``#``), if it has a header."""

    columns: tuple[str, ...]
    has_header: bool


def normalise_column(name: str) -> str:
    return name.strip().lstrip("#").strip().strip('"').strip().lower()


def first_line(head: bytes) -> str:
    """The first non-blank line of the data (BOM removed; undecodable bytes replaced)."""
    text = head.decode("utf-8", errors="replace").lstrip("\ufeff")
    for line in text.splitlines():
        if line.strip():
            return line.strip()
    return ""


def detect_layout(source: Source, head: bytes) -> str:
    """The layout of ``source`` from the first bytes of its (decompressed) data."""
    if source.compression == "none" and head.startswith(PARQUET_MAGIC):
        return "parquet"
    line = first_line(head)
    if not line:
        raise InputFileError(f"{source.name}: holds only blank lines; give a file with AIS data")
    if line[0] in "!$\\":
        return "nmea"
    fields = [normalise_column(f) for f in line.split(",")]
    names = set(fields)
    if fields[0] == "timestamp" and {"type of mobile", "mmsi", "latitude", "longitude"} <= names:
        return "dma26" if {"a", "b", "c", "d"} <= names else "dma22"
    if {"mmsi", "basedatetime", "lat", "lon"} <= names:
        return "marinecadastre"
    if _DMA_TIME.match(fields[0]) and len(fields) in (22, 26):
        return "dma26" if len(fields) == 26 else "dma22"
    if len(fields) == len(MARINECADASTRE_COLUMNS) and _ISO_TIME.match(fields[1]):
        return "marinecadastre"
    shown = line if len(line) <= _SHOWN_CHARS else line[:_SHOWN_CHARS] + "..."
    raise InputFileError(
        f"{source.name}: unknown AIS layout; the first line is {shown!r}. Accepted layouts: "
        f"{', '.join(LAYOUTS)}; give one with --format if the file is one of them"
    )


def csv_header(head: bytes, layout: str) -> CsvHeader:
    """The file's own column names, or the layout's defaults when the file has no header.

    A first line whose first character is a digit is data (DMA and MarineCadastre rows start
    with a date or an MMSI); anything else is a header.
    """
    line = first_line(head)
    if line and not line[0].isdigit():
        return CsvHeader(tuple(normalise_column(f) for f in line.split(",")), True)
    return CsvHeader(DEFAULT_COLUMNS[layout], False)
