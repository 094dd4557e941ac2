"""The columns each CSV layout reads, and how they are read (DMA here; the others by their
column maps, column_map.py).

A light module (no ``pyarrow.compute``, pandas or shapely): ``colregs9 stats`` starts reading
its first CSV before it imports those (``csv_read.start_reading``).
"""

from __future__ import annotations

from dataclasses import dataclass

from .column_map import ColumnMap, column_map
from .detect import DMA22_COLUMNS

# -- DMA "aisdk" (lower-case names) -------------------------------------------------------------

# Header columns the canonical schema has no place for: the CSV reader skips them.
DMA_UNREAD_COLUMNS = (
    "cargo type",
    "type of position fixing device",
    "destination",
    "eta",
    "data source type",
)
DMA_READ_COLUMNS = tuple(c for c in DMA22_COLUMNS if c not in DMA_UNREAD_COLUMNS)
DMA_ABCD = ("a", "b", "c", "d")
# Columns read as numbers; a chunk with text in one of them is parsed again with every
# column as text (see csv_chunks.py).
DMA_NUMERIC_COLUMNS = (
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
# Of those, the ones DMA writes as whole numbers (metres), read as integers: about 5 % faster
# to parse than decimals. A decimal in one makes its chunk text, as any other bad number.
DMA_WHOLE_COLUMNS = ("mmsi", "width", "length", *DMA_ABCD)
DMA_STATIC_TEXT_COLUMNS = ("ship type", "name", "callsign", "imo")
# Converted for every row; the others only for the rows kept.
DMA_ROW_COLUMNS = ("type of mobile", "mmsi", "latitude", "longitude", "width", "length", "draught")


def dma_read_columns(has_abcd: bool) -> tuple[str, ...]:
    return (*DMA_READ_COLUMNS, *DMA_ABCD) if has_abcd else DMA_READ_COLUMNS


def dma_row_columns(has_abcd: bool) -> tuple[str, ...]:
    return (*DMA_ROW_COLUMNS, *DMA_ABCD) if has_abcd else DMA_ROW_COLUMNS


def dma_dimension_columns(has_abcd: bool) -> tuple[str, ...]:
    dimensions = ("width", "length", "draught")
    return (*dimensions, *DMA_ABCD) if has_abcd else dimensions


@dataclass(frozen=True)
class CsvColumns:
    """What the chunk reader converts: ``row_columns`` for every row, ``columns`` for the
    rows taken; ``numeric`` are read as numbers, those also in ``whole`` as integers."""

    columns: tuple[str, ...]
    row_columns: tuple[str, ...]
    numeric: tuple[str, ...]
    whole: tuple[str, ...]
    delimiter: str = ","


def csv_columns(layout: str, header: tuple[str, ...] = ()) -> CsvColumns:
    """The columns of ``layout`` read from a file with the columns ``header``."""
    if layout in ("dma26", "dma22"):
        abcd = layout == "dma26"

        def present(names: tuple[str, ...]) -> tuple[str, ...]:
            return tuple(c for c in names if abcd or c not in DMA_ABCD)

        return CsvColumns(
            dma_read_columns(abcd),
            dma_row_columns(abcd),
            present(DMA_NUMERIC_COLUMNS),
            present(DMA_WHOLE_COLUMNS),
        )
    return map_columns(file_map(layout, header))


def file_map(layout: str, header: tuple[str, ...]) -> ColumnMap:
    """The column map of ``layout`` for a file with the columns ``header`` (its aliases
    resolved, column_map.py)."""
    map_ = column_map(layout)
    if map_ is None:
        raise ValueError(f"{layout!r} is not a mapped CSV layout")
    return map_.for_header(header)


def map_columns(map_: ColumnMap) -> CsvColumns:
    """What the chunk reader converts for a column map (column_map.py): the mapped columns,
    the MMSI, position, class and dimensions for every row."""
    return CsvColumns(
        map_.read_columns,
        map_.row_columns,
        map_.numeric_columns,
        map_.whole_columns,
        map_.delimiter,
    )
