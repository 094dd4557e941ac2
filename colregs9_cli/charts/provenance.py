"""The charts of a run as run.json records them: every file that went into each chart, with
its sha256 and whether GDAL applied it."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..provenance import file_sha256
from .s57_updates import applied_updates, update_files_beside


def charts_manifest(
    paths: Sequence[Path], used: Sequence[Path] | None = None
) -> list[dict[str, Any]]:
    """Each chart given, with every file that went into it or lies beside it and its sha256:
    an S-57 base cell ``X.000`` with the update files ``X.001``, ``X.002`` …, each marked
    ``applied`` or not (GDAL applies none after a gap), and the names of those missing.
    ``used``: the charts the run used (the others lie away from the AIS); default all."""
    charts = []
    for path in paths:
        updates, missing = update_files_beside(path) if path.suffix == ".000" else ([], [])
        applied = applied_updates(updates, missing)
        files = [{"path": str(path), "sha256": file_sha256(path), "applied": True}]
        files += [
            {"path": str(update), "sha256": file_sha256(update), "applied": update in applied}
            for update in updates
        ]
        charts.append(
            {
                "path": str(path),
                "used": used is None or Path(path) in {Path(u) for u in used},
                "files": files,
                "missing_updates": missing,
            }
        )
    return charts
