"""S-57 cell identity and integrity: its DSID record, and the checks made before it is read.

An S-57 cell's update files are checked before it is read (``s57_cell_info``): a gap in their
sequence is a ``ChartError`` unless accepted, and each cell's edition, update number, issue
date, purpose and scale are kept in ``CellInfo``.

GDAL reads a cell cut short and skips an update of another edition without a word, and a cell
in feet would be read as metres: the checks here (the cell's records against its DSSI counts,
``s57_records``; its update files, ``s57_updates``; each update's own DSID; the depth unit)
make each of these a ``ChartError`` naming the file, so no cell is read as other than it is.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyogrio
from pyogrio.errors import DataLayerError, DataSourceError, FieldError

from ..errors import ChartError
from .gdal_layers import S57_OPEN_OPTIONS, gdal_quiet
from .s57_records import record_count
from .s57_updates import applied_updates, update_files_beside


def cell_purpose(intu: Any, path: Path) -> int:
    """A cell's navigational purpose, 1 (overview) … 6 (berthing): DSID INTU, else the digit
    in the third character of its name (``US5CA72M``: 5, harbour), else 0 (unknown)."""
    purpose = whole_number(intu)
    if purpose is not None and 1 <= purpose <= 6:
        return purpose
    digit = Path(path).name[2:3]
    return int(digit) if digit.isdigit() and 1 <= int(digit) <= 6 else 0


def whole_number(value: Any) -> int | None:
    """An S-57 integer field's value; None where it is empty or not a whole number."""
    return int(value) if value is not None and str(value).strip().isdigit() else None


def dsid_fields(path: Path, apply_updates: bool = True) -> dict[str, Any]:
    """The DSID record of an S-57 cell (after its updates, unless not ``apply_updates``: the
    file's own; an update file's own too), or nothing when GDAL has none."""
    options = {**S57_OPEN_OPTIONS, "UPDATES": "APPLY" if apply_updates else "IGNORE"}
    try:
        with gdal_quiet():
            meta, _, _, values = pyogrio.raw.read(
                path, layer="DSID", read_geometry=False, **options
            )
    except (DataSourceError, DataLayerError, FieldError, RuntimeError):
        return {}
    return {
        name: column[0] for name, column in zip(meta["fields"], values, strict=True) if len(column)
    }


@dataclass(frozen=True)
class CellInfo:
    """An S-57 cell's identity as read from its DSID record after the updates were applied.

    ``update_files`` are the update files beside the base cell, in order; ``missing_updates``
    names the files missing from that sequence, when the user accepted the gap (GDAL then
    applies the updates before the gap and none after it: ``update_number`` tells which).
    ``purpose`` and ``scale`` rank the cell where charts overlap (``project_charts``).
    """

    path: Path
    name: str
    edition: int | None
    update_number: int | None
    issue_date: str | None
    update_files: tuple[Path, ...]
    missing_updates: tuple[str, ...]
    purpose: int = 0  # navigational purpose (``cell_purpose``); 0 unknown
    scale: int | None = None  # compilation scale denominator (DSPM CSCL)


def s57_cell_info(path: Path, accept_gaps: bool = False) -> CellInfo:
    """The cell's edition, update number and issue date; a gap in its update sequence is a
    ``ChartError`` unless ``accept_gaps`` (GDAL would stop at the gap without a word)."""
    updates, missing = update_files_beside(path)
    if missing and not accept_gaps:
        raise ChartError(
            f"{path}: the update sequence has a gap, {', '.join(missing)} missing beside "
            f"{', '.join(u.name for u in updates)}; GDAL would apply the updates before the gap "
            "and silently skip the rest. Put the missing update files beside the cell, or "
            "pass --accept-chart-gaps to use the cell as updated up to the gap"
        )
    records = _whole_records(path, updates)
    _check_update_identities(path, applied_updates(updates, missing))
    fields = dsid_fields(path)
    _check_all_records(path, records, fields)
    _check_updates_applied(path, updates, missing, whole_number(fields.get("DSID_UPDN")))
    check_depth_unit(path, fields.get("DSPM_DUNI"))
    issue = fields.get("DSID_ISDT")
    return CellInfo(
        path=path,
        name=str(fields.get("DSID_DSNM") or path.name),
        edition=whole_number(fields.get("DSID_EDTN")),
        update_number=whole_number(fields.get("DSID_UPDN")),
        issue_date=None if not issue else str(issue),
        update_files=tuple(updates),
        missing_updates=tuple(missing),
        purpose=cell_purpose(fields.get("DSID_INTU"), path),
        scale=whole_number(fields.get("DSPM_CSCL")),
    )


