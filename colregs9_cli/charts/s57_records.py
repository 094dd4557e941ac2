"""The records of an S-57 file (ISO/IEC 8211), counted from their leaders.

GDAL reads a cell cut short between two records without a word, with the features of the
missing records gone: a cell whose download stopped at 90 % of its records read as 52 of its
249 depth areas, all of them shallow. Each record's leader starts with the record's length in
five digits, and the cell's DSSI field lists how many records of each kind it holds, which
together tell such a cell (``cells.s57_cell_info`` compares them).
"""

from __future__ import annotations

from pathlib import Path

# An ISO 8211 leader: the record length in its first five bytes.
LEADER_BYTES = 24
_LENGTH_DIGITS = 5


def record_count(path: Path) -> int | None:
    """The number of records in ``path``, the data descriptive record included; None when a
    leader does not start with its record's length or a record runs past the end of the
    file (cut short inside a record, or not ISO 8211)."""
    data = Path(path).read_bytes()
    position = count = 0
    while position < len(data):
        length_text = data[position : position + _LENGTH_DIGITS]
        if len(length_text) < _LENGTH_DIGITS or not length_text.isdigit():
            return None
        length = int(length_text)
        if length < LEADER_BYTES or position + length > len(data):
            return None
        position += length
        count += 1
    return count
