"""Slab-wise replay (``slabs.py``): the same results as one go, for any slab length."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_replay_cli import write_dma

from colregs9_cli.core.tracks import (
    NO_TRACK_STATS,
    REPORT_COLUMNS,
    empty_carry,
    segment_reports,
)
from colregs9_cli.jobs.replay import run_replay
from colregs9_cli.jobs.replay_params import ReplayParams

from fixture_files import NMEA, SANDIEGO_AIS, SANDIEGO_ENC

ONE_SLAB = {"replay": {"slab_s": 86400.0}}  # every fixture lies within one day


def _replay(paths, charts=(), slab_s: float | None = None):
    overrides = ONE_SLAB if slab_s is None else {"replay": {"slab_s": slab_s}}
    return run_replay(paths, charts, overrides=overrides, write=False)


def _same(result, expected) -> None:
    assert [dataclasses.asdict(p.summary) for p in result.pairs] == [
        dataclasses.asdict(p.summary) for p in expected.pairs
    ]
    for pair, expected_pair in zip(result.pairs, expected.pairs, strict=True):
        for seat, expected_seat in zip(pair.seats, expected_pair.seats, strict=True):
            assert seat.summary == expected_seat.summary
            pd.testing.assert_frame_equal(seat.series, expected_seat.series)
    assert result.counts == expected.counts
    assert result.manifest["tracks"] == expected.manifest["tracks"]
    assert result.manifest["ledger"] == expected.manifest["ledger"]


@pytest.fixture(scope="module")
def national_one_slab():
    return _replay([NMEA])


@pytest.mark.parametrize("slab_s", [37.0, 60.0, 150.0])
def test_slab_boundaries_inside_encounters_change_nothing(national_one_slab, slab_s) -> None:
    """The five-minute national sample cut into slabs shorter than its encounters (from
    37 s): every encounter that crosses a boundary is found whole."""
    result = _replay([NMEA], slab_s=slab_s)
    assert result.counts.triggered_pairs == 12
    crossing = [
        p
        for p in result.pairs
        if int(p.summary.start_utc.timestamp() // slab_s)
        != int(p.summary.end_utc.timestamp() // slab_s)
    ]
    assert crossing, "no encounter crosses a slab boundary: the test proves nothing"
    _same(result, national_one_slab)


def test_sandiego_with_a_chart_is_the_same_in_slabs() -> None:
    expected = _replay([SANDIEGO_AIS], [SANDIEGO_ENC])
    _same(_replay([SANDIEGO_AIS], [SANDIEGO_ENC], slab_s=600.0), expected)


def _converging(path: Path, pairs: int = 1) -> Path:
    """Two vessels an hour long, A east at 10 kn, B 1 km south of her on 085° at 10 kn: a
    candidate pair from the first report, which closes at 0.45 m/s and triggers about 35
    minutes later. ``pairs`` such pairs, 0.2° of latitude apart."""
    rows = [
        (stamp, mmsi + 2 * k, lat + 0.2 * k, lon, sog, cog)
        for k in range(pairs)
        for stamp, mmsi, lat, lon, sog, cog in _converging_rows()
    ]
    return write_dma(path, rows)


def _converging_rows() -> list[tuple]:
    rows = []
    metres_per_deg_lon = 111_320 * np.cos(np.radians(57.0))
    speed_mps = 10 * 1852 / 3600
    for second in range(0, 3601, 10):
        when = pd.Timestamp("2013-11-12 12:00:00") + pd.Timedelta(seconds=second)
        stamp = when.strftime("%d/%m/%Y %H:%M:%S")
        a_lon = 10.0 + speed_mps * second / metres_per_deg_lon
        b_north = -1000.0 + speed_mps * np.sin(np.radians(5.0)) * second
        b_east = speed_mps * np.cos(np.radians(5.0)) * second
        rows.append((stamp, 219000001, 57.0, a_lon, 10.0, 90.0))
        rows.append(
            (
                stamp,
                219000002,
                57.0 + b_north / 111_320,
                10.0 + b_east / metres_per_deg_lon,
                10.0,
                85.0,
            )
        )
    return rows


def test_an_encounter_longer_than_a_slab_window_is_followed(tmp_path: Path) -> None:
    path = _converging(tmp_path / "converging.csv")
    expected = _replay([path])
    (pair,) = expected.pairs
    started, triggered = pair.summary.start_utc, pair.summary.trigger_utc
    assert (triggered - started).total_seconds() > 1500
    assert expected.manifest["slabs"]["pairs_followed_past_their_slab"] == 0
    in_slabs = _replay([path], slab_s=300.0)
    assert in_slabs.manifest["slabs"]["pairs_followed_past_their_slab"] == 1
    _same(in_slabs, expected)


@pytest.mark.parametrize("own_mmsi", [(), (219000003,)])
def test_encounters_followed_together_are_those_followed_alone(tmp_path: Path, own_mmsi) -> None:
    """Three such pairs followed in one read and search per window: each as in one slab."""
    path = _converging(tmp_path / "three.csv", pairs=3)

    def replay(slab_s: float | None):
        overrides = ONE_SLAB if slab_s is None else {"replay": {"slab_s": slab_s}}
        return run_replay([path], own_mmsi=own_mmsi, overrides=overrides, write=False)

    expected = replay(None)
    assert len(expected.pairs) == (1 if own_mmsi else 3)
    in_slabs = replay(300.0)
    assert in_slabs.manifest["slabs"]["pairs_followed_past_their_slab"] == (1 if own_mmsi else 3)
    _same(in_slabs, expected)


# -- segmentation carried from slab to slab ---------------------------------------------------


@st.composite
def _reports(draw) -> pd.DataFrame:
    """A few vessels' reports: steady steps with the odd repeat, jump, and gap."""
    frames = []
    for vessel in range(draw(st.integers(1, 4))):
        count = draw(st.integers(1, 40))
        steps = draw(
            st.lists(
                st.sampled_from([0.0, 3.0, 10.0, 10.0, 10.0, 400.0]), min_size=count, max_size=count
            )
        )
        t = 1_000_000.0 + np.cumsum(steps)
        jumps = np.asarray(
            draw(st.lists(st.booleans(), min_size=count, max_size=count)), dtype=bool
        ) & np.asarray(draw(st.lists(st.booleans(), min_size=count, max_size=count)), dtype=bool)
        north_m = np.arange(count) * 50.0 + np.where(jumps, 20_000.0, 0.0)
        frames.append(
            pd.DataFrame(
                {
                    "mmsi": np.full(count, 219_000_000 + vessel, dtype=np.int64),
                    "t_s": t,
                    "lat_deg": 57.0 + north_m / 111_320.0,
                    "lon_deg": np.full(count, 10.0),
                    "sog_kn": np.full(count, 9.7),
                    "cog_deg": np.full(count, 0.0),
                    "heading_deg": np.full(count, np.nan),
                    "nav_status": np.full(count, 0.0),
                }
            )
        )
    return pd.concat(frames, ignore_index=True)[list(REPORT_COLUMNS)]


@settings(max_examples=100, deadline=None)
@given(reports=_reports(), slab_s=st.sampled_from([5.0, 20.0, 60.0, 300.0, 1000.0]))
def test_segmentation_in_slabs_decides_every_report_as_in_one_go(reports, slab_s) -> None:
    params = ReplayParams()
    whole = segment_reports(reports, empty_carry(), params.tracks)
    slab = np.floor(reports["t_s"].to_numpy() / slab_s).astype(np.int64)
    indices = np.unique(slab)
    carry, stats, kept = empty_carry(), NO_TRACK_STATS, []
    for n, index in enumerate(indices):
        until = None if n == len(indices) - 1 else (index + 1) * slab_s
        part = segment_reports(reports[slab == index], carry, params.tracks, until)
        carry, stats = part.carry, stats + part.stats
        kept.append(part.kept)
    streamed = pd.concat(kept, ignore_index=True)
    order = np.lexsort((streamed["t_s"].to_numpy(), streamed["mmsi"].to_numpy()))
    pd.testing.assert_frame_equal(streamed.iloc[order].reset_index(drop=True), whole.kept)
    assert stats == whole.stats
