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
from colregs9_cli.jobs import slabs
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


# -- passings across slab boundaries ----------------------------------------------------------


def _legs_rows(
    mmsi: int,
    north0_m: float,
    east0_m: float,
    legs: list[tuple[float, float, float]],
    slow: tuple[float, float] | None = None,
) -> list[tuple]:
    """DMA rows every 10 s from 12:00 of a vessel sailing ``legs`` of (seconds, course, m/s)
    from (north, east) metres of 57° N 10° E; SOG 0 at the reports in ``slow``."""
    metres_per_deg_lon = 111_320 * np.cos(np.radians(57.0))
    rows = []
    t, north, east = 0.0, north0_m, east0_m
    points = [(t, north, east, legs[0][1], legs[0][2])]
    for seconds, course, speed in legs:
        for k in range(1, int(seconds // 10) + 1):
            points.append(
                (
                    t + 10 * k,
                    north + speed * np.cos(np.radians(course)) * 10 * k,
                    east + speed * np.sin(np.radians(course)) * 10 * k,
                    course,
                    speed,
                )
            )
        t, north, east = points[-1][:3]
    for second, n, e, course, speed in points:
        when = pd.Timestamp("2013-11-12 12:00:00") + pd.Timedelta(seconds=second)
        sog_kn = 0.0 if slow is not None and slow[0] <= second <= slow[1] else speed * 3600 / 1852
        rows.append(
            (
                when.strftime("%d/%m/%Y %H:%M:%S"),
                mmsi,
                57.0 + n / 111_320,
                10.0 + e / metres_per_deg_lon,
                round(sog_kn, 2),
                course,
            )
        )
    return rows


def _slab_results(monkeypatch: pytest.MonkeyPatch) -> list:
    """The ``SlabResult`` of every slab the next replays run (in this process)."""
    results: list = []
    replay_slab = slabs.replay_slab

    def recorded(*args, **kwargs):
        results.append(replay_slab(*args, **kwargs))
        return results[-1]

    monkeypatch.setattr(slabs, "replay_slab", recorded)
    return results


@pytest.mark.parametrize("slab_s", [60.0, 300.0])
def test_a_second_passing_after_a_slab_boundary_is_found_in_slabs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, slab_s: float
) -> None:
    """A passes B head-on at 12:05:00 (100 m), the range opens at 12:05:18; B turns 2 km
    astern at 12:08:20 and overtakes A (trigger 12:16:27, 100 m). One candidate run, two
    passings: the second starts at 12:05:19, in a slab of its own, and triggers in a later
    one, where the pair's chain began twenty minutes before the window (read again)."""
    path = write_dma(
        tmp_path / "return.csv",
        _legs_rows(219000001, 0.0, 0.0, [(1400.0, 0.0, 5.0)])
        + _legs_rows(219000002, 3000.0, 100.0, [(500.0, 180.0, 5.0), (900.0, 0.0, 8.0)]),
    )
    expected = _replay([path])
    assert [(str(p.summary.start_utc), str(p.summary.trigger_utc)) for p in expected.pairs] == [
        ("2013-11-12 12:00:00+00:00", "2013-11-12 12:02:01+00:00"),
        ("2013-11-12 12:05:19+00:00", "2013-11-12 12:16:27+00:00"),
    ]
    results = _slab_results(monkeypatch)
    in_slabs = _replay([path], slab_s=slab_s)
    assert any(r.looked_back for r in results), "no slab read the history: proves nothing"
    _same(in_slabs, expected)


@pytest.mark.parametrize(
    ("slows_at_s", "slab_s", "reads"), [(2400.0, 180.0, "history"), (3400.0, 300.0, "later data")]
)
def test_a_slow_passing_splits_where_it_opened_in_slabs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, slows_at_s: float, slab_s: float, reads: str
) -> None:
    """B overtakes A 100 m off at 0.2 m/s: trigger at 12:22:01 (TCPA 180 s), closest at
    12:25:00, opened past 200 m at 12:39:27, long past the follow window. Then B slows to
    4.5 m/s and A overtakes her back: the second passing starts at 12:39:28. A slab of 180 s
    whose core holds 12:39:28 has a window that starts after the pass and holds no firing
    before the second trigger: it must read the pair's history (the least range, 100 m,
    lies before its window) to know the first passing has opened. With B slowing at
    12:56:40 the second trigger lies past that slab's window: it must read on to learn that
    a passing starts in its core."""
    path = write_dma(
        tmp_path / "slow.csv",
        _legs_rows(219000001, 0.0, 0.0, [(slows_at_s + 1100.0, 0.0, 5.0)])
        + _legs_rows(219000002, -300.0, 100.0, [(slows_at_s, 0.0, 5.2), (1100.0, 0.0, 4.5)]),
    )
    expected = _replay([path])
    first, second = (p.summary for p in expected.pairs)
    assert str(first.trigger_utc) == "2013-11-12 12:22:01+00:00"
    assert (str(first.end_utc), str(second.start_utc)) == (
        "2013-11-12 12:39:27+00:00",
        "2013-11-12 12:39:28+00:00",
    )
    # A closes on B at 0.5 m/s from a gap of 0.2·(t_slow − 1500) m: TCPA 180 s at 90 m.
    gap_m = 0.2 * (slows_at_s - 1500.0)
    assert (second.trigger_utc - pd.Timestamp("2013-11-12 12:00:00Z")).total_seconds() == (
        pytest.approx(slows_at_s + (gap_m - 90.0) / 0.5, abs=1.5)
    )
    results = _slab_results(monkeypatch)
    _same(_replay([path], slab_s=slab_s), expected)
    if reads == "history":
        assert any(r.looked_back for r in results)


@pytest.mark.parametrize("slab_s", [37.0, 60.0, 300.0, 920.0])
def test_a_speed_dip_across_a_slab_boundary_is_one_passing(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, slab_s: float
) -> None:
    """Head-on 100 m apart, triggered at 12:13:41; B reports SOG 0 from 12:15:00 to 12:15:20
    (a boundary of slabs of 60 s and 300 s, inside one of 37 s and 920 s). The run after the
    dip starts in another slab and joins the passing: one pair, as in one slab."""
    path = write_dma(
        tmp_path / "dip.csv",
        _legs_rows(219000003, -5000.0, 0.0, [(2000.0, 0.0, 5.0)])
        + _legs_rows(219000004, 5000.0, 100.0, [(2000.0, 180.0, 5.0)], slow=(900.0, 920.0)),
    )
    expected = _replay([path])
    (pair,) = expected.pairs
    assert str(pair.summary.trigger_utc) == "2013-11-12 12:13:41+00:00"
    assert str(pair.summary.end_utc) == "2013-11-12 12:22:50+00:00"
    assert expected.counts.encounters == 2  # one per seat
    results = _slab_results(monkeypatch)
    _same(_replay([path], slab_s=slab_s), expected)
    assert sum(r.encounters for r in results) == 2


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
