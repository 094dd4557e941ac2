"""Atomic output: write to a temporary file beside the target, then rename over it.

A crash leaves either the old file or the new one, never a half-written report. A report
directory is staged whole beside its ``--out`` and swapped in (``report_directory``); its
run.json lists the files colregs9 wrote (``FILES_KEY``), so that a rerun replaces those and
keeps, or refuses to touch, anything else (``check_out_dir``).
"""

from __future__ import annotations

import json
import os
import secrets
import shutil
import stat
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from fnmatch import fnmatchcase
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
    file, an existing path that is not a regular file (a directory, a FIFO, a device: the
    output would replace it by a regular file), or a file of a colregs9 report (its run.json
    lists it: a rerun of the report would replace it). Another existing regular file is
    replaced."""
    _check_file_target(target)
    owner = _report_holding(target)
    if owner is not None:
        directory, command = owner
        raise OutputError(
            f"{target}: --out is a file of the colregs9 {command} report in {directory}, "
            "which a rerun of that report replaces; give another --out"
        )


def _check_file_target(target: Path) -> None:
    """``check_out_file`` but for the reports' files, which ``atomic_path`` writes too."""
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
    _check_file_target(target)
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
# run.json's list of the files colregs9 wrote into the report: paths relative to it, "/"
# between the parts, run.json included. A rerun replaces these and no other file.
FILES_KEY = "files"
# The manifest of a dataset of ``colregs9 ingest`` (``ais.dataset_scan.MANIFEST_NAME``, which
# the base cannot import): a report never goes into a dataset.
DATASET_MARKER = "colregs9-dataset.json"
# The files a report of each command wrote before run.json listed them (colregs9 0.1.0 up to
# issue 30): a run.json without the list owns the files of its command's report, and no other.
LEGACY_REPORT_FILES: dict[str, tuple[str, ...]] = {
    "replay": (
        "run.json",
        "pairs.csv",
        "encounters.csv",
        "index.md",
        "index.html",
        "report.gpkg",
        "encounters/*.csv",
        "encounters/*.png",
    ),
    "stats": (
        "run.json",
        "dimension_stats.csv",
        "dimension_stats.md",
        "dimension_histograms.png",
        "index.html",
    ),
    "swing": ("run.json", "rate_of_swing.csv", "rate_of_swing.png"),
    # and, in a directory per scenario, the replay report that its own run.json marks
    "demo": ("run.json", "simulate-*.csv", "*.png"),
}
# Files a reader makes beside a file it opens (SQLite's, when QGIS opens report.gpkg; GDAL's
# for a PNG): they go with the file, and a rerun replaces them with it.
SIDECAR_SUFFIXES = ("-wal", "-shm", "-journal", ".aux.xml")
# What file managers and office suites leave in a directory they show or a file they open
# (LibreOffice's lock of an open CSV): no reason to refuse a rerun; kept as the user's files.
LITTER = (".DS_Store", "Thumbs.db", "desktop.ini", ".~lock.*#")
# How many of the files that are not colregs9's an error names (then: "and N more").
NAMED_FILES = 3


def report_manifest(directory: Path) -> dict[str, Any] | None:
    """The run.json of the colregs9 report in ``directory``; None where there is none."""
    marker = directory / REPORT_MARKER
    if not marker.is_file():  # a pipe of that name would block the read
        return None
    try:
        manifest = json.loads(marker.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):  # RecursionError: JSON nested thousands deep
        return None
    if isinstance(manifest, dict) and manifest.get("tool") == "colregs9":
        return manifest
    return None


def is_report(directory: Path) -> bool:
    """True for a directory holding a colregs9 report (its run.json says so)."""
    return report_manifest(directory) is not None


