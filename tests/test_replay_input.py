"""A replay's AIS by slab (``replay_input.py``): the positions and ledger of ``load_ais``, a
dataset read in place, gaps of years skipped, and the same verdicts from files and datasets."""

from __future__ import annotations

import dataclasses
from datetime import datetime, timedelta
from pathlib import Path

import pandas as pd
import pytest
from test_replay_cli import write_dma

from colregs9_cli.ais.load import load_ais
from colregs9_cli.jobs.ingest import ingest
from colregs9_cli.jobs.replay import REPLAY_COLUMNS, run_replay
from colregs9_cli.jobs.replay_input import open_replay_input
from colregs9_cli.query import everything_query, load_query

from fixture_files import DMA22, DMA26, NMEA, ROOT

SLAB_S = 1800.0
# 10 kn at 57° N in degrees of longitude per second.
_DEG_PER_S = 10 * 1852 / 3600 / (111_320 * 0.5446)


def _head_on(start: datetime, first_mmsi: int) -> list[tuple]:
    """Two vessels meeting nearly end on at 10 kn each, 60 m apart abeam: one trigger."""
    rows = []
    for k in range(61):
        when = start + timedelta(seconds=10 * k)
        stamp = when.strftime("%d/%m/%Y %H:%M:%S")
        rows.append((stamp, first_mmsi, 57.0, 10.0 + _DEG_PER_S * 10 * k, 10.0, 90.0))
        rows.append((stamp, first_mmsi + 1, 57.00055, 10.12 - _DEG_PER_S * 10 * k, 10.0, 270.0))
    return rows


def _read_all(paths, query, scratch: Path):
    ais = open_replay_input(paths, query, None, True, scratch, SLAB_S, REPLAY_COLUMNS)
    parts = [part for _, part in ais.positions()]
    positions = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame()
    return ais, positions


def _same_ledger(got, want) -> None:
    """The same counts; the examples may name other rows of the same kind."""
    got, want = got.to_dict(), want.to_dict()
    assert got.pop("reject_examples").keys() == want.pop("reject_examples").keys()
    assert got == want


def _sorted(frame: pd.DataFrame) -> pd.DataFrame:
    frame = frame[sorted(frame.columns)]
    keys = ["mmsi", "timestamp", "lat_deg", "lon_deg", "sog_kn", "cog_deg"]
    return frame.sort_values(keys, kind="stable", ignore_index=True)


@pytest.mark.parametrize("query_file", [None, "limfjorden.toml"])
def test_slabs_hold_the_positions_and_ledger_of_load_ais(tmp_path: Path, query_file) -> None:
    """Files ingested to the scratch dataset, read back slab by slab: the rows and the
    ledger that reading the files whole gives, duplicates across files included."""
    half = tmp_path / "half_of_dma26.csv"
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    half.write_text("\n".join(lines[: len(lines) // 2]) + "\n", encoding="utf-8")
    paths = [DMA26, half, DMA22, NMEA]
    query = load_query(ROOT / "queries" / query_file) if query_file else everything_query()
    ais, positions = _read_all(paths, query, tmp_path / "scratch")
    whole = load_ais(paths, query=query, columns=REPLAY_COLUMNS)
    pd.testing.assert_frame_equal(_sorted(positions), _sorted(whole.positions))
    _same_ledger(ais.ledger, whole.ledger)
    if query_file is None:
        assert ais.ledger.rejects["duplicate"] >= len(lines) // 2 - 1
    assert ais.dataset is not None  # read slab by slab, not in memory
    assert [i.path for i in ais.inputs] == paths


def test_a_file_given_twice_is_read_whole_with_its_duplicates(tmp_path: Path) -> None:
    ais, positions = _read_all([DMA26, DMA26], everything_query(), tmp_path)
    whole = load_ais([DMA26, DMA26], columns=REPLAY_COLUMNS)
    assert ais.dataset is None
    pd.testing.assert_frame_equal(_sorted(positions), _sorted(whole.positions))
    assert ais.ledger.to_dict() == whole.ledger.to_dict()


def test_a_gap_of_two_years_reads_only_the_slabs_with_data(tmp_path: Path) -> None:
    rows = _head_on(datetime(2013, 11, 12, 12, 0), 219000001)
    rows += _head_on(datetime(2015, 11, 12, 12, 0), 219000001)
    path = write_dma(tmp_path / "two_years.csv", rows)
    ais, _ = _read_all([path], everything_query(), tmp_path / "scratch")
    assert len(ais.slabs) <= 4  # not the 35,000 slabs of two years
    result = run_replay([path], write=False)
    assert result.counts.triggered_pairs == 2
    assert result.manifest["slabs"]["slabs"] <= 4
    starts = sorted(p.summary.start_utc for p in result.pairs)
    assert [s[:4] for s in map(str, starts)] == ["2013", "2015"]


@pytest.fixture(scope="module")
def nmea_dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("replay-dataset") / "ais"
    ingest([NMEA], out)
    return out


def test_replay_of_a_dataset_is_the_replay_of_its_files(nmea_dataset: Path) -> None:
    overrides = {"replay": {"slab_s": 120.0}}
    from_files = run_replay([NMEA], overrides=overrides, write=False)
    from_dataset = run_replay([nmea_dataset], overrides=overrides, write=False)
    assert from_files.counts.triggered_pairs == 12
    assert [dataclasses.asdict(p.summary) for p in from_dataset.pairs] == [
        dataclasses.asdict(p.summary) for p in from_files.pairs
    ]
    for key in ("ledger", "tracks", "counts", "verdicts"):
        assert from_dataset.manifest[key] == from_files.manifest[key], key
    assert [i.get("dataset") for i in from_dataset.manifest["inputs"]] == [str(nmea_dataset)]


def test_the_slabs_are_read_from_the_dataset_one_window_at_a_time(
    nmea_dataset: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Memory holds one slab: every read is one slab's window, none the whole run."""
    import colregs9_cli.jobs.replay_input as replay_input

    windows: list[timedelta] = []
    read = replay_input.read_window_counted

    def recording(dataset, query, start, end, columns, mmsis):  # type: ignore[no-untyped-def]
        windows.append(end - start)
        return read(dataset, query, start, end, columns, mmsis)

    monkeypatch.setattr(replay_input, "read_window_counted", recording)
    result = run_replay([nmea_dataset], overrides={"replay": {"slab_s": 60.0}}, write=False)
    assert result.counts.triggered_pairs == 12
    assert len(windows) >= 5
    assert set(windows) == {timedelta(seconds=60)}
