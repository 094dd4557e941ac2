"""Stage 2 of the replay (``slabs.replay_slab``) on dask.distributed (docs/design.md §6).

A ``LocalCluster`` of ``workers`` processes (one thread each: the work is NumPy and pandas
under the GIL) by default, or the cluster whose scheduler is at ``scheduler``. The slabs'
shared context and the chart are sent to the workers once; each slab is one task, and the
results are put back in slab order, so that they do not depend on the number of workers.
The slabs' results stay on the workers until the reports are written: each slab's series
CSVs and map layers are made where its result is (``EncountersOnCluster``), and the figures
are drawn there too.

On a cluster of several machines every worker must read the run's scratch directory (the
spilled reports): give ``--scratch`` on a file system they all mount.

A local cluster leaves no file behind (``cluster_scratch``): its workers' directories and
Dask's lock files, and the socket of multiprocessing's forkserver, go into temporary
directories that are removed when it closes; the console script's quick exit
(``quick_exit``) would skip multiprocessing's own removal of its ``pymp-*`` directory.
"""

from __future__ import annotations

import ctypes
import logging
import multiprocessing
import os
import shutil
import tempfile
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from contextlib import ExitStack, closing, contextmanager
from dataclasses import dataclass, field
from functools import partial
from multiprocessing import forkserver
from pathlib import Path
from typing import Any, TypeVar

import dask
import pyarrow as pa
from distributed import Client, Future, LocalCluster, Worker, WorkerPlugin, as_completed

from ..charts.water import Chart
from ..core.replay_results import EncounterOutcome, seats_in_order
from ..errors import ParameterError
from ..geo import LocalFrame
from ..progress import ProgressSink
from ..quick_exit import fewer_collections
from ..report.replay_report import Drawer, draw_encounter
from .slabs import PairEvaluator, SlabContext, SlabResult, replay_slab, slab_label

Part = TypeVar("Part")
# How long to wait for a scheduler given with --scheduler before giving up.
_CONNECT_TIMEOUT_S = 10
# After a failure, how long to wait for the tasks running on the workers to end (a figure or
# a slab's series take seconds), before the report's staging directory is removed.
_SETTLE_TIMEOUT_S = 60
_SETTLE_POLL_S = 0.05
# The local clusters open in this process, and the directory that this module gave
# multiprocessing for its temporary files (the forkserver's socket) while they run.
_clusters_lock = threading.Lock()
_clusters_open = 0
_multiprocessing_dir: Path | None = None


@contextmanager
def cluster_scratch(parent: Path | None) -> Iterator[Path]:
    """A new directory in ``parent`` (default: the system's temporary directory) for a local
    cluster's files (its workers' directories, Dask's lock files, the workers' ``TMPDIR``),
    removed with all it holds on leaving, once the cluster has closed. Multiprocessing's
    temporary directory of this process, where the forkserver that starts the workers has
    its socket, is one of colregs9's too while clusters are open (``_enter_cluster``)."""
    try:
        local_dir = Path(tempfile.mkdtemp(prefix="colregs9-dask-", dir=parent))
    except OSError as exc:
        where = f"--scratch {parent}" if parent is not None else "the temporary directory"
        raise ParameterError(
            f"{where}: cannot make the Dask workers' directory there ({exc.strerror}); give a "
            "writable directory with --scratch"
        ) from None
    try:
        _enter_cluster()
        try:
            yield local_dir
        finally:
            _leave_cluster()
    finally:
        shutil.rmtree(local_dir, ignore_errors=True)


def _forkserver() -> Any:
    # multiprocessing's own forkserver of this process (private: Python has no public API).
    return getattr(forkserver, "_forkserver", None)


def _enter_cluster() -> None:
    """Before the first of this process's open local clusters, if multiprocessing has made
    no temporary directory yet and runs no forkserver: give it a directory of colregs9's
    (``colregs9-mp-*`` in the system's temporary directory: the socket's path must stay
    short), which ``_leave_cluster`` removes."""
    global _clusters_open, _multiprocessing_dir
    with _clusters_lock:
        config: dict[str, Any] = getattr(multiprocessing.current_process(), "_config", {})
        server = _forkserver()
        idle = server is None or getattr(server, "_forkserver_pid", None) is None
        if _clusters_open == 0 and config.get("tempdir") is None and idle:
            _multiprocessing_dir = Path(tempfile.mkdtemp(prefix="colregs9-mp-"))
            config["tempdir"] = str(_multiprocessing_dir)
        _clusters_open += 1