def report_files(directory: Path, manifest: Mapping[str, Any]) -> frozenset[str]:
    """The files of the report in ``directory`` that colregs9 wrote (relative, "/"-joined):
    those its run.json lists; for a run.json from before the list, the files that match its
    command's report (``LEGACY_REPORT_FILES``). A report in one of its directories (each
    scenario's replay in the demo's) adds its own."""
    listed = manifest.get(FILES_KEY)
    if isinstance(listed, list):
        files = {name for name in listed if isinstance(name, str)}
    else:
        command = str(manifest.get("command"))
        patterns = LEGACY_REPORT_FILES.get(command, (REPORT_MARKER,))
        if command == "demo":
            patterns = (*patterns, f"*/{REPORT_MARKER}")
        files = {
            found.relative_to(directory).as_posix()
            for pattern in patterns
            for found in directory.glob(pattern)
            if found.is_file()
        }
    for nested in sorted(name for name in files if name.endswith(f"/{REPORT_MARKER}")):
        sub = nested.removesuffix(f"/{REPORT_MARKER}")
        inner = report_manifest(directory / sub)
        if inner is not None:
            files.update(f"{sub}/{name}" for name in report_files(directory / sub, inner))
    return frozenset(files)


def _parents(relative: str) -> list[str]:
    """The directories a relative "/"-joined path lies in: "a/b/c" -> ["a", "a/b"]."""
    parts = relative.split("/")
    return ["/".join(parts[:k]) for k in range(1, len(parts))]


def _is_sidecar(relative: str, owned: frozenset[str]) -> bool:
    return any(
        relative.endswith(suffix) and relative.removesuffix(suffix) in owned
        for suffix in SIDECAR_SUFFIXES
    )


def _is_litter(relative: str) -> bool:
    name = relative.rsplit("/", 1)[-1]
    return any(fnmatchcase(name, pattern) for pattern in LITTER)


def not_owned(directory: Path, owned: frozenset[str]) -> list[tuple[str, bool]]:
    """What ``directory`` holds besides the ``owned`` files and their sidecars: each entry
    (file, link, directory) as high up as it lies wholly outside them, as its relative path
    and whether it is a directory, in name order."""
    owned_dirs = {parent for name in owned for parent in _parents(name)}
    found: list[tuple[str, bool]] = []
    pending = [""]
    while pending:
        under = pending.pop()
        with os.scandir(directory / under) as scan:
            entries = [(entry.name, entry.is_dir(follow_symlinks=False)) for entry in scan]
        for name, is_dir in entries:
            relative = f"{under}/{name}" if under else name
            if is_dir and relative in owned_dirs:
                pending.append(relative)
            elif is_dir or not (relative in owned or _is_sidecar(relative, owned)):
                found.append((relative, is_dir))
    return sorted(found)


def _named(entries: Sequence[tuple[str, bool]]) -> str:
    """The first few entries by name (a directory with a trailing "/"), and how many more."""
    names = [f"{path}/" if is_dir else path for path, is_dir in entries[:NAMED_FILES]]
    more = len(entries) - NAMED_FILES
    return ", ".join(names) + (f" and {more} more" if more > 0 else "")


def _report_holding(target: Path) -> tuple[Path, str] | None:
    """The directory and command of the colregs9 report that ``target`` is a file of."""
    target = target.absolute()
    for directory in target.parents:
        if not (directory / REPORT_MARKER).is_file():
            continue
        manifest = report_manifest(directory)
        relative = target.relative_to(directory).as_posix()
        if manifest is not None and relative in report_files(directory, manifest):
            return directory, str(manifest.get("command"))
    return None


def check_out_dir(
    out_dir: Path, overwrite: bool = False, inputs: Sequence[Path] = (), *, command: str
) -> None:
    """Refuse, before any work, an ``--out`` that cannot take a report of ``command``: a file,
    a directory under a file, one without write access, the current, a parent or the home
    directory (the report replaces its directory), one that is or holds one of the run's
    ``inputs``, or a dataset of ``colregs9 ingest`` or a directory inside one (all these even
    with ``overwrite``); and,
    unless ``overwrite``, a colregs9 report of another command, or a directory that holds
    files colregs9 did not write there (those its run.json does not list; all of them where
    there is no run.json), naming the first few. With ``overwrite`` the report replaces the
    colregs9 files there and leaves the others (``report_directory``)."""
    _check_reachable(out_dir)
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
    # realpath, unlike Path.resolve, leaves a symbolic link that loops as it is (and raises
    # nothing): such an input is neither --out nor above it, and its reader names it.
    resolved = Path(os.path.realpath(out_dir))
    if resolved in (Path.cwd().resolve(), *Path.cwd().resolve().parents, Path.home().resolve()):
        raise OutputError(
            f"{out_dir}: --out would replace the current, a parent or the home directory; "
            "give a directory of its own for the report"
        )
    for given in inputs:
        input_path = Path(os.path.realpath(given))
        if resolved == input_path or resolved in input_path.parents:
            raise OutputError(
                f"{out_dir}: --out is or holds the input {given}, which the report would "
                "replace; give another directory for the report"
            )
    for above in resolved.parents:
        if (above / DATASET_MARKER).exists():
            raise OutputError(
                f"{out_dir}: --out lies inside {above}, a dataset of colregs9 ingest, which "
                "holds its own files only; give a directory outside it for the report"
            )
    if out_dir.is_dir():
        _check_what_is_there(out_dir, overwrite, command)


