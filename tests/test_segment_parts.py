"""Stage 1 in parts of the vessels (``slabs.segment_part``, ``replay_input.ReplayInput.parts``):
the segmentation, the ledger and the counts of one part, for any number of parts."""

from __future__ import annotations

import pickle
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_replay_cli import write_dma

from colregs9_cli.jobs.replay import REPLAY_COLUMNS
from colregs9_cli.jobs.replay_input import ReplayInput, open_replay_input, segment_input_part
from colregs9_cli.jobs.replay_params import ReplayParams
from colregs9_cli.jobs.slabs import Segmentation, merge_parts, segment_part, slabs_of_frame
from colregs9_cli.query import everything_query

from fixture_files import DMA22, DMA26, NMEA

SLAB_S = 60.0  # the national sample's five minutes in five slabs


def _same(got: Segmentation, want: Segmentation) -> None:
    read = (want.first_s, want.last_s)
    pd.testing.assert_frame_equal(got.spill.read(*read), want.spill.read(*read))
    pd.testing.assert_frame_equal(got.statics, want.statics)
    np.testing.assert_array_equal(got.vessels, want.vessels)
    assert got.vessels.dtype == want.vessels.dtype
    assert got.extent == want.extent
    pd.testing.assert_frame_equal(got.points, want.points)
    assert (got.first_s, got.last_s, got.stats) == (want.first_s, want.last_s, want.stats)


def _in_parts(
    dataset: Path, number: int, spill_dir: Path, slab_s: float = SLAB_S
) -> tuple[Segmentation, ReplayInput]:
    """Stage 1 of the dataset in ``number`` parts; several are each read and segmented from
    a pickled copy, as on a worker, one in place, as in the run's process."""
    spill_dir.mkdir()
    ais = open_replay_input(
        [dataset], everything_query(), None, True, spill_dir, slab_s, REPLAY_COLUMNS
    )
    parts = ais.parts(number)
    assert len(parts) == number
    if number > 1:
        parts = tuple(pickle.loads(pickle.dumps(part)) for part in parts)
    params = ReplayParams(slab_s=slab_s)
    done = [segment_input_part(part, k, spill_dir, params) for k, part in enumerate(parts)]
    return ais.merge(done), ais


