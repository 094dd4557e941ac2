"""S-57 update files beside a base cell (light: the run manifest lists them too)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path


def update_files_beside(path: Path) -> tuple[list[Path], list[str]]:
    """The update files ``X.001``, ``X.002`` … beside the base cell ``X.000``, and the names
    of those missing below the highest one present."""
    numbers = sorted(
        int(candidate.suffix[1:])
        for candidate in path.parent.glob(f"{path.stem}.*")
        if len(candidate.suffix) == 4
        and candidate.suffix[1:].isdigit()
        and candidate.suffix != ".000"
    )
    present = set(numbers)
    highest = numbers[-1] if numbers else 0
    missing = [f"{path.stem}.{n:03d}" for n in range(1, highest + 1) if n not in present]
    return [path.with_suffix(f".{n:03d}") for n in numbers], missing


def applied_updates(updates: Sequence[Path], missing: Sequence[str]) -> list[Path]:
    """The update files GDAL applies: those before the first one missing."""
    first_gap = min((int(name.rsplit(".", 1)[1]) for name in missing), default=None)
    return [u for u in updates if first_gap is None or int(u.suffix[1:]) < first_gap]