def _check_reachable(out_dir: Path) -> None:
    """Refuse an ``--out`` that no path reaches: through a symbolic link that loops, or a
    name too long. A missing one, or one under a file, is for ``check_out_dir`` to say."""
    try:
        out_dir.stat()
    except (FileNotFoundError, NotADirectoryError):
        return
    except OSError as exc:
        raise OutputError(
            f"{out_dir}: --out cannot be reached ({exc.strerror}); check the path and its "
            "symbolic links, or give another directory"
        ) from None


def _check_what_is_there(out_dir: Path, overwrite: bool, command: str) -> None:
    """``check_out_dir`` for an existing directory: what it holds."""
    if (out_dir / DATASET_MARKER).exists():
        raise OutputError(
            f"{out_dir}: --out is a dataset of colregs9 ingest, which a report does not go "
            "into, even with --overwrite; give another directory for the report"
        )
    manifest = report_manifest(out_dir)
    try:
        others = not_owned(out_dir, report_files(out_dir, manifest) if manifest else frozenset())
    except OSError as exc:
        raise OutputError(
            f"{out_dir}: cannot read what --out holds ({exc.strerror or exc}); give a "
            "directory you can read"
        ) from None
    if overwrite:
        return
    there = None if manifest is None else str(manifest.get("command"))
    if there is not None and there != command:
        raise OutputError(
            f"{out_dir}: --out holds a colregs9 {there} report, which a {command} report would "
            f"replace; give another --out, or add --overwrite to replace the {there} report's "
            "files"
        )
    theirs = [entry for entry in others if entry[1] or not _is_litter(entry[0])]
    if theirs and there is None:
        raise OutputError(
            f"{out_dir}: --out is not a colregs9 report and holds {len(theirs)} item(s): "
            f"{_named(theirs)}; give a new or empty directory, or add --overwrite to write the "
            "report beside them (they are kept)"
        )
    if theirs:
        raise OutputError(
            f"{out_dir}: --out holds {len(theirs)} item(s) that colregs9 did not write there: "
            f"{_named(theirs)}; move them out, give another --out, or add --overwrite to "
            "replace only the report's files (they are kept)"
        )


@contextmanager
def report_directory(out_dir: Path, overwrite: bool = False) -> Iterator[Path]:
    """Yield an empty staging directory beside ``out_dir``; on success run.json there gets
    the list of the files written (``FILES_KEY``), and the staging directory replaces
    ``out_dir``, so that a report is never a mix of two runs (no stale file of an earlier run
    remains). What ``out_dir`` holds besides colregs9's files (``report_files``: the user's
    notes, a QGIS project) is moved into the new report first, where it was. One of them
    with the name of a file of the new report (put there during the run, or allowed by
    ``overwrite``) is replaced by it with ``overwrite``, else refused (``OutputError``). On
    failure ``out_dir`` is left as it was, and an ``OSError`` becomes one ``OutputError``."""
    try:
        out_dir.parent.mkdir(parents=True, exist_ok=True)
        staging = _new_directory(out_dir.parent, f".{out_dir.name}.", ".new")
    except OSError as exc:
        raise _output_error(out_dir, exc) from None
    kept_in_staging: list[str] = []
    try:
        yield staging
        _list_files(staging)
        _put_in_place(staging, out_dir, overwrite, kept_in_staging)
    except OSError as exc:
        raise _output_error(out_dir, exc) from None
    finally:
        if staging.exists() and not kept_in_staging:
            shutil.rmtree(staging, ignore_errors=True)