def _whole_records(path: Path, updates: Sequence[Path]) -> int:
    """The number of records of the base cell, once every record of the cell and its updates
    is found to end within its file (GDAL reads a file cut inside a record up to the cut, or
    refuses it with a message about its leaders)."""
    found = _records_of(path)
    for update in updates:
        _records_of(update)
    return found


def _records_of(file: Path) -> int:
    count = record_count(file)
    if count is None:
        raise ChartError(
            f"{file}: cut short or corrupt: a record of the file runs past its end or has "
            "no length in its leader (ISO 8211); download the cell and its updates again"
        )
    return count


def _check_update_identities(path: Path, updates: Sequence[Path]) -> None:
    """Each update file GDAL applies is, by its own DSID, the update of this edition of this
    cell that its name says: GDAL skips a stale, swapped or foreign update and every later
    one without a word, and may take its update number, so that the check after reading
    (``_check_updates_applied``) would blame the wrong file."""
    if not updates:
        return
    base = dsid_fields(path, apply_updates=False)
    cell = Path(str(base.get("DSID_DSNM") or path.name)).stem
    edition = whole_number(base.get("DSID_EDTN"))
    for update in updates:
        own = dsid_fields(update, apply_updates=False)
        if not own:  # not readable as S-57: the check after reading names it
            continue
        name = Path(str(own.get("DSID_DSNM") or update.name)).stem
        its_edition = whole_number(own.get("DSID_EDTN"))
        number = whole_number(own.get("DSID_UPDN"))
        expected = int(update.suffix[1:])
        if (name, its_edition, number) != (cell, edition, expected):
            raise ChartError(
                f"{update}: by its DSID, update {number} of edition {its_edition} of cell "
                f"{name}, not update {expected} of edition {edition} of {cell}; put update "
                f"{expected} of this edition in its place, or move it and the later updates "
                "away to use the cell as updated before it"
            )


# DSSI's counts of the records of each kind: meta, cartographic, geo and collection feature
# records, then isolated nodes, connected nodes, edges and faces.
_DSSI_COUNTS = ("NOMR", "NOCR", "NOGR", "NOLR", "NOIN", "NOCN", "NOED", "NOFA")


def _check_all_records(path: Path, found: int, fields: Mapping[str, Any]) -> None:
    """The base cell holds every record its DSSI field lists, besides its data descriptive
    record (GDAL reads a cell cut between two records without a word, the features of the
    missing records gone)."""
    counts = [whole_number(fields.get(f"DSSI_{name}")) for name in _DSSI_COUNTS]
    if any(count is None for count in counts):
        return
    # The DSID record, and the DSPM record when there is one (its scale is mandatory).
    has_dspm = bool(whole_number(fields.get("DSPM_CSCL")))
    listed = 1 + int(has_dspm) + sum(count or 0 for count in counts)
    if found - 1 < listed:
        raise ChartError(
            f"{path}: cut short: its DSSI field lists {listed} records and the file holds "
            f"{found - 1} (a download stopped early?); download the cell again"
        )


def _check_updates_applied(
    path: Path, updates: Sequence[Path], missing: Sequence[str], update_number: int | None
) -> None:
    """GDAL skips an update it cannot apply (corrupt, or of another edition) without a word;
    the cell's update number after reading tells."""
    before_gap = applied_updates(updates, missing)
    if not before_gap:
        return
    expected = int(before_gap[-1].suffix[1:])
    if update_number is None or update_number < expected:
        applied = f"up to .{update_number:03d}" if update_number else "none"
        raise ChartError(
            f"{path}: of the update files {before_gap[0].name} to {before_gap[-1].name} beside "
            f"it GDAL applied {applied}: .{(update_number or 0) + 1:03d} could not be applied "
            "(corrupt, or of another edition of the cell). Replace the update files with those "
            "of this edition, or move them away to use the base cell alone"
        )


# S-57 depth units (DSPM DUNI); ENCs must give metres.
_DEPTH_UNITS = {1: "metres", 2: "fathoms and feet", 3: "feet", 4: "fathoms and fractions"}


def check_depth_unit(path: Path, duni: Any) -> None:
    """A ``ChartError`` unless the cell's depth unit (DSPM DUNI) is metres or not given."""
    unit = whole_number(duni)
    if unit is not None and unit != 1:
        raise ChartError(
            f"{path}: the cell gives its depths in {_DEPTH_UNITS.get(unit, f'unit {unit}')} "
            "(DSPM DUNI), and colregs9 reads depths in metres; give an ENC in metres"
        )
