"""Running the console script: fewer garbage collections, and leaving the process once a
command is done without tearing the interpreter down.

A normal exit finalises the interpreter: it frees every object of pandas, matplotlib and
pyarrow one by one, a noticeable wait after every run, once all the work is done. The console
script therefore flushes the standard streams and leaves with ``os._exit``, as mypy does by
default (``mypy.util.hard_exit``). Nothing is lost: every command closes the files it writes
(atomically) and joins its threads before it returns.

Only the console script's ``cli.run`` calls ``run_and_exit``: the Typer app, the library
(``colregs9_cli.api``) and the jobs leave the process's exit, signal handlers and collector
as they find them. ``fewer_collections`` changes the collector only within its block.
"""

from __future__ import annotations

import gc
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import NoReturn

# What CPython exits with when it cannot flush stdout at exit (e.g. a closed pipe).
_UNFLUSHED_STATUS = 120
# Allocations between two collections of the youngest generation (CPython's default: 700).
# A command imports pandas, matplotlib and pyarrow: about a million objects that live until
# the end, which the collector would walk again and again, a sizeable share of the imports'
# time (figures: tests/benchmarks/README.md). Cycles are still collected, less often.
GC_YOUNG_THRESHOLD = 50_000


def exit_status(exit_: SystemExit) -> int:
    """The status ``sys.exit`` would give; a message is printed to stderr, as it would be."""
    code = exit_.code
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    print(code, file=sys.stderr)
    return 1


def flush_streams(status: int) -> int:
    """Flush stdout and stderr; ``status``, or 120 if it was 0 and a stream would not flush."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            status = status or _UNFLUSHED_STATUS
    return status


# The thresholds are the process's: blocks that overlap (tasks on the threads of one Dask
# worker) share one change, made by the first to enter and undone by the last to leave,
# whatever order they leave in. One entry per open block: the thresholds before the first.
_blocks_lock = threading.Lock()
_open_blocks: list[tuple[int, int, int]] = []


@contextmanager
def fewer_collections() -> Iterator[None]:
    """Within the block, collect the youngest generation every ``GC_YOUNG_THRESHOLD``
    allocations; on leaving it, the collector's thresholds are again what they were. Used by
    the console script around its command, and by the Dask workers of a replay around each
    task, which hold the same objects."""
    with _blocks_lock:
        if _open_blocks:
            before = _open_blocks[0]
        else:
            before = gc.get_threshold()
            _, older, oldest = before
            gc.set_threshold(GC_YOUNG_THRESHOLD, older, oldest)
        _open_blocks.append(before)
    try:
        yield
    finally:
        with _blocks_lock:
            _open_blocks.pop()
            if not _open_blocks:
                gc.set_threshold(*before)


# The status of a command stopped by SIGTERM: 128 + 15, as a shell reports it.
TERMINATED_STATUS = 143
_terminated: list[int] = []


def _interrupt(signum: int, frame: object) -> None:
    _terminated.append(signum)
    raise KeyboardInterrupt


def run_and_exit(main: Callable[[], object]) -> NoReturn:
    """Run ``main`` (a Click or Typer app, which ends with ``SystemExit``), then leave at once
    with its status. Any other exception propagates, with its traceback, as usual.

    SIGTERM (what ``timeout``, batch schedulers and systemd send) stops a command as Ctrl-C
    does, so that it removes its staging and scratch directories on the way out, and it
    leaves with status 143."""
    signal.signal(signal.SIGTERM, _interrupt)
    try:
        with fewer_collections():
            main()
        status = 0
    except SystemExit as exit_:
        status = exit_status(exit_)
    if _terminated:
        status = TERMINATED_STATUS
    os._exit(flush_streams(status))