def _list_files(staging: Path) -> None:
    """Add to the staged run.json the list of every file of the report (``FILES_KEY``)."""
    marker = staging / REPORT_MARKER
    if not marker.is_file():
        return
    manifest = json.loads(marker.read_text(encoding="utf-8"))
    files = sorted(
        (Path(root) / name).relative_to(staging).as_posix()
        for root, _, names in os.walk(staging)
        for name in names
    )
    write_json(marker, {**manifest, FILES_KEY: files})


def _put_in_place(
    staging: Path, out_dir: Path, overwrite: bool, kept_in_staging: list[str]
) -> None:
    """Swap ``staging`` in for ``out_dir``, with what ``out_dir`` holds that colregs9 did not
    write moved into it first. ``kept_in_staging`` receives what could not be moved back
    after a failure (the staging directory is then left, and the error names it)."""
    if not os.path.lexists(out_dir):
        os.replace(staging, out_dir)
        return
    manifest = report_manifest(out_dir)
    others = not_owned(out_dir, report_files(out_dir, manifest) if manifest else frozenset())
    moves, clashes = _carry_plan(out_dir, staging, others)
    if clashes and not overwrite:
        raise OutputError(
            f"{out_dir}: holds {len(clashes)} item(s) that colregs9 did not write there, with "
            f"the names of files of the new report: {_named(clashes)}; move them out and run "
            "again, or add --overwrite to replace them"
        )
    moved: list[str] = []
    retired = out_dir.parent / f".{out_dir.name}.{secrets.token_hex(6)}.old"
    try:
        for relative in moves:
            (staging / relative).parent.mkdir(parents=True, exist_ok=True)
            os.replace(out_dir / relative, staging / relative)
            moved.append(relative)
        os.replace(out_dir, retired)
        try:
            os.replace(staging, out_dir)
        except BaseException:
            os.replace(retired, out_dir)
            raise
    except BaseException:
        _move_back(moved, staging, out_dir, kept_in_staging)
        raise
    shutil.rmtree(retired)


def _carry_plan(
    out_dir: Path, staging: Path, others: list[tuple[str, bool]]
) -> tuple[list[str], list[tuple[str, bool]]]:
    """Which entries of ``others`` move into ``staging`` as they are, and which clash with
    a file of the new report there (a directory that meets one of the report's is merged
    into it, entry by entry)."""
    moves: list[str] = []
    clashes: list[tuple[str, bool]] = []
    pending = list(others)
    while pending:
        relative, is_dir = pending.pop(0)
        target = staging / relative
        blocked = any(
            os.path.lexists(staging / parent) and not _real_dir(staging / parent)
            for parent in _parents(relative)
        )
        if not blocked and not os.path.lexists(target):
            moves.append(relative)
        elif not blocked and is_dir and _real_dir(target):
            with os.scandir(out_dir / relative) as scan:
                pending.extend(
                    (f"{relative}/{entry.name}", entry.is_dir(follow_symlinks=False))
                    for entry in scan
                )
        else:
            clashes.append((relative, is_dir))
    return moves, sorted(clashes)


def _real_dir(path: Path) -> bool:
    return path.is_dir() and not path.is_symlink()


def _move_back(moved: list[str], staging: Path, out_dir: Path, stuck: list[str]) -> None:
    """Return the entries ``moved`` into ``staging`` to ``out_dir``; those that cannot go
    back are added to ``stuck`` and named in an ``OutputError``."""
    for relative in reversed(moved):
        try:
            os.replace(staging / relative, out_dir / relative)
        except OSError:
            stuck.append(relative)
    if stuck:
        raise OutputError(
            f"{out_dir}: the report could not be put in place, and {len(stuck)} item(s) of "
            f"yours could not be moved back from {staging}: {_named([(s, False) for s in stuck])}"
            "; move them back by hand"
        )


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
