"""Running the console script: fewer garbage collections, and leaving the process once a
command is done without tearing the interpreter down.

A normal exit finalises the interpreter: it frees every object of pandas, matplotlib and
pyarrow one by one, which takes 0.15-0.2 s after every run, once all the work is done. The
console script therefore flushes the standard streams and leaves with ``os._exit``, as mypy
does by default (``mypy.util.hard_exit``). Nothing is lost: every command closes the files it
writes (atomically) and joins its threads before it returns.
"""

from __future__ import annotations

import gc
import os
import signal
import sys
from collections.abc import Callable
from typing import NoReturn

# What CPython exits with when it cannot flush stdout at exit (e.g. a closed pipe).
_UNFLUSHED_STATUS = 120
# Allocations between two collections of the youngest generation (CPython's default: 700).
# A command imports pandas, matplotlib and pyarrow: about a million objects that live until
# the end, which the collector would walk again and again (0.12 s of the 0.96 s those
# imports take; 0.08 s less with this threshold). Cycles are still collected, less often.
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


def fewer_collections() -> None:
    """Collect the youngest generation every ``GC_YOUNG_THRESHOLD`` allocations: in the
    console script, and in the Dask workers of a replay, which hold the same objects."""
    _, older, oldest = gc.get_threshold()
    gc.set_threshold(GC_YOUNG_THRESHOLD, older, oldest)


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
    fewer_collections()
    try:
        main()
        status = 0
    except SystemExit as exit_:
        status = exit_status(exit_)
    if _terminated:
        status = TERMINATED_STATUS
    os._exit(flush_streams(status))
