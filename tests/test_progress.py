"""Progress for every phase of a long replay, with the slab in progress."""

from __future__ import annotations

from contextlib import contextmanager

import pytest

import colregs9_cli.jobs.ingest as dataset
import colregs9_cli.jobs.replay as replay
from colregs9_cli.progress import progress_bar

from fixture_files import NMEA


class _Recorder:
    def __init__(self, description: str, total: float | None, in_bytes: bool) -> None:
        self.description, self.total, self.in_bytes = description, total, in_bytes
        self.done = 0.0
        self.notes: list[str] = []

    def advance(self, amount: float = 1.0) -> None:
        self.done += amount

    def describe(self, note: str) -> None:
        self.notes.append(note)


def test_every_phase_of_a_replay_shows_progress(monkeypatch: pytest.MonkeyPatch) -> None:
    bars: list[_Recorder] = []

    @contextmanager
    def recording(description, total, enabled, in_bytes=False):  # type: ignore[no-untyped-def]
        bar = _Recorder(description, total, in_bytes)
        bars.append(bar)
        yield bar

    monkeypatch.setattr(replay, "progress_bar", recording)
    monkeypatch.setattr(dataset, "progress_bar", recording)
    replay.run_replay([NMEA], overrides={"replay": {"slab_s": 60.0}}, write=False)
    by_name = {bar.description: bar for bar in bars}
    reading = by_name["Reading AIS"]
    assert reading.in_bytes and reading.total == NMEA.stat().st_size
    assert reading.done == reading.total
    tracks = by_name["Tracks (slabs)"]
    pairs = by_name["Pairs and verdicts (slabs)"]
    assert tracks.done >= 5 and pairs.done >= 5
    for bar in (tracks, pairs):
        assert len(bar.notes) == bar.done
        assert bar.notes[0].startswith("2013-11-12 ") and bar.notes[0].endswith(" UTC")
        assert bar.notes == sorted(bar.notes)


def test_a_bar_is_silent_when_disabled(capsys: pytest.CaptureFixture[str]) -> None:
    with progress_bar("Reading AIS", 100, enabled=False, in_bytes=True) as bar:
        bar.advance(50)
        bar.describe("slab 1")
    assert capsys.readouterr().err == ""


def test_a_shown_bar_names_the_slab(monkeypatch: pytest.MonkeyPatch) -> None:
    """A real rich bar, on a terminal, shows the note beside the description."""
    import io

    import rich.console

    screen = io.StringIO()
    original = rich.console.Console

    def on_screen(*args, **kwargs):  # type: ignore[no-untyped-def]
        kwargs.update(file=screen, force_terminal=True, width=120)
        kwargs.pop("stderr", None)
        return original(*args, **kwargs)

    monkeypatch.setattr(rich.console, "Console", on_screen)
    with progress_bar("Tracks (slabs)", 2, enabled=True) as bar:
        bar.describe("2013-11-12 12:00:00 UTC")
        bar.advance()
    assert "Tracks (slabs) (2013-11-12 12:00:00 UTC)" in screen.getvalue()
