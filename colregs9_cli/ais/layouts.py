"""The AIS input formats ("layouts"): one ``Layout`` per format, in the registry ``LAYOUTS``.

A layout tells how its files are told apart (``sniff``, which detect.py tries), which reader
reads them (``read_as``: dispatch.py's ``READERS``), the columns of a CSV layout
(``header``; ``csv_columns`` for DMA's, ``column_map`` for a layout read through a column map,
column_map.py), what it is (``description``, ``example``) and, for DMA's 26 columns, how
colregs9 writes it (``writer``, which ``colregs9 simulate`` uses).

Adding a format is one entry in ``LAYOUTS``, plus its reader when no existing reader reads it
(a ``ReadAs`` and its entry in ``dispatch.READERS``); a CSV that a column map describes needs
no reader of its own. ``--format`` takes the names of ``LAYOUTS``, listed in this order in the
help and in messages; ``--columns MAP.toml`` stands for a layout made from the map
(``find_layout``).

A light module (the standard library only): ``colregs9 --help`` lists the layouts without
loading pyarrow, and ``colregs9 stats`` resolves a layout before it imports pandas.
"""

from __future__ import annotations

import enum
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

from ..errors import ParameterError
from ..vessels import NAV_STATUS_CODES

if TYPE_CHECKING:
    import pandas as pd

MAP_PREFIX = "columns:"


class ReadAs(enum.Enum):
    """How a layout's files are read; each has its reader (``dispatch.READERS``)."""

    DMA_CSV = "DMA CSV"  # chunks of CSV, converted by dma.py
    MAPPED_CSV = "mapped CSV"  # chunks of CSV, converted through a column map (mapped.py)
    NMEA = "NMEA"  # NMEA 0183 sentences, decoded by nmea.py
    PARQUET = "Parquet"  # the canonical columns

    @property
    def is_csv(self) -> bool:
        return self in (ReadAs.DMA_CSV, ReadAs.MAPPED_CSV)


# -- how a layout is detected (detect.py tries the kinds in this order) -------------------------


@dataclass(frozen=True)
class MagicSniff:
    """The data starts with ``magic``. ``when_compressed``: such a file cannot be read
    compressed, and this says so (``{compression}``: the compression's name)."""

    magic: bytes
    when_compressed: str | None = None

    def matches(self, head: bytes) -> bool:
        return head.startswith(self.magic)


@dataclass(frozen=True)
class LineSniff:
    """The first non-blank line starts with one of ``first_chars``."""

    first_chars: str

    def matches(self, line: str) -> bool:
        return bool(line) and line[0] in self.first_chars


@dataclass(frozen=True)
class HeaderSniff:
    """A header line (names normalised, ``normalise_column``) that has all of ``columns``,
    and whose first column is ``first`` when that is given."""

    columns: frozenset[str]
    first: str | None = None

    def matches(self, fields: Sequence[str]) -> bool:
        return (self.first is None or fields[0] == self.first) and self.columns <= set(fields)


Sniff: TypeAlias = MagicSniff | LineSniff | HeaderSniff


def normalise_column(name: str) -> str:
    """A column name as the readers compare them: lower case, without ``#`` or quotes."""
    # DMA writes '# Timestamp'; tools that quote every field write '"# Timestamp"'.
    unquoted = name.strip().strip('"').strip()
    return unquoted.lstrip("#").strip().strip('"').strip().lower()


# -- how a CSV layout's columns are read and written ---------------------------------------------


@dataclass(frozen=True)
class CsvColumns:
    """What the chunk reader converts: ``row_columns`` for every row, ``columns`` for the
    rows taken; ``numeric`` are read as numbers, those also in ``whole`` as integers."""

    columns: tuple[str, ...]
    row_columns: tuple[str, ...]
    numeric: tuple[str, ...]
    whole: tuple[str, ...]
    delimiter: str = ","


