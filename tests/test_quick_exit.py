"""The console script's quick exit: the statuses of ``sys.exit``, streams flushed, files whole."""

from __future__ import annotations

import gc
import io
import json
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from colregs9_cli import quick_exit

from fixture_files import DMA26, ROOT


@pytest.fixture(autouse=True)
def _gc_thresholds() -> Iterator[None]:
    """``run_and_exit`` sets the collector's thresholds for the process: restore pytest's."""
    thresholds = gc.get_threshold()
    yield
    gc.set_threshold(*thresholds)


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
    _, older, oldest = gc.get_threshold()
    seen: list[tuple[int, int, int]] = []
    _exit_status(lambda: seen.append(gc.get_threshold()), monkeypatch)
    assert seen == [(quick_exit.GC_YOUNG_THRESHOLD, older, oldest)]
    assert gc.isenabled()


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