def _leave_cluster() -> None:
    """After the last open local cluster: stop the forkserver started for the clusters (its
    socket is in the directory ``_enter_cluster`` gave; this process's next cluster starts
    another), give multiprocessing back its own temporary directory, and remove colregs9's."""
    global _clusters_open, _multiprocessing_dir
    with _clusters_lock:
        _clusters_open -= 1
        if _clusters_open or _multiprocessing_dir is None:
            return
        ours, _multiprocessing_dir = _multiprocessing_dir, None
        stop = getattr(_forkserver(), "_stop", None)
        if stop is not None:
            stop()
        config: dict[str, Any] = getattr(multiprocessing.current_process(), "_config", {})
        if config.get("tempdir") == str(ours):
            config["tempdir"] = None
        shutil.rmtree(ours, ignore_errors=True)


@contextmanager
def dask_client(
    workers: int, scheduler: str | None, scratch_dir: Path | None = None
) -> Iterator[Client]:
    """A client of the cluster at ``scheduler``, else of a new local cluster, whose temporary
    files go into ``scratch_dir`` (default: the system's temporary directory) and are
    removed when it closes (``cluster_scratch``)."""
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout=_CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError) as exc:
            raise ParameterError(
                f"--scheduler {scheduler}: cannot reach a Dask scheduler there ({exc}); start "
                "one (dask scheduler) or leave out --scheduler to use a local cluster"
            ) from None
        with client:
            # Started apart (``dask worker``), the workers have Dask's defaults: the
            # settings of a local cluster (below) are applied in each, now and on joining.
            client.register_plugin(WorkerSettings())
            yield client
        return
    # Dask's nannies set MALLOC_TRIM_THRESHOLD_=65536 in their workers, so that freed memory
    # goes back to the system at once; a slab's large arrays, allocated and freed again and
    # again, then make every task much slower (figures: tests/benchmarks/README.md). A
    # slab's memory is bounded anyway: keep glibc's own threshold. A worker's event loop
    # shares the GIL with its task: Dask's profiler samples the task's stack every 10 ms
    # (for a dashboard this cluster has not), and the loop wakes every 20 ms to time itself
    # and every 100 ms to measure the memory. A slab runs for seconds: check once a second.
    # The workers are forked from a server that imported NumPy, pandas and the like once,
    # rather than each importing them anew while the input is read beside them.
    settings: dict[str, object] = {
        "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
        "distributed.worker.profile.enabled": False,
        "distributed.admin.tick.interval": "1s",
        "distributed.worker.memory.monitor-interval": "1s",
    }
    if "forkserver" in multiprocessing.get_all_start_methods():
        settings["distributed.worker.multiprocessing-method"] = "forkserver"
    with cluster_scratch(scratch_dir) as local_dir:
        settings["temporary-directory"] = str(local_dir)
        with dask.config.set(settings):
            cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                # The scheduler's HTTP server starts even without a dashboard, on 8787 unless
                # told otherwise, and warns on stderr when another cluster holds that port.
                scheduler_kwargs={"dashboard_address": ":0"},
                # Dask's own log lines are not the tool's: a worker that misses a heartbeat
                # while the cluster closes logs an ERROR with a traceback. A task's failure
                # reaches the run as an exception, said in one line.
                silence_logs=logging.CRITICAL,
                local_directory=str(local_dir),
                # What the workers' own temporary files would leave, in the same place.
                env={"TMPDIR": str(local_dir)},
            )
        with _local_cluster(cluster) as client:
            yield client


@contextmanager
def _local_cluster(cluster: LocalCluster) -> Iterator[Client]:
    """A client of the local ``cluster``, both closed on leaving."""
    # Not made the default client: that is a context variable of the thread that starts it
    # (``dask_client_soon``), and the run's own thread uses and closes it.
    with closing(cluster), closing(Client(cluster, set_as_default=False)) as client:
        # The workers import the replay (pandas, shapely, matplotlib: slow imports) now,
        # while this process reads the input, not when the first slab arrives.
        client.run(_ready, wait=False)
        yield client


async def _ready() -> None:
    """Unpickling it on a worker imports this module and so the whole replay (a coroutine,
    as Dask runs only those without waiting). A worker is one of the cluster's processes
    sharing the machine: Arrow's thread pool of one thread per core would oversubscribe it."""
    pa.set_cpu_count(1)


