"""The columns a CSV layout reads, and how they are read: a DMA layout's are fixed
(``Layout.csv_columns``, layouts.py); the others' follow their column map (column_map.py) as
resolved for the file's header.

A light module (no ``pyarrow.compute``, pandas or shapely): ``colregs9 stats`` starts reading
its first CSV before it imports those (``csv_read.start_reading``).
"""

from __future__ import annotations

from .column_map import ColumnMap, column_map
from .layouts import CsvColumns, Layout


def csv_columns(layout: Layout, header: tuple[str, ...] = ()) -> CsvColumns:
    """The columns of ``layout`` read from a file with the columns ``header``."""
    if layout.csv_columns is not None:
        return layout.csv_columns
    return map_columns(file_map(layout, header))


def file_map(layout: Layout, header: tuple[str, ...]) -> ColumnMap:
    """The column map of ``layout`` for a file with the columns ``header`` (its aliases
    resolved, column_map.py)."""
    map_ = column_map(layout)
    if map_ is None:
        raise ValueError(f"{layout.name!r} is not a mapped CSV layout")
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


def missing_columns(layout: Layout, header: tuple[str, ...]) -> list[str]:
    """The columns the layout reads that the file's ``header`` lacks, in the layout's order
    (``Layout.header``; a ``--columns`` map's: the order of its targets)."""
    present = set(header)
    order = {c: i for i, c in enumerate(layout.header)}
    absent = [c for c in csv_columns(layout, header).columns if c not in present]
    return sorted(absent, key=lambda c: order.get(c, len(order)))
