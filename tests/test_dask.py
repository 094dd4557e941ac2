"""``replay --workers`` and ``--scheduler`` on dask.distributed: the same results for any
number of workers, and clear errors."""

from __future__ import annotations

import functools
import math
import operator
import os
import pickle
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyogrio
import pytest
from distributed import Client, LocalCluster
from typer.testing import CliRunner

from colregs9_cli.cli import app
from colregs9_cli.jobs import dask_run
from colregs9_cli.jobs.ingest import ingest
from colregs9_cli.jobs.replay import REPLAY_COLUMNS, run_params
from colregs9_cli.jobs.replay_input import (
    ReadCounts,
    ReplayInput,
    open_replay_input,
    segment_input_part,
)
from colregs9_cli.progress import progress_bar
from colregs9_cli.query import everything_query

from fixture_files import NMEA


def _replay(out: Path, *options: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [
            *(sys.executable, "-m", "colregs9_cli", "replay", str(NMEA), "--quiet"),
            # Every ellipse, so that the layer is compared (no chart: none is "restricted").
            *("--out", str(out), "--slab-minutes", "1", "--domains", "all", *options),
            # Two own ships: four seats, a few figures drawn on the workers.
            *("--own-mmsi", "211356520", "--own-mmsi", "211558470"),
        ],
        capture_output=True,
        text=True,
        check=False,
    )


def _report_files(out: Path) -> dict[str, bytes]:
    return {
        str(path.relative_to(out)): path.read_bytes()
        for path in sorted(out.rglob("*"))
        if path.is_file() and path.name not in ("run.json", "report.gpkg")
    }


def _map_layers(path: Path) -> dict[str, tuple[list[str], list[bytes], list[list[object]]]]:
    """The GeoPackage's map layers: fields, geometries and values (the QGIS styles, stamped
    with the time they were written, left out)."""
    layers = {}
    for layer in pyogrio.list_layers(path)[:, 0]:
        meta, _, wkb, fields = pyogrio.raw.read(path, layer=layer, datetime_as_string=True)
        if wkb is not None:
            values = [[None if v != v else v for v in column.tolist()] for column in fields]
            layers[str(layer)] = (list(meta["fields"]), list(wkb), values)
    return layers


def test_two_workers_write_what_one_writes(tmp_path: Path) -> None:
    """A LocalCluster of two processes, figures included: the same files, byte for byte
    (the GeoPackage feature for feature: its series and map layers are made on the workers),
    the encounters in the same order, and nothing on stderr."""
    one = _replay(tmp_path / "one")
    two = _replay(tmp_path / "two", "--workers", "2")
    assert one.returncode == 0, one.stderr
    assert two.returncode == 0, two.stderr
    assert two.stderr == ""
    files = _report_files(tmp_path / "one")
    assert sum(name.endswith(".png") for name in files) >= 2
    assert _report_files(tmp_path / "two") == files
    layers = _map_layers(tmp_path / "one" / "report.gpkg")
    assert {"encounters", "tracks", "domains"} <= layers.keys()
    assert _map_layers(tmp_path / "two" / "report.gpkg") == layers
    assert one.stdout.replace(str(tmp_path / "one"), "") == two.stdout.replace(
        str(tmp_path / "two"), ""
    )


def test_an_unreachable_scheduler_is_one_error_before_any_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(dask_run, "_CONNECT_TIMEOUT_S", 1)
    result = CliRunner().invoke(
        app,
        [
            *("replay", str(NMEA), "--quiet", "--out", str(tmp_path / "r")),
            *("--scheduler", "tcp://127.0.0.1:9"),
        ],
    )
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: --scheduler tcp://127.0.0.1:9")
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--workers", "0"], "--workers 0"),
        (["--scratch", "/nonexistent/scratch"], "--scratch /nonexistent/scratch"),
    ],
)
def test_bad_worker_options_are_one_error(tmp_path: Path, options, message) -> None:
    result = CliRunner().invoke(
        app, ["replay", str(NMEA), "--quiet", "--out", str(tmp_path / "r"), *options]
    )
    assert result.exit_code == 2, result.output
    assert result.output.startswith(f"Error: {message}")


def test_a_local_cluster_leaves_nothing_in_the_temporary_directory(tmp_path: Path) -> None:
    """``--workers 2`` through the console script, which leaves with ``os._exit``: neither
    multiprocessing's ``pymp-*`` (the forkserver's socket) nor Dask's worker directories
    and lock files stay in TMPDIR (issue 30)."""
    # A short TMPDIR of its own: multiprocessing's socket path must fit AF_UNIX's 108 bytes,
    # which a deep pytest directory (under xdist, say) need not.
    tmp = Path(tempfile.mkdtemp(prefix="c9-", dir="/tmp"))
    result = subprocess.run(
        [
            *(sys.executable, "-m", "colregs9_cli", "replay", str(NMEA), "--quiet", "--no-plots"),
            *("--out", str(tmp_path / "r"), "--slab-minutes", "1", "--workers", "2"),
        ],
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "TMPDIR": str(tmp)},
    )
    left = sorted(p.name for p in tmp.rglob("*"))
    shutil.rmtree(tmp)
    assert result.returncode == 0, result.stderr
    assert left == []
    assert (tmp_path / "r" / "pairs.csv").is_file()