@dataclass(frozen=True)
class MapSpec:
    """A built-in column map (column_map.py makes its ``ColumnMap``): source column
    (normalised) -> canonical target, the time format, and the other names a target's
    column goes by (used where the first is absent from a file's header)."""

    targets: Mapping[str, str]
    time_format: str
    aliases: Mapping[str, tuple[str, ...]] = field(default_factory=dict)


@dataclass(frozen=True)
class CsvWriter:
    """How colregs9 writes a CSV layout: the header line's columns in order, the time format
    and the texts of the navigational status codes."""

    columns: tuple[str, ...]
    time_format: str
    nav_status_texts: Mapping[int, str]

    def time_text(self, time: datetime) -> str:
        return time.strftime(self.time_format)

    def nav_status_text(self, code: int) -> str:
        return self.nav_status_texts[code]

    def write(self, path: Path, rows: pd.DataFrame, **kwargs: Any) -> None:
        """Write ``rows`` (text cells under the layout's column names, any order) as the
        layout's CSV, atomically; ``ValueError`` unless they have exactly its columns."""
        from ..outputs import write_csv  # pandas: only for the run that writes

        unknown = [c for c in rows.columns if c not in self.columns]
        missing = [c for c in self.columns if c not in rows.columns]
        if unknown or missing:
            raise ValueError(f"not the layout's columns: unknown {unknown}, missing {missing}")
        write_csv(path, rows[list(self.columns)], **kwargs)


# -- the Danish Maritime Authority "aisdk" CSV (dma.py) ------------------------------------------

# The header line of DMA's 26-column files, as DMA writes it; the 22-column files lack A-D.
DMA_COLUMNS: tuple[str, ...] = (
    "# Timestamp",
    "Type of mobile",
    "MMSI",
    "Latitude",
    "Longitude",
    "Navigational status",
    "ROT",
    "SOG",
    "COG",
    "Heading",
    "IMO",
    "Callsign",
    "Name",
    "Ship type",
    "Cargo type",
    "Width",
    "Length",
    "Type of position fixing device",
    "Draught",
    "Destination",
    "ETA",
    "Data source type",
    "A",
    "B",
    "C",
    "D",
)
DMA26_COLUMNS = tuple(normalise_column(c) for c in DMA_COLUMNS)
DMA22_COLUMNS = DMA26_COLUMNS[:22]
DMA_ABCD = DMA26_COLUMNS[22:]
DMA_TIME_FORMAT = "%d/%m/%Y %H:%M:%S"
# DMA spells these differently from ITU-R M.1371 (docs/design.md §4); the readers map both back.
DMA_NAV_STATUS_TEXTS: Mapping[int, str] = {
    **NAV_STATUS_CODES,
    3: "Restricted manoeuverability",
}

# Header columns the canonical schema has no place for: the CSV reader skips them.
_DMA_UNREAD_COLUMNS = (
    "cargo type",
    "type of position fixing device",
    "destination",
    "eta",
    "data source type",
)
# Columns read as numbers; a chunk with text in one of them is parsed again with every
# column as text (see csv_chunks.py).
_DMA_NUMERIC_COLUMNS = (
    "mmsi",
    "latitude",
    "longitude",
    "rot",
    "sog",
    "cog",
    "heading",
    "width",
    "length",
    "draught",
    *DMA_ABCD,
)
# Of those, the ones DMA writes as whole numbers (metres), read as integers, which parse
# faster than decimals (tests/benchmarks/README.md, "Figures moved from code comments"). A
# decimal in one makes its chunk text, as any other bad number.
_DMA_WHOLE_COLUMNS = ("mmsi", "width", "length", *DMA_ABCD)
# Converted for every row; the others only for the rows kept.
_DMA_ROW_COLUMNS = (
    "type of mobile",
    "mmsi",
    "latitude",
    "longitude",
    "width",
    "length",
    "draught",
    *DMA_ABCD,
)
_DMA_SNIFFED = frozenset({"type of mobile", "mmsi", "latitude", "longitude"})


