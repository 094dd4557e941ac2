"""Progress bars on stderr: shown only for a TTY and when not ``--quiet``."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from rich.progress import Progress


class ProgressSink(Protocol):
    def advance(self, amount: float = 1.0) -> None: ...

    def describe(self, note: str) -> None:
        """Show ``note`` (what is in progress: a slab, a day) beside the description."""


class _Silent:
    def advance(self, amount: float = 1.0) -> None:
        return None

    def describe(self, note: str) -> None:
        return None


class _RichSink:
    def __init__(self, progress: Progress, task_id: int, description: str) -> None:
        self._progress = progress
        self._task_id = task_id
        self._description = description

    def advance(self, amount: float = 1.0) -> None:
        self._progress.advance(self._task_id, amount)  # type: ignore[arg-type]

    def describe(self, note: str) -> None:
        self._progress.update(
            self._task_id,  # type: ignore[arg-type]
            description=f"{self._description} ({note})",
        )


def progress_enabled(quiet: bool) -> bool:
    return not quiet and sys.stderr.isatty()


@contextmanager
def progress_bar(
    description: str, total: float | None, enabled: bool, in_bytes: bool = False
) -> Iterator[ProgressSink]:
    """A progress bar over ``total`` units (steps, slabs, ...; bytes, shown in MB, when
    ``in_bytes``), or a silent sink."""
    if not enabled:
        yield _Silent()
        return
    # rich is imported only when a bar is shown: quiet and piped runs start faster.
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        DownloadColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    progress = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        DownloadColumn() if in_bytes else MofNCompleteColumn(),
        TimeElapsedColumn(),
        TimeRemainingColumn(),
        console=Console(stderr=True),
        transient=True,
    )
    with progress:
        task_id = progress.add_task(description, total=total)
        yield _RichSink(progress, task_id, description)