@pytest.fixture(scope="module")
def with_duplicates(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The inputs of ``test_replay_input``'s ledger test in a scratch dataset: the national
    sample, and a file with half of another file's rows (duplicates across inputs)."""
    scratch = tmp_path_factory.mktemp("parts")
    half = scratch / "half_of_dma26.csv"
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    half.write_text("\n".join(lines[: len(lines) // 2]) + "\n", encoding="utf-8")
    ais = open_replay_input(
        [DMA26, half, DMA22, NMEA], everything_query(), None, True, scratch, SLAB_S, REPLAY_COLUMNS
    )
    assert ais.dataset is not None
    return ais.dataset.directory


@pytest.mark.parametrize("number", [2, 3])
def test_parts_of_a_dataset_segment_as_one(with_duplicates: Path, tmp_path: Path, number) -> None:
    """Vessels across slab boundaries and duplicates across inputs, in two and three parts:
    the spill, statics, vessels, extent, points, span and counts of one part, the same
    ledger (its example of a duplicate too) and the same vessels read."""
    one, whole = _in_parts(with_duplicates, 1, tmp_path / "one")
    split, parts = _in_parts(with_duplicates, number, tmp_path / "split")
    _same(split, one)
    assert parts.ledger.to_dict() == whole.ledger.to_dict()
    assert parts.counts == whole.counts
    assert whole.ledger.rejects["duplicate"] > 0
    assert len({f.path.name.rsplit("-", 1)[1] for f in split.spill.files}) == number
    spilled = one.spill.read(one.first_s, one.last_s)
    slabs_per_vessel = spilled.groupby("mmsi")["t_s"].agg(lambda t: np.ptp(t // SLAB_S))
    assert (slabs_per_vessel > 0).any(), "no vessel crosses a slab boundary"


def test_the_example_duplicate_is_of_the_earliest_slab_whatever_the_parts(tmp_path: Path) -> None:
    """The first duplicate dropped, as one part reads them: of the earliest slab, although
    the lower part of the vessels has its own duplicates only in a later slab."""
    low, high = 219000001, 219000002
    rows = [
        (f"12/11/2013 12:{s // 60:02d}:{s % 60:02d}", mmsi, 57.0 + k, 10.0 + s * 1e-5, 10.0, 90.0)
        for s in range(0, 180, 10)
        for k, mmsi in enumerate((low, high))
    ]
    repeated = [r for r in rows if (r[1] == high) == r[0].startswith("12/11/2013 12:00")]
    paths = [write_dma(tmp_path / "a.csv", rows), write_dma(tmp_path / "b.csv", repeated)]
    ais = open_replay_input(paths, everything_query(), None, True, tmp_path, SLAB_S, REPLAY_COLUMNS)
    assert ais.dataset is not None
    one, whole = _in_parts(ais.dataset.directory, 1, tmp_path / "one")
    split, parts = _in_parts(ais.dataset.directory, 2, tmp_path / "two")
    _same(split, one)
    assert [part.mmsis for part in whole.parts(2)] == [(low, low), (high, high)]
    assert parts.ledger.to_dict() == whole.ledger.to_dict()
    assert whole.ledger.rejects["duplicate"] == len(repeated)
    (example,) = whole.ledger.to_dict()["reject_examples"]["duplicate"]
    assert example.startswith(f"MMSI {high} at 2013-11-12 12:00:00")


def test_an_input_in_memory_is_one_part(tmp_path: Path) -> None:
    ais = open_replay_input(
        [DMA26, DMA26], everything_query(), None, True, tmp_path, SLAB_S, REPLAY_COLUMNS
    )
    assert ais.dataset is None
    assert ais.parts(3) == (ais,)


@st.composite
def _positions(draw) -> pd.DataFrame:
    """A few vessels' positions, each from its own start, so that a part of the vessels
    skips slabs that another has: steady steps with the odd repeat, jump and gap, and static
    values that are missing or change."""
    frames = []
    for vessel in range(draw(st.integers(1, 5))):
        count = draw(st.integers(1, 30))
        start = draw(st.sampled_from([0.0, 50.0, 700.0, 2000.0]))
        steps = draw(
            st.lists(
                st.sampled_from([0.0, 3.0, 10.0, 10.0, 10.0, 400.0]), min_size=count, max_size=count
            )
        )
        t = 1_000_000.0 + start + np.cumsum(steps)
        jumps = np.asarray(
            draw(st.lists(st.booleans(), min_size=count, max_size=count)), dtype=bool
        ) & np.asarray(draw(st.lists(st.booleans(), min_size=count, max_size=count)), dtype=bool)
        north_m = np.arange(count) * 50.0 + np.where(jumps, 20_000.0, 0.0)
        lengths = draw(
            st.lists(st.sampled_from([np.nan, 90.0, 120.0]), min_size=count, max_size=count)
        )
        frames.append(
            pd.DataFrame(
                {
                    "timestamp": pd.to_datetime(t * 1000.0, unit="ms", utc=True),
                    "mmsi": np.full(count, 219_000_000 + vessel, dtype=np.int64),
                    "lat_deg": 57.0 + north_m / 111_320.0,
                    "lon_deg": np.full(count, 10.0 + vessel * 0.003),
                    "sog_kn": np.full(count, 9.7),
                    "cog_deg": np.full(count, 0.0),
                    "heading_deg": np.full(count, np.nan),
                    "nav_status": np.full(count, 0.0),
                    "name": [f"VESSEL {vessel}"] * count,
                    "length_m": lengths,
                }
            )
        )
    return pd.concat(frames, ignore_index=True)


@settings(max_examples=60, deadline=None)
@given(
    positions=_positions(),
    slab_s=st.sampled_from([30.0, 60.0, 300.0, 1000.0]),
    cuts=st.lists(st.integers(219_000_001, 219_000_004), max_size=3, unique=True),
)
def test_segmentation_in_parts_of_the_vessels_is_that_of_all(positions, slab_s, cuts) -> None:
    """Jumps left pending at a slab's end, decided in a later slab or at the end, in parts
    that skip slabs: the same segmentation, whatever the cut."""
    params = ReplayParams(slab_s=slab_s)
    part_of = np.searchsorted(np.sort(cuts), positions["mmsi"].to_numpy(), side="right")
    with tempfile.TemporaryDirectory() as one_dir, tempfile.TemporaryDirectory() as parts_dir:
        one = merge_parts(
            [segment_part(slabs_of_frame(positions, slab_s), 0, Path(one_dir), params)]
        )
        parts = [
            segment_part(
                slabs_of_frame(positions[part_of == k], slab_s), k, Path(parts_dir), params
            )
            for k in range(len(cuts) + 1)
        ]
        _same(merge_parts(parts), one)