def _dma_csv_columns(header: tuple[str, ...]) -> CsvColumns:
    """What the chunk reader converts of a DMA layout with the columns ``header``."""

    def present(names: tuple[str, ...]) -> tuple[str, ...]:
        return tuple(c for c in names if c in header)

    return CsvColumns(
        tuple(c for c in header if c not in _DMA_UNREAD_COLUMNS),
        present(_DMA_ROW_COLUMNS),
        present(_DMA_NUMERIC_COLUMNS),
        present(_DMA_WHOLE_COLUMNS),
    )


# -- the built-in column maps: MarineCadastre, exactEarth/Spire (column_map.py, mapped.py) -------

ISO_TIME_FORMAT = "%Y-%m-%dT%H:%M:%S"  # a space for the T is accepted too (mapped.py)
_MARINECADASTRE_TARGETS = {
    "mmsi": "mmsi",
    "basedatetime": "timestamp",
    "lat": "lat_deg",
    "lon": "lon_deg",
    "sog": "sog_kn",
    "cog": "cog_deg",
    "heading": "heading_deg",
    "vesselname": "name",
    "imo": "imo",
    "callsign": "callsign",
    "vesseltype": "ship_type",
    "status": "nav_status",
    "length": "length_m",
    "width": "breadth_m",
    "draft": "draught_m",
}
MARINECADASTRE_2015_HEADER = (
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
)
MARINECADASTRE_HEADER = (*MARINECADASTRE_2015_HEADER, "transceiverclass")
MARINECADASTRE_2025_HEADER = (
    "mmsi",
    "base_date_time",
    "longitude",
    "latitude",
    "sog",
    "cog",
    "heading",
    "vessel_name",
    "imo",
    "call_sign",
    "vessel_type",
    "status",
    "length",
    "width",
    "draft",
    "cargo",
    "transceiver",
)
_MARINECADASTRE_2025_TARGETS = {
    "mmsi": "mmsi",
    "base_date_time": "timestamp",
    "longitude": "lon_deg",
    "latitude": "lat_deg",
    "sog": "sog_kn",
    "cog": "cog_deg",
    "heading": "heading_deg",
    "vessel_name": "name",
    "imo": "imo",
    "call_sign": "callsign",
    "vessel_type": "ship_type",
    "status": "nav_status",
    "length": "length_m",
    "width": "breadth_m",
    "draft": "draught_m",
    "transceiver": "mobile_type",
}
# exactEarth / Spire decoded-message CSV, as AISdb documents it: the first columns, up to
# those read (the file has about 150; a header-less file is not accepted without them all).
EXACTEARTH_HEADER = (
    "mmsi",
    "message_id",
    "repeat_indicator",
    "time",
    "millisecond",
    "region",
    "country",
    "base_station",
    "online_data",
    "group_code",
    "sequence_id",
    "channel",
    "data_length",
    "vessel_name",
    "call_sign",
    "imo",
    "ship_type",
    "dimension_to_bow",
    "dimension_to_stern",
    "dimension_to_port",
    "dimension_to_starboard",
    "draught",
    "destination",
    "ais_version",
    "navigational_status",
    "rot",
    "sog",
    "accuracy",
    "longitude",
    "latitude",
    "cog",
    "heading",
)
_EXACTEARTH_TARGETS = {
    "mmsi": "mmsi",
    "message_id": "message_type",
    "time": "timestamp",
    "millisecond": "millisecond",
    "vessel_name": "name",
    "call_sign": "callsign",
    "imo": "imo",
    "ship_type": "ship_type",
    "dimension_to_bow": "to_bow",
    "dimension_to_stern": "to_stern",
    "dimension_to_port": "to_port",
    "dimension_to_starboard": "to_starboard",
    "draught": "draught_m",
    "navigational_status": "nav_status",
    "rot": "rot_deg_per_min",
    "sog": "sog_kn",
    "longitude": "lon_deg",
    "latitude": "lat_deg",
    "cog": "cog_deg",
    "heading": "heading_deg",
}


