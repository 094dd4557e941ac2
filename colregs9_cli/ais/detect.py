"""Telling the layout of an AIS file from its content (``--format`` overrides this).

- ``parquet``: the file starts with ``PAR1``.
- ``nmea``: the first non-blank line starts with ``!``, ``$`` or ``\\`` (a tag block).
- ``dma26`` / ``dma22``: a DMA "aisdk" header (``Timestamp`` or ``# Timestamp``, ``Type of
  mobile``, ``MMSI``, ...), with or without the ``A,B,C,D`` columns; or, without a header, a
  first field ``dd/mm/yyyy HH:MM:SS`` and 26 or 22 fields.
- ``marinecadastre`` (2018-2024): a header with ``MMSI``, ``BaseDateTime``, ``LAT``, ``LON``
  and ``TransceiverClass``; ``marinecadastre2015`` (2015-2017): the same without
  ``TransceiverClass``; ``marinecadastre2025``: the lower-case header with ``base_date_time``,
  ``longitude`` and ``latitude``; ``exactearth``: exactEarth/Spire's ``MMSI,Message_ID,
  Repeat_indicator,Time,Millisecond,...`` (column_map.py has their maps).

A file without a header is refused unless ``--format`` names its layout (or ``--columns``
gives a map, which names its own columns): the columns are never guessed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import InputFileError
from .column_map import BUILTIN_MAPS, MAP_PREFIX, builtin_for_header, column_map
from .sources import PARQUET_MAGIC, Source

MAP_LAYOUTS = tuple(BUILTIN_MAPS)
LAYOUTS = ("dma26", "dma22", *MAP_LAYOUTS, "nmea", "parquet")
CSV_LAYOUTS = ("dma26", "dma22", *MAP_LAYOUTS)

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
DEFAULT_COLUMNS: dict[str, tuple[str, ...]] = {
    "dma26": DMA26_COLUMNS,
    "dma22": DMA22_COLUMNS,
    **{name: map_.header for name, map_ in BUILTIN_MAPS.items() if name != "exactearth"},
}

# A tar archive (POSIX ustar or GNU) names itself at byte 257 of its first header.
_TAR_MAGIC_AT = 257
_TAR_MAGIC = b"ustar"
_DMA_TIME = re.compile(r"^\d{2}/\d{2}/\d{4} \d{2}:\d{2}:\d{2}$")
_ISO_TIME = re.compile(r"^\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}:\d{2}")
_SHOWN_CHARS = 80


def is_csv_layout(layout: str) -> bool:
    """DMA's layouts, the built-in maps and ``--columns`` maps."""
    return layout in CSV_LAYOUTS or layout.startswith(MAP_PREFIX)


def known_layout(layout: str) -> bool:
    return layout in LAYOUTS or layout.startswith(MAP_PREFIX)


@dataclass(frozen=True)
class CsvHeader:
    """The column names of a CSV file (normalised: lower case, no ``#``), if it has a header."""

    columns: tuple[str, ...]
    has_header: bool


def normalise_column(name: str) -> str:
    # DMA writes '# Timestamp'; tools that quote every field write '"# Timestamp"'.
    unquoted = name.strip().strip('"').strip()
    return unquoted.lstrip("#").strip().strip('"').strip().lower()


def first_line(head: bytes) -> str:
    """The first non-blank line of the data (BOM removed; undecodable bytes replaced)."""
    text = head.decode("utf-8", errors="replace").lstrip("\ufeff")
    for line in text.splitlines():
        if line.strip():
            return line.strip()
    return ""


def detect_layout(source: Source, head: bytes) -> str:
    """The layout of ``source`` from the first bytes of its (decompressed) data."""
    if head.startswith(PARQUET_MAGIC):
        if source.compression == "none":
            return "parquet"
        # Parquet is read by seeking to its footer, which a compressed stream cannot do.
        raise InputFileError(
            f"{source.name}: a Parquet file compressed with {source.compression}; decompress "
            "it (Parquet already compresses its columns)"
        )
    if head[_TAR_MAGIC_AT : _TAR_MAGIC_AT + len(_TAR_MAGIC)] == _TAR_MAGIC:
        raise InputFileError(
            f"{source.name}: a tar archive; extract it (tar xf {source.path.name}) and give "
            "the AIS file inside"
        )
    line = first_line(head)
    if not line:
        raise InputFileError(f"{source.name}: holds only blank lines; give a file with AIS data")
    if line[0] in "!$\\":
        return "nmea"
    fields = [normalise_column(f) for f in line.split(",")]
    names = set(fields)
    if fields[0] == "timestamp" and {"type of mobile", "mmsi", "latitude", "longitude"} <= names:
        return "dma26" if {"a", "b", "c", "d"} <= names else "dma22"
    builtin = builtin_for_header(names)
    if builtin is not None:
        return builtin
    shown = line if len(line) <= _SHOWN_CHARS else line[:_SHOWN_CHARS] + "..."
    if _DMA_TIME.match(fields[0]) or any(_ISO_TIME.match(f) for f in fields[:3]):
        # Data where a header should be (a file cut with split, say): the columns could be
        # in any order, and MarineCadastre's own files put longitude first since 2025.
        raise InputFileError(
            f"{source.name}: no header line; the first line is data ({shown!r}). colregs9 "
            "does not guess which column is which: put the header line back, or give "
            f"--format ({', '.join(DEFAULT_COLUMNS)}) if the columns are in that layout's "
            "order, or --columns MAP.toml (see the README, 'Column maps')"
        )
    raise InputFileError(
        f"{source.name}: unknown AIS layout; the first line is {shown!r}. Accepted layouts: "
        f"{', '.join(LAYOUTS)}; give one with --format if the file is one of them, or describe "
        "its columns with --columns MAP.toml (see the README, 'Column maps')"
    )


def csv_header(source: Source, head: bytes, layout: str) -> CsvHeader:
    """The file's own column names, or the layout's defaults when the file has no header.

    A first line whose first character is a digit (or a sign or point: a longitude) is data
    (DMA, MarineCadastre and exactEarth rows start with a date or an MMSI); anything else is
    a header. A header-less file is read only in a layout whose columns are known in order
    (DMA and MarineCadastre, named with ``--format``).
    """
    map_ = column_map(layout)
    delimiter = map_.delimiter if map_ is not None else ","
    line = first_line(head)
    if line and not (line[0].isdigit() or line[0] in "+-."):
        return CsvHeader(tuple(normalise_column(f) for f in line.split(delimiter)), True)
    if layout in DEFAULT_COLUMNS:
        return CsvHeader(DEFAULT_COLUMNS[layout], False)
    what = (
        f"the map {layout[len(MAP_PREFIX) :]} names columns, not their order"
        if layout.startswith(MAP_PREFIX)
        else f"{layout} files differ in their number of columns"
    )
    raise InputFileError(
        f"{source.name}: no header line, and {what}; put the file's header line back"
    )