# glibc's ``mallopt`` parameters, and the ceiling its dynamic thresholds reach on 64 bits.
_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
_GLIBC_MMAP_THRESHOLD_MAX = 32 * 2**20
# What Dask's nannies set MALLOC_TRIM_THRESHOLD_ to in their workers.
_DASK_TRIM_THRESHOLD = "65536"


class WorkerSettings(WorkerPlugin):
    """The local cluster's settings (``dask_client``) in a worker started apart, with Dask's
    defaults (``dask worker``): the profiler off, the event loop's tick and the memory
    monitor once a second, Arrow's threads the worker's own, and glibc's thresholds back to
    their ceiling where Dask's nanny set ``MALLOC_TRIM_THRESHOLD_`` (glibc read it at the
    process's start; it also stops the thresholds moving, so every array over 128 KiB
    was mapped and unmapped again: a slab ran 1.7× slower)."""

    name = "colregs9-worker-settings"

    def setup(self, worker: Worker) -> None:
        for name in ("profile", "profile-cycle"):
            callback = worker.periodic_callbacks.pop(name, None)
            if callback is not None:
                callback.stop()
        for name in ("tick", "memory_monitor"):
            callback = worker.periodic_callbacks.get(name)
            if callback is not None:
                callback.callback_time = max(callback.callback_time, 1000.0)
        pa.set_cpu_count(max(1, worker.state.nthreads))
        if os.environ.get("MALLOC_TRIM_THRESHOLD_") == _DASK_TRIM_THRESHOLD:
            try:
                libc = ctypes.CDLL("libc.so.6")
            except OSError:  # not glibc: the variable meant nothing
                return
            libc.mallopt(_M_MMAP_THRESHOLD, _GLIBC_MMAP_THRESHOLD_MAX)
            libc.mallopt(_M_TRIM_THRESHOLD, 2 * _GLIBC_MMAP_THRESHOLD_MAX)


def _seldom_collected(function: Callable[..., Part], /, *args: Any, **kwargs: Any) -> Part:
    """``function(*args, **kwargs)``, as a task on a worker, collecting garbage as seldom as
    the console script does (``quick_exit.fewer_collections``), and the worker's collector as
    it was once the task is done. A task holds the same many long-lived objects as a command
    (pandas, shapely, matplotlib), which the collector would walk again and again: fewer
    collections make a slab a little faster (figures: tests/benchmarks/README.md)."""
    with fewer_collections():
        return function(*args, **kwargs)


@contextmanager
def dask_client_soon(
    workers: int, scheduler: str | None, scratch_dir: Path | None = None
) -> Iterator[Callable[[], Client]]:
    """``dask_client``, started while the caller goes on: yields a function that waits for
    the client. A scheduler given by address is reached at once, so that an unreachable one
    stops the run before any work; a local cluster starts on a thread (importing Dask and
    spawning the workers take a few seconds, mostly waiting)."""
    if scheduler is not None:
        with dask_client(workers, scheduler) as client:
            yield lambda: client
        return
    with ExitStack() as stack, ThreadPoolExecutor(max_workers=1) as pool:
        # Leaving waits for the start, then closes the cluster, even after an error.
        yield pool.submit(stack.enter_context, dask_client(workers, None, scratch_dir)).result


def dask_slabs(
    client: Client,
    slabs: Sequence[int],
    context: SlabContext,
    evaluate: PairEvaluator,
    chart: Chart | None,
    bar: ProgressSink,
) -> tuple[list[SlabResult], EncountersOnCluster]:
    """``slabs.replay_slab`` for every slab on the cluster of ``client``, in slab order;
    and the slabs' results left on the workers, for the reports."""
    # hash=False: a chart of None (or the same context) scattered twice in a run would share
    # one key, and the release of the first would race the second ("lost dependencies").
    shared = client.scatter([context, chart], broadcast=True, hash=False)
    futures = client.map(
        partial(_seldom_collected, replay_slab),
        list(slabs),
        job=shared[0],
        evaluate=evaluate,
        chart=shared[1],
        pure=False,
    )
    done: list[tuple[SlabResult, Future]] = []
    for future in as_completed(futures, loop=client.loop):
        done.append((future.result(), future))
        bar.advance()
        bar.describe("done: " + slab_label(done[-1][0].slab, context.params.slab_s))
    done.sort(key=lambda item: item[0].slab)
    kept = tuple(future for result, future in done if result.pairs)
    return [result for result, _ in done], EncountersOnCluster(client, kept)