# -- the layouts ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Layout:
    """One AIS input format (module docstring).

    ``name``: its ``--format`` name, recorded in run.json (a ``--columns`` map's:
    ``columns:<path>``). ``description``: what it is; ``example``: how its files begin (each
    built-in layout's example is detected as that layout). ``sniff``: how ``detect_layout``
    tells it; None: only by ``--format`` or ``--columns``. ``header``: a CSV layout's columns
    in order (normalised), by which a file without its header line is read when
    ``headerless`` allows it, and in whose order missing columns are named. ``csv_columns``:
    what the chunk reader converts of a DMA layout (a map's follow the file's header,
    columns.csv_columns). ``column_map``: a built-in map; ``map_file``: a ``--columns`` map.
    ``writer``: how colregs9 writes the layout, if it does.
    """

    name: str
    read_as: ReadAs
    description: str
    example: str
    sniff: Sniff | None = None
    header: tuple[str, ...] = ()
    headerless: bool = False
    csv_columns: CsvColumns | None = None
    column_map: MapSpec | None = None
    map_file: Path | None = None
    writer: CsvWriter | None = None

    def csv_writer(self) -> CsvWriter:
        if self.writer is None:
            raise ValueError(f"colregs9 does not write the {self.name} layout")
        return self.writer


DMA26 = Layout(
    "dma26",
    ReadAs.DMA_CSV,
    description='DMA "aisdk" CSV, 26 columns (A, B, C, D: the antenna position)',
    example=",".join(DMA_COLUMNS),
    sniff=HeaderSniff(_DMA_SNIFFED | frozenset(DMA_ABCD), first="timestamp"),
    header=DMA26_COLUMNS,
    headerless=True,
    csv_columns=_dma_csv_columns(DMA26_COLUMNS),
    writer=CsvWriter(DMA_COLUMNS, DMA_TIME_FORMAT, DMA_NAV_STATUS_TEXTS),
)
DMA22 = Layout(
    "dma22",
    ReadAs.DMA_CSV,
    description='DMA "aisdk" CSV before 2020, 22 columns (without A, B, C, D)',
    example=",".join(DMA_COLUMNS[:22]),
    sniff=HeaderSniff(_DMA_SNIFFED, first="timestamp"),  # tried after dma26
    header=DMA22_COLUMNS,
    headerless=True,
    csv_columns=_dma_csv_columns(DMA22_COLUMNS),
)
_MARINECADASTRE_SNIFFED = frozenset({"mmsi", "basedatetime", "lat", "lon"})
MARINECADASTRE = Layout(
    "marinecadastre",
    ReadAs.MAPPED_CSV,
    description="US MarineCadastre CSV, 2018-2024",
    example="MMSI,BaseDateTime,LAT,LON,SOG,COG,Heading,VesselName,IMO,CallSign,VesselType,"
    "Status,Length,Width,Draft,Cargo,TransceiverClass",
    sniff=HeaderSniff(_MARINECADASTRE_SNIFFED | {"transceiverclass"}),
    header=MARINECADASTRE_HEADER,
    headerless=True,
    column_map=MapSpec(
        {**_MARINECADASTRE_TARGETS, "transceiverclass": "mobile_type"}, ISO_TIME_FORMAT
    ),
)
MARINECADASTRE2015 = Layout(
    "marinecadastre2015",
    ReadAs.MAPPED_CSV,
    description="US MarineCadastre CSV, 2015-2017 (no transceiver class: class unknown)",
    example="MMSI,BaseDateTime,LAT,LON,SOG,COG,Heading,VesselName,IMO,CallSign,VesselType,"
    "Status,Length,Width,Draft,Cargo",
    sniff=HeaderSniff(_MARINECADASTRE_SNIFFED),  # tried after marinecadastre
    header=MARINECADASTRE_2015_HEADER,
    headerless=True,
    column_map=MapSpec(_MARINECADASTRE_TARGETS, ISO_TIME_FORMAT),
)
MARINECADASTRE2025 = Layout(
    "marinecadastre2025",
    ReadAs.MAPPED_CSV,
    description="US MarineCadastre CSV, 2025 on (longitude before latitude)",
    example=",".join(MARINECADASTRE_2025_HEADER),
    sniff=HeaderSniff(frozenset({"mmsi", "base_date_time", "latitude", "longitude"})),
    header=MARINECADASTRE_2025_HEADER,
    headerless=True,
    column_map=MapSpec(_MARINECADASTRE_2025_TARGETS, ISO_TIME_FORMAT),
)
EXACTEARTH = Layout(
    "exactearth",
    ReadAs.MAPPED_CSV,
    description="exactEarth/Spire decoded AIS messages, CSV",
    example="MMSI,Message_ID,Repeat_indicator,Time,Millisecond,Region,Country,Base_station,"
    "Online_data,Group_code,Sequence_ID,Channel,Data_length,Vessel_Name,Call_sign,IMO,"
    "Ship_Type,Dimension_to_Bow,Dimension_to_stern,Dimension_to_port,"
    "Dimension_to_starboard,Draught,Destination,AIS_version,Navigational_status,ROT,SOG,"
    "Accuracy,Longitude,Latitude,COG,Heading",
    sniff=HeaderSniff(
        frozenset({"mmsi", "message_id", "time", "millisecond", "latitude", "longitude"})
    ),
    # Files differ in their number of columns: one without its header is refused.
    header=EXACTEARTH_HEADER,
    # Spire's files call the heading True_heading, AISdb's Heading.
    column_map=MapSpec(
        _EXACTEARTH_TARGETS, "%Y%m%d_%H%M%S", aliases={"heading_deg": ("true_heading",)}
    ),
)
NMEA = Layout(
    "nmea",
    ReadAs.NMEA,
    description="raw NMEA 0183 AIS sentences (!AIVDM/!AIVDO), with tag blocks, $PGHP lines "
    "or trailing unix times for the receive times",
    example="!AIVDM,1,1,,A,13u?etPv2;0n:dDPwUM1U1Cb069D,0*24",
    sniff=LineSniff("!$\\"),
)
PARQUET = Layout(
    "parquet",
    ReadAs.PARQUET,
    description="Parquet with colregs9's canonical columns",
    example="PAR1",
    # Parquet is read by seeking to its footer, which a compressed stream cannot do.
    sniff=MagicSniff(
        b"PAR1",
        when_compressed="a Parquet file compressed with {compression}; decompress it "
        "(Parquet already compresses its columns)",
    ),
)

