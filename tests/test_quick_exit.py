"""The console script's quick exit: the statuses of ``sys.exit``, streams flushed, files whole;
and none of its process tweaks (quick exit, SIGTERM handler, collector thresholds) outside it."""

from __future__ import annotations

import gc
import io
import json
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest
from typer.testing import CliRunner

from colregs9_cli import quick_exit

from fixture_files import DMA26, ROOT


@pytest.fixture(autouse=True)
def _process_state() -> Iterator[None]:
    """``run_and_exit`` installs its SIGTERM handler for the process (the console script's
    whole life): restore pytest's, and its collector's thresholds should a test fail inside a
    ``fewer_collections`` block."""
    thresholds = gc.get_threshold()
    on_sigterm = signal.getsignal(signal.SIGTERM)
    yield
    gc.set_threshold(*thresholds)
    signal.signal(signal.SIGTERM, on_sigterm)


class _Left(Exception):
    """Stands in for ``os._exit`` in the tests, which must not end pytest."""


def _exit_status(main: object, monkeypatch: pytest.MonkeyPatch) -> int:
    statuses: list[int] = []

    def leave(status: int) -> None:
        statuses.append(status)
        raise _Left

    monkeypatch.setattr(quick_exit.os, "_exit", leave)
    with pytest.raises(_Left):
        quick_exit.run_and_exit(main)  # type: ignore[arg-type]
    return statuses[0]