@dataclass(frozen=True)
class EncountersOnCluster:
    """``replay_report.EncounterParts``: each slab's encounters on the worker that holds the
    slab's result (``slabs``: the futures of the slabs with pairs, in slab order), so that
    their series CSVs and map layers are made there and need not travel."""

    client: Client
    slabs: tuple[Future, ...]
    submitted: list[Future] = field(default_factory=list, compare=False)

    def map(
        self, function: Callable[[tuple[EncounterOutcome, ...]], Part]
    ) -> list[Callable[[], Part]]:
        futures = [
            self.client.submit(_seldom_collected, _on_seats, function, slab, pure=False)
            for slab in self.slabs
        ]
        self.submitted.extend(futures)
        return [future.result for future in futures]

    def settle(self) -> None:
        """Drop the parts' tasks not begun, and wait for those running (``settle_tasks``)."""
        settle_tasks(self.client, self.submitted)


# A task in one of these states on a worker runs no more: done, failed or let go.
_SETTLED_STATES = frozenset({"memory", "error", "released", "forgotten"})


def settle_tasks(client: Client, futures: Sequence[Future]) -> None:
    """Cancel ``futures`` and return once no worker runs or holds one of them any more (or
    after ``_SETTLE_TIMEOUT_S``): a running task cannot be stopped, and one a worker holds
    ready would start before the cancellation reaches it. Used after a failure, before the
    report's staging directory, which the tasks write into, is removed."""
    keys = {future.key for future in futures}
    try:
        client.cancel(list(futures))
        deadline_s = time.monotonic() + _SETTLE_TIMEOUT_S
        while time.monotonic() < deadline_s:
            held = client.run(_unsettled_keys)
            if not keys.intersection(key for found in held.values() for key in found):
                return
            time.sleep(_SETTLE_POLL_S)
    except Exception:  # a cluster that is gone or broken runs no task that writes
        return


def _unsettled_keys(dask_worker: Any) -> list[Any]:
    """On a worker (``Client.run``): the keys of its tasks that may still run."""
    return [
        task.key for task in dask_worker.state.tasks.values() if task.state not in _SETTLED_STATES
    ]


def _on_seats(function: Callable[[tuple[EncounterOutcome, ...]], Part], slab: SlabResult) -> Part:
    return function(seats_in_order(slab.pairs))


def dask_drawer(client: Client) -> Drawer:
    """A ``replay_report.Drawer`` that draws each figure as a task on the cluster (the
    workers write into the report's staging directory)."""

    def draw(
        jobs: Sequence[tuple[EncounterOutcome, Path]],
        chart: Chart | None,
        ukc_m: float,
        frame: LocalFrame,
        progress: ProgressSink,
    ) -> None:
        (shared,) = client.scatter([chart], broadcast=True, hash=False)
        # The encounters travel in the task graph (about 0.2 MB each), which distributed
        # would warn about on stderr from 10 MB; scattering them first lost them now and
        # then ("lost dependencies") on a two-worker LocalCluster.
        with dask.config.set({"distributed.admin.large-graph-warning-threshold": "16GiB"}):
            futures = client.map(
                partial(_seldom_collected, draw_encounter),
                [outcome for outcome, _ in jobs],
                [target for _, target in jobs],
                chart=shared,
                ukc_m=ukc_m,
                frame=frame,
                pure=False,
            )
        try:
            for future in as_completed(futures, loop=client.loop):
                future.result()
                progress.advance()
        except BaseException:
            settle_tasks(client, futures)  # none writes into the staging once it is gone
            raise

    return draw


def dask_segments(
    client: Client, parts: Sequence[Callable[[], Part]], bar: ProgressSink
) -> list[Part]:
    """Stage 1 on the cluster: each part of the vessels (``replay_input.segment_input_part``
    with its arguments bound) as one task, ``bar`` advanced as each ends; the results in the
    order of ``parts``, whatever the order they end in."""
    futures = [client.submit(_seldom_collected, part, pure=False) for part in parts]
    order = {future.key: index for index, future in enumerate(futures)}
    results: dict[int, Part] = {}
    for future in as_completed(futures, loop=client.loop):
        results[order[future.key]] = future.result()
        bar.advance()
    return [results[index] for index in range(len(futures))]
