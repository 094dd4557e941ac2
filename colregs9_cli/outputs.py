"""Atomic output: write to a temporary file beside the target, then rename over it.

A crash leaves either the old file or the new one, never a half-written report.
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import stat
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

import pandas as pd

from .errors import OutputError


def _kind(path: Path) -> str:
    """What a path that is not a regular file is, for messages."""
    mode = path.stat().st_mode
    for test, name in (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISFIFO, "a named pipe (FIFO)"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "not a regular file"


def check_out_file(target: Path) -> None:
    """Refuse, before any work, an ``--out`` file that cannot take the output: one under a
    file, or an existing path that is not a regular file (a directory, a FIFO, a device: the
    output would replace it by a regular file). An existing regular file is replaced."""
    existing = target.parent
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise OutputError(f"{target}: lies under {existing}, which is a file; give another --out")
    try:
        present = target.exists()
        kind = _kind(target) if present and not target.is_file() else ""
    except OSError as exc:
        raise _output_error(target, exc) from None
    if kind:
        raise OutputError(
            f"{target}: --out is {kind}, not a regular file; give the path of a file to write"
        )


@contextmanager
def atomic_path(target: Path, suffix: str = ".tmp") -> Iterator[Path]:
    """Yield a temporary path in the target's directory; rename it to ``target`` on success.

    The temporary file is created with mode 0666 less the umask, as ``open`` would create
    the target itself (``tempfile.mkstemp`` would make it 0600 whatever the umask). ``suffix``
    ends its name, for writers that go by it (GDAL wants ``.gpkg``).
    """
    check_out_file(target)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = _new_file(target.parent, f".{target.name}.", suffix)
        mode = stat.S_IMODE(tmp.stat().st_mode)
    except OSError as exc:
        raise _output_error(target, exc) from None
    try:
        yield tmp
        try:
            # A writer that made the file again (GDAL, through SQLite: 0644) chose its mode.
            os.chmod(tmp, mode)
            os.replace(tmp, target)
        except OSError as exc:
            raise _output_error(target, exc) from None
    finally:
        if tmp.exists():
            tmp.unlink()


def _new_file(directory: Path, prefix: str, suffix: str) -> Path:
    """An empty file of a fresh name, created exclusively, with the umask's mode."""
    while True:
        candidate = directory / f"{prefix}{secrets.token_hex(6)}{suffix}"
        try:
            fd = os.open(candidate, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666)
        except FileExistsError:
            continue
        os.close(fd)
        return candidate


REPORT_MARKER = "run.json"


def is_report(directory: Path) -> bool:
    """True for a directory holding a colregs9 report (its run.json says so)."""
    try:
        manifest = json.loads((directory / REPORT_MARKER).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(manifest, dict) and manifest.get("tool") == "colregs9"


def check_out_dir(out_dir: Path, overwrite: bool = False, inputs: Sequence[Path] = ()) -> None:
    """Refuse, before any work, an ``--out`` that cannot take a report: a file, a directory
    under a file, one without write access, the current, a parent or the home directory
    (the report replaces its directory whole), one that is or holds one of the run's
    ``inputs``, or a directory holding something other than a colregs9 report (unless
    ``overwrite``: its content is then replaced)."""
    if out_dir.exists() and not out_dir.is_dir():
        raise OutputError(f"{out_dir}: --out is a file, not a directory; give a directory")
    existing = out_dir
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise OutputError(
            f"{out_dir}: --out lies under {existing}, which is a file; give a directory"
        )
    # The report replaces out_dir from beside it: its parent must be writable.
    writable_in = out_dir.parent if existing == out_dir else existing
    if not os.access(writable_in, os.W_OK | os.X_OK):
        raise OutputError(
            f"{out_dir}: no permission to write in {writable_in}; give a directory you can write to"
        )
    resolved = out_dir.resolve()
    if resolved in (Path.cwd().resolve(), *Path.cwd().resolve().parents, Path.home().resolve()):
        raise OutputError(
            f"{out_dir}: --out would replace the current, a parent or the home directory; "
            "give a directory of its own for the report"
        )
    for given in inputs:
        if resolved == Path(given).resolve() or resolved in Path(given).resolve().parents:
            raise OutputError(
                f"{out_dir}: --out is or holds the input {given}, which the report would "
                "replace; give another directory for the report"
            )
    if out_dir.is_dir() and any(out_dir.iterdir()) and not is_report(out_dir) and not overwrite:
        raise OutputError(
            f"{out_dir}: --out holds files that are not a colregs9 report; give a new or empty "
            "directory, or add --overwrite to replace it"
        )


@contextmanager
def report_directory(out_dir: Path) -> Iterator[Path]:
    """Yield an empty staging directory beside ``out_dir``; on success it replaces
    ``out_dir`` whole, so that a report is never a mix of two runs (no stale files of an
    earlier run remain). On failure ``out_dir`` is left as it was, and an ``OSError`` while
    writing becomes one ``OutputError``."""
    try:
        out_dir.parent.mkdir(parents=True, exist_ok=True)
        staging = _new_directory(out_dir.parent, f".{out_dir.name}.", ".new")
    except OSError as exc:
        raise _output_error(out_dir, exc) from None
    try:
        yield staging
        if out_dir.exists():
            retired = out_dir.parent / f".{out_dir.name}.{secrets.token_hex(6)}.old"
            os.replace(out_dir, retired)
            os.replace(staging, out_dir)
            shutil.rmtree(retired)
        else:
            os.replace(staging, out_dir)
    except OSError as exc:
        raise _output_error(out_dir, exc) from None
    finally:
        if staging.exists():
            shutil.rmtree(staging, ignore_errors=True)


def _output_error(out: Path, exc: OSError) -> OutputError:
    where = exc.filename if exc.filename else out
    return OutputError(
        f"{out}: cannot write it ({exc.strerror or exc} at {where}); check the path, the free "
        "space and the permissions, or give another --out"
    )


def _new_directory(parent: Path, prefix: str, suffix: str) -> Path:
    """An empty directory of a fresh name, with the umask's mode (``mkdtemp`` makes 0700)."""
    while True:
        candidate = parent / f"{prefix}{secrets.token_hex(6)}{suffix}"
        try:
            os.mkdir(candidate, 0o777)
        except FileExistsError:
            continue
        return candidate


@contextmanager
def atomic_open(target: Path, mode: str = "w", **kwargs: Any) -> Iterator[IO[Any]]:
    with atomic_path(target) as tmp, open(tmp, mode, **kwargs) as handle:
        yield handle


def write_text(target: Path, text: str) -> None:
    with atomic_open(target, "w", encoding="utf-8") as handle:
        handle.write(text)


def write_json(target: Path, payload: Any) -> None:
    write_text(target, json.dumps(payload, indent=2, sort_keys=False, default=str) + "\n")


def write_csv(target: Path, frame: pd.DataFrame, **kwargs: Any) -> None:
    with atomic_path(target) as tmp:
        frame.to_csv(tmp, index=False, **kwargs)


def save_figure(target: Path, figure: Any, **kwargs: Any) -> None:
    """Save a matplotlib figure atomically (format from the target's suffix)."""
    with atomic_path(target) as tmp:
        figure.savefig(tmp, format=target.suffix.lstrip(".") or "png", **kwargs)