# Detection tries the layouts of a kind of sniff in this order, and the first that matches wins
# (dma26 before dma22, marinecadastre before marinecadastre2015).
LAYOUTS: Mapping[str, Layout] = {
    layout.name: layout
    for layout in (
        DMA26,
        DMA22,
        MARINECADASTRE,
        MARINECADASTRE2015,
        MARINECADASTRE2025,
        EXACTEARTH,
        NMEA,
        PARQUET,
    )
}


def find_layout(name: str) -> Layout:
    """The layout ``--format`` names, or the one a ``--columns`` map stands for
    (``columns:<path>``, column_map.map_layout; the map is read when a file is); else
    ``ParameterError``."""
    layout = LAYOUTS.get(name)
    if layout is not None:
        return layout
    if name.startswith(MAP_PREFIX):
        return Layout(
            name,
            ReadAs.MAPPED_CSV,
            description="a CSV read through a --columns map",
            example="",
            map_file=Path(name[len(MAP_PREFIX) :]),
        )
    raise ParameterError(f"--format {name!r} is not a layout; use one of {', '.join(LAYOUTS)}")


def check_format(fmt: str | None) -> None:
    """``ParameterError`` unless ``fmt`` is None, a layout or a column map (``columns:``)."""
    if fmt is not None:
        find_layout(fmt)
