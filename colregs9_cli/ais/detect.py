"""Telling the layout of an AIS file from its content (``--format`` overrides this).

Each layout says how it is told (``Layout.sniff``, layouts.py), and the kinds of sniff are
tried in this order: the first bytes (``parquet``: ``PAR1``); the first non-blank line's first
character (``nmea``: ``!``, ``$`` or ``\\`` for a tag block); the column names of a header
line (``dma26`` / ``dma22``: a DMA "aisdk" header, ``Timestamp`` or ``# Timestamp``, ``Type
of mobile``, ``MMSI``, ..., with or without the ``A,B,C,D`` columns; ``marinecadastre``
(2018-2024): ``MMSI``, ``BaseDateTime``, ``LAT``, ``LON`` and ``TransceiverClass``;
``marinecadastre2015`` (2015-2017): the same without ``TransceiverClass``;
``marinecadastre2025``: the lower-case header with ``base_date_time``, ``longitude`` and
``latitude``; ``exactearth``: exactEarth/Spire's ``MMSI,Message_ID,Repeat_indicator,Time,
Millisecond,...``). Within a kind, the first layout of ``LAYOUTS`` that matches wins.

A file without a header is refused unless ``--format`` names its layout (or ``--columns``
gives a map, which names its own columns): the columns are never guessed.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import InputFileError
from .column_map import column_map
from .layouts import (
    LAYOUTS,
    MAP_PREFIX,
    HeaderSniff,
    Layout,
    LineSniff,
    MagicSniff,
    normalise_column,
)
from .sources import Source

# A tar archive (POSIX ustar or GNU) names itself at byte 257 of its first header.
_TAR_MAGIC_AT = 257
_TAR_MAGIC = b"ustar"
_DMA_TIME = re.compile(r"^\d{2}/\d{2}/\d{4} \d{2}:\d{2}:\d{2}$")
_ISO_TIME = re.compile(r"^\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}:\d{2}")
_SHOWN_CHARS = 80


@dataclass(frozen=True)
class CsvHeader:
    """The column names of a CSV file (normalised: lower case, no ``#``), if it has a header."""

    columns: tuple[str, ...]
    has_header: bool


def first_line(head: bytes) -> str:
    """The first non-blank line of the data (BOM removed; undecodable bytes replaced)."""
    text = head.decode("utf-8", errors="replace").lstrip("\ufeff")
    for line in text.splitlines():
        if line.strip():
            return line.strip()
    return ""


def detect_layout(source: Source, head: bytes) -> Layout:
    """The layout of ``source`` from the first bytes of its (decompressed) data."""
    for layout in LAYOUTS.values():
        sniff = layout.sniff
        if isinstance(sniff, MagicSniff) and sniff.matches(head):
            if sniff.when_compressed is not None and source.compression != "none":
                refusal = sniff.when_compressed.format(compression=source.compression)
                raise InputFileError(f"{source.name}: {refusal}")
            return layout
    if head[_TAR_MAGIC_AT : _TAR_MAGIC_AT + len(_TAR_MAGIC)] == _TAR_MAGIC:
        raise InputFileError(
            f"{source.name}: a tar archive; extract it (tar xf {source.path.name}) and give "
            "the AIS file inside"
        )
    line = first_line(head)
    if not line:
        raise InputFileError(f"{source.name}: holds only blank lines; give a file with AIS data")
    for layout in LAYOUTS.values():
        if isinstance(layout.sniff, LineSniff) and layout.sniff.matches(line):
            return layout
    fields = [normalise_column(f) for f in line.split(",")]
    for layout in LAYOUTS.values():
        if isinstance(layout.sniff, HeaderSniff) and layout.sniff.matches(fields):
            return layout
    shown = line if len(line) <= _SHOWN_CHARS else line[:_SHOWN_CHARS] + "..."
    if _DMA_TIME.match(fields[0]) or any(_ISO_TIME.match(f) for f in fields[:3]):
        # Data where a header should be (a file cut with split, say): the columns could be
        # in any order, and MarineCadastre's own files put longitude first since 2025.
        headerless = ", ".join(name for name, layout in LAYOUTS.items() if layout.headerless)
        raise InputFileError(
            f"{source.name}: no header line; the first line is data ({shown!r}). colregs9 "
            "does not guess which column is which: put the header line back, or give "
            f"--format ({headerless}) if the columns are in that layout's "
            "order, or --columns MAP.toml (see the README, 'Column maps')"
        )
    raise InputFileError(
        f"{source.name}: unknown AIS layout; the first line is {shown!r}. Accepted layouts: "
        f"{', '.join(LAYOUTS)}; give one with --format if the file is one of them, or describe "
        "its columns with --columns MAP.toml (see the README, 'Column maps')"
    )


def csv_header(source: Source, head: bytes, layout: Layout) -> CsvHeader:
    """The file's own column names, or the layout's defaults when the file has no header.

    A first line whose first character is a digit (or a sign or point: a longitude) is data
    (DMA, MarineCadastre and exactEarth rows start with a date or an MMSI); anything else is
    a header. A header-less file is read only in a layout whose columns are known in order
    (``Layout.headerless``: DMA and MarineCadastre, named with ``--format``).
    """
    map_ = column_map(layout)
    delimiter = map_.delimiter if map_ is not None else ","
    line = first_line(head)
    if line and not (line[0].isdigit() or line[0] in "+-."):
        return CsvHeader(tuple(normalise_column(f) for f in line.split(delimiter)), True)
    if layout.headerless:
        return CsvHeader(layout.header, False)
    what = (
        f"the map {layout.name.removeprefix(MAP_PREFIX)} names columns, not their order"
        if layout.map_file is not None
        else f"{layout.name} files differ in their number of columns"
    )
    raise InputFileError(
        f"{source.name}: no header line, and {what}; put the file's header line back"
    )