@pytest.mark.parametrize(("code", "status"), [(None, 0), (0, 0), (2, 2), (3, 3), ("Error: bad", 1)])
def test_the_status_is_that_of_sys_exit(
    code: object, status: int, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    def main() -> None:
        sys.exit(code)  # type: ignore[arg-type]

    assert _exit_status(main, monkeypatch) == status
    assert capsys.readouterr().err == ("Error: bad\n" if isinstance(code, str) else "")


def test_a_main_that_returns_exits_0(monkeypatch: pytest.MonkeyPatch) -> None:
    assert _exit_status(lambda: None, monkeypatch) == 0


def test_the_main_runs_with_fewer_young_collections(monkeypatch: pytest.MonkeyPatch) -> None:
    before = gc.get_threshold()
    _, older, oldest = before
    seen: list[tuple[int, int, int]] = []
    _exit_status(lambda: seen.append(gc.get_threshold()), monkeypatch)
    assert seen == [(quick_exit.GC_YOUNG_THRESHOLD, older, oldest)]
    assert gc.isenabled()
    assert gc.get_threshold() == before


def test_fewer_collections_lasts_as_long_as_its_blocks() -> None:
    before = gc.get_threshold()
    _, older, oldest = before
    fewer = (quick_exit.GC_YOUNG_THRESHOLD, older, oldest)
    with quick_exit.fewer_collections():
        assert gc.get_threshold() == fewer
        with quick_exit.fewer_collections():
            assert gc.get_threshold() == fewer
        assert gc.get_threshold() == fewer
    assert gc.get_threshold() == before
    with pytest.raises(ValueError, match="a bug"), quick_exit.fewer_collections():
        raise ValueError("a bug")
    assert gc.get_threshold() == before
    # Blocks that overlap (tasks on the threads of one worker) may leave in any order.
    first, second = quick_exit.fewer_collections(), quick_exit.fewer_collections()
    first.__enter__()
    second.__enter__()
    first.__exit__(None, None, None)
    assert gc.get_threshold() == fewer
    second.__exit__(None, None, None)
    assert gc.get_threshold() == before


def test_a_dask_task_collects_seldom_and_leaves_its_worker_as_it_was() -> None:
    from colregs9_cli.jobs import dask_run

    before = gc.get_threshold()
    _, older, oldest = before
    during = dask_run._seldom_collected(gc.get_threshold)
    assert during == (quick_exit.GC_YOUNG_THRESHOLD, older, oldest)
    assert gc.get_threshold() == before


@pytest.fixture
def tweaks(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """What a library caller must never meet: a quick exit, a SIGTERM handler or another
    collector threshold, each recorded instead of done."""
    seen: list[str] = []
    set_threshold, set_handler = gc.set_threshold, signal.signal

    def threshold(*values: int) -> None:
        seen.append(f"gc.set_threshold{values}")
        set_threshold(*values)

    def handler(signum: int, action: object) -> object:
        if signum == signal.SIGTERM:
            seen.append("signal.signal(SIGTERM)")
        return set_handler(signum, action)  # type: ignore[arg-type]

    monkeypatch.setattr(gc, "set_threshold", threshold)
    monkeypatch.setattr(signal, "signal", handler)
    monkeypatch.setattr(quick_exit.os, "_exit", lambda status: seen.append(f"os._exit({status})"))
    return seen


def test_the_console_script_entry_makes_them(
    tweaks: list[str], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    from colregs9_cli.cli import run

    monkeypatch.setattr(sys, "argv", ["colregs9", "--version"])
    run()  # os._exit only recorded: returns
    assert capsys.readouterr().out.startswith("colregs9 ")
    assert tweaks[0] == "signal.signal(SIGTERM)"
    assert tweaks[1].startswith(f"gc.set_threshold({quick_exit.GC_YOUNG_THRESHOLD}, ")
    assert tweaks[2:] == [f"gc.set_threshold{gc.get_threshold()}", "os._exit(0)"]


def test_the_typer_app_leaves_the_process_alone(tmp_path: Path, tweaks: list[str]) -> None:
    from colregs9_cli.cli import app

    thresholds, on_sigterm = gc.get_threshold(), signal.getsignal(signal.SIGTERM)
    result = CliRunner().invoke(app, ["stats", str(DMA26), "--out", str(tmp_path), "--quiet"])
    assert result.exit_code == 0, result.output
    assert tweaks == []
    assert gc.get_threshold() == thresholds
    assert signal.getsignal(signal.SIGTERM) == on_sigterm


def test_the_api_leaves_the_process_alone(tweaks: list[str]) -> None:
    import colregs9_cli.api as colregs9

    thresholds, on_sigterm = gc.get_threshold(), signal.getsignal(signal.SIGTERM)
    table = colregs9.vessel_stats([DMA26])
    assert not table.empty
    assert tweaks == []
    assert gc.get_threshold() == thresholds
    assert signal.getsignal(signal.SIGTERM) == on_sigterm


def test_other_exceptions_propagate_with_their_traceback(monkeypatch: pytest.MonkeyPatch) -> None:
    def main() -> None:
        raise ValueError("a bug")

    monkeypatch.setattr(quick_exit.os, "_exit", lambda status: pytest.fail("left quickly"))
    with pytest.raises(ValueError, match="a bug"):
        quick_exit.run_and_exit(main)


def test_an_unflushable_stdout_gives_120_unless_already_failing(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    class Closed(io.StringIO):
        def flush(self) -> None:
            raise BrokenPipeError

    monkeypatch.setattr(sys, "stdout", Closed())
    assert quick_exit.flush_streams(0) == 120
    assert quick_exit.flush_streams(3) == 3


def _run(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    """The console script's entry point in a fresh interpreter."""
    code = "import sys; from colregs9_cli.cli import run; sys.argv[0] = 'colregs9'; run()"
    return subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=cwd, check=False
    )


def test_the_console_script_writes_everything_before_it_leaves(tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = _run("stats", str(DMA26), "--out", str(out), "--quiet", cwd=ROOT)
    assert done.returncode == 0, done.stderr
    assert "length_m" in done.stdout  # the table, flushed
    manifest = json.loads((out / "run.json").read_text())
    assert manifest["rows_read"] == 20
    assert (out / "dimension_histograms.png").read_bytes().startswith(b"\x89PNG")
    assert sorted(p.name for p in out.iterdir()) == [
        "dimension_histograms.png",
        "dimension_stats.csv",
        "dimension_stats.md",
        "index.html",
        "run.json",
    ]


def test_the_console_script_keeps_error_lines_and_codes(tmp_path: Path) -> None:
    done = _run("stats", str(tmp_path / "missing.csv"), cwd=tmp_path)
    assert done.returncode != 0
    assert done.stderr.startswith("Error: ") and done.stderr.count("\n") == 1
    version = _run("--version", cwd=tmp_path)
    assert version.returncode == 0 and version.stdout.startswith("colregs9 ")


def test_sigterm_stops_a_run_as_ctrl_c_does_leaving_nothing_behind(tmp_path: Path) -> None:
    import signal
    import time

    from fixture_files import NMEA

    out = tmp_path / "report"
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    command = [sys.executable, "-m", "colregs9_cli", "replay", str(NMEA), "--out", str(out)]
    run = subprocess.Popen(
        [*command, "--scratch", str(scratch), "--quiet"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    while not any(p.name.endswith(".new") for p in tmp_path.iterdir()):  # writing the report
        assert run.poll() is None and time.monotonic() < deadline, "the run ended too soon"
        time.sleep(0.05)
    run.send_signal(signal.SIGTERM)
    _, stderr = run.communicate(timeout=60)
    assert run.returncode == 143  # 128 + SIGTERM, as a shell reports it
    assert "Traceback" not in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scratch"]
    assert list(scratch.iterdir()) == []
