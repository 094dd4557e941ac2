"""Where a replay's work runs: in this process, or on a Dask cluster (docs/design.md §6).

``run_replay`` asks one ``Executor`` for the three stages that can run elsewhere: stage 1
(segmenting each part of the vessels), stage 2 (each slab's pairs and verdicts) and the
figures of the report. ``LocalExecutor`` runs them here; ``DaskExecutor`` (``dask_run.py``)
on a local cluster or one given by its scheduler's address. The results never depend on
which, nor on the number of workers.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

from ..charts.water import Chart
from ..core.replay_results import ReplayResult
from ..progress import ProgressSink
from ..report.replay_geopackage import Domains
from ..report.replay_report import write_replay_reports
from .slabs import PairEvaluator, SlabContext, SlabResult, run_slabs

if TYPE_CHECKING:
    from distributed import Client

    from .dask_run import EncountersOnCluster

# One part of stage 1, its arguments bound but the progress bar (given where it runs here).
SegmentTask = Callable[..., Any]


class Executor(Protocol):
    """The stages of a replay that may run away from this process."""

    def parts(self) -> int:
        """How many parts of the vessels stage 1 should have (one per worker)."""
        ...

    def segment(self, tasks: Sequence[SegmentTask], bar: ProgressSink) -> list[Any]:
        """Stage 1: each task's result, in the order of ``tasks``."""
        ...

    def replay_slabs(
        self,
        slabs: Sequence[int],
        context: SlabContext,
        evaluate: PairEvaluator,
        chart: Chart | None,
        bar: ProgressSink,
    ) -> list[SlabResult]:
        """Stage 2: each slab's result, in slab order."""
        ...

    def write_reports(
        self,
        result: ReplayResult,
        chart: Chart | None,
        plots: bool,
        bar: ProgressSink,
        overwrite: bool = False,
        domains: Domains = Domains.RESTRICTED,
    ) -> tuple[Path, ...]:
        """The report files, written whole (``report.replay_report.write_replay_reports``)."""
        ...


class LocalExecutor:
    """Every stage in this process, one after the other."""

    def parts(self) -> int:
        return 1

    def segment(self, tasks: Sequence[SegmentTask], bar: ProgressSink) -> list[Any]:
        return [task(bar) for task in tasks]

    def replay_slabs(
        self,
        slabs: Sequence[int],
        context: SlabContext,
        evaluate: PairEvaluator,
        chart: Chart | None,
        bar: ProgressSink,
    ) -> list[SlabResult]:
        return run_slabs(slabs, context, evaluate, chart, bar)

    def write_reports(
        self,
        result: ReplayResult,
        chart: Chart | None,
        plots: bool,
        bar: ProgressSink,
        overwrite: bool = False,
        domains: Domains = Domains.RESTRICTED,
    ) -> tuple[Path, ...]:
        return write_replay_reports(result, chart, plots, bar, overwrite=overwrite, domains=domains)


class DaskExecutor:
    """Every stage on a Dask cluster (``client`` waits for it to have started); the slabs'
    results stay on the workers that made them, for the report's per-encounter files."""

    def __init__(self, client: Callable[[], Client]) -> None:
        self._client = client
        self._on_cluster: EncountersOnCluster | None = None

    def parts(self) -> int:
        return len(self._client().nthreads())

    def segment(self, tasks: Sequence[SegmentTask], bar: ProgressSink) -> list[Any]:
        if len(tasks) == 1:
            return [tasks[0](bar)]
        from .dask_run import dask_segments

        return dask_segments(self._client(), tasks, bar)

    def replay_slabs(
        self,
        slabs: Sequence[int],
        context: SlabContext,
        evaluate: PairEvaluator,
        chart: Chart | None,
        bar: ProgressSink,
    ) -> list[SlabResult]:
        from .dask_run import dask_slabs

        results, self._on_cluster = dask_slabs(self._client(), slabs, context, evaluate, chart, bar)
        return results

    def write_reports(
        self,
        result: ReplayResult,
        chart: Chart | None,
        plots: bool,
        bar: ProgressSink,
        overwrite: bool = False,
        domains: Domains = Domains.RESTRICTED,
    ) -> tuple[Path, ...]:
        from .dask_run import dask_drawer

        drawer = dask_drawer(self._client())
        return write_replay_reports(
            result, chart, plots, bar, drawer, self._on_cluster, overwrite, domains
        )


@contextmanager
def executor(
    workers: int, scheduler: str | None, scratch_dir: Path | None = None
) -> Iterator[Executor]:
    """This process for one worker and no scheduler; else a Dask cluster, started at once
    (so that an unreachable scheduler stops the run before any work; a local cluster starts
    beside the reading, with its temporary files in ``scratch_dir``, default the system's
    temporary directory, removed when it closes) and closed on leaving. Dask is imported
    only then: it takes a second."""
    if workers == 1 and scheduler is None:
        yield LocalExecutor()
        return
    from .dask_run import dask_client_soon

    with dask_client_soon(workers, scheduler, scratch_dir) as client:
        yield DaskExecutor(client)