def test_local_clusters_one_after_another_in_one_process(tmp_path: Path) -> None:
    """The forkserver a cluster started is stopped with it (its socket was in a directory
    now removed): the next cluster of the process starts its own, and leaves nothing."""
    for _ in range(2):
        with dask_run.dask_client(1, None, tmp_path) as client:
            assert client.submit(operator.add, 1, 2).result() == 3
            (made,) = tmp_path.iterdir()
            assert made.name.startswith("colregs9-dask-")
        assert list(tmp_path.iterdir()) == []


def _write_after(started: Path, path: Path, delay_s: float) -> None:
    import time

    started.write_text("")
    time.sleep(delay_s)
    path.write_text("late")


def test_settling_waits_for_the_tasks_that_run(tmp_path: Path) -> None:
    """After a failure while the workers write into the report's staging directory: a
    running task cannot be stopped, so ``settle_tasks`` returns only once it has ended
    (the staging directory is removed after), and a task not begun never runs."""
    import time

    with dask_run.dask_client(1, None, tmp_path) as client:
        started = tmp_path / "started"
        running = client.submit(_write_after, started, tmp_path / "running", 1.0, pure=False)
        queued = client.submit(_write_after, started, tmp_path / "queued", 0.0, pure=False)
        while not started.exists():
            time.sleep(0.01)
        dask_run.settle_tasks(client, [running, queued])
        assert (tmp_path / "running").read_text() == "late"
        time.sleep(0.3)
        assert not (tmp_path / "queued").exists()


def test_a_worker_reads_its_part_of_a_dataset_itself(tmp_path: Path) -> None:
    """Stage 1 on a LocalCluster of two: each task carries the dataset's place and a range
    of MMSIs, not positions (pickled, a small share of the positions' bytes), and the
    worker reads them from the dataset: the client's parts have read nothing, and the
    workers' results are those of one process reading the whole dataset."""
    ingest([NMEA], tmp_path / "dataset")
    query = everything_query()
    params = run_params(query).replay

    def opened() -> ReplayInput:
        return open_replay_input(
            [tmp_path / "dataset"], query, None, True, tmp_path, params.slab_s, REPLAY_COLUMNS
        )

    whole = opened()
    (tmp_path / "one").mkdir()
    alone = whole.merge([segment_input_part(whole, 0, tmp_path / "one", params)])
    parts = opened().parts(2)
    assert len(parts) == 2
    (tmp_path / "two").mkdir()
    tasks = [
        functools.partial(segment_input_part, part, k, tmp_path / "two", params)
        for k, part in enumerate(parts)
    ]
    positions_bytes = sum(frame.memory_usage(deep=True).sum() for _, frame in opened().positions())
    sent_bytes = [len(pickle.dumps(task)) for task in tasks]
    assert max(sent_bytes) < positions_bytes / 20, (sent_bytes, positions_bytes)
    with dask_run.dask_client(2, None, tmp_path) as client, progress_bar("", 2, False) as bar:
        done = dask_run.dask_segments(client, tasks, bar)
    assert all(part.counts == ReadCounts() for part in parts)  # read on the workers only
    assert sum(part.counts.kept for part in done) == whole.counts.kept > 20_000
    merged = opened().merge(done)
    assert merged.stats == alone.stats
    assert np.array_equal(merged.vessels, alone.vessels)
    pd.testing.assert_frame_equal(merged.statics, alone.statics)
    everything = (-math.inf, math.inf)
    pd.testing.assert_frame_equal(merged.spill.read(*everything), alone.spill.read(*everything))


def _worker_settings(dask_worker: Any) -> tuple[bool, float, float, int]:
    callbacks = dask_worker.periodic_callbacks
    return (
        "profile" in callbacks,
        callbacks["tick"].callback_time,
        callbacks["memory_monitor"].callback_time,
        pa.cpu_count(),
    )


def test_workers_started_apart_get_the_local_clusters_settings(tmp_path: Path) -> None:
    """A cluster started without colregs9 (as ``dask worker`` starts one: Dask's defaults,
    the profiler sampling every 10 ms, the tick every 20 ms): ``--scheduler`` gives its
    workers the settings of colregs9's local cluster."""
    with (
        LocalCluster(
            n_workers=1,
            threads_per_worker=1,
            dashboard_address=None,
            scheduler_kwargs={"dashboard_address": ":0"},
            local_directory=str(tmp_path),
        ) as cluster,
        Client(cluster) as plain,
    ):
        (before,) = plain.run(_worker_settings).values()
        assert before[:2] == (True, 20.0)
        with dask_run.dask_client(1, cluster.scheduler_address) as client:
            (after,) = client.run(_worker_settings).values()
    assert after == (False, 1000.0, 1000.0, 1)
