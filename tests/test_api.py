"""The notebook API: the README's example runs as written and writes nothing; the replay's
tables are the CSV files' columns, typed; the tracks carry UTC and lat/lon; the errors are
the API's own; importing it changes nothing in the process."""

from __future__ import annotations

import contextlib
import io
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from test_replay_cli import write_dma

import colregs9_cli.api as colregs9
from colregs9_cli import errors
from colregs9_cli.core.replay_results import TRACK_COLUMNS, ReplayResult
from colregs9_cli.core.rows import ENCOUNTER_COLUMNS, PAIR_COLUMNS
from colregs9_cli.jobs.replay import run_replay

from fixture_files import DMA26, ROOT


def test_the_readme_example_runs_as_written(monkeypatch: pytest.MonkeyPatch) -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Python API", 1)[1]
    (code,) = re.findall(r"```python\n(.*?)```", section.split("\n## ", 1)[0], flags=re.DOTALL)
    monkeypatch.chdir(ROOT)
    before = set(os.listdir(ROOT / "reports"))
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        exec(compile(code, "README.md", "exec"), {})  # the README's own example
    assert set(os.listdir(ROOT / "reports")) == before  # nothing written
    lines = printed.getvalue().splitlines()
    assert any("length_m" in line for line in lines)
    assert sum(line.startswith("20220103T") for line in lines) == 3
    assert any(line.startswith("Error: ") and "no-such-day.csv" in line for line in lines)


def test_api_results_match_the_commands() -> None:
    positions = colregs9.read_ais([str(DMA26)])
    assert {"timestamp", "mmsi", "lat_deg", "lon_deg"} <= set(positions.columns)
    table = colregs9.vessel_stats([DMA26], by="ship_type")
    assert "ship_type" in table.columns
    with pytest.raises(colregs9.ParameterError, match="per is one of"):
        colregs9.vessel_stats([DMA26], per="ship")


def test_one_path_may_be_given_alone_and_a_bad_mmsi_is_one_error() -> None:
    """A string is one path, not a sequence of one-letter paths; own_mmsi takes one MMSI or
    a list, and anything else is the API's ParameterError."""
    alone = colregs9.read_ais(str(DMA26))
    pd.testing.assert_frame_equal(alone, colregs9.read_ais([DMA26]))
    assert colregs9.vessel_stats(DMA26).equals(colregs9.vessel_stats([str(DMA26)]))
    for bad in (["abc"], 1.5j, [None]):
        with pytest.raises(colregs9.ParameterError, match=r"own_mmsi = .*give an MMSI"):
            colregs9.replay(DMA26, own_mmsi=bad)  # type: ignore[arg-type]


def test_the_error_classes_are_the_apis_and_bad_input_raises_them(tmp_path: Path) -> None:
    assert colregs9.Colregs9Error is errors.Colregs9Error
    exported = {name for name in colregs9.__all__ if name.endswith("Error")}
    defined = {
        name
        for name, value in vars(errors).items()
        if isinstance(value, type) and issubclass(value, errors.Colregs9Error)
    }
    assert exported == defined
    missing = tmp_path / "no-such-day.csv"
    with pytest.raises(colregs9.Colregs9Error, match=r"no-such-day\.csv") as raised:
        colregs9.replay([missing])
    assert isinstance(raised.value, colregs9.InputFileError)
    with pytest.raises(colregs9.Colregs9Error, match="no such encounter"):
        _empty_run(tmp_path).series("20220103T000009-1-2")


def _typed_csv(path: Path, like: pd.DataFrame) -> pd.DataFrame:
    """A CSV of the report read into the dtypes of ``like``: the values a reader of the file
    gets, to compare with the API's."""
    text = pd.read_csv(path, dtype=str, keep_default_na=False)
    assert list(text.columns) == list(like.columns)
    columns = {}
    for name, dtype in like.dtypes.items():
        cells = text[name].replace("", None)
        if pd.api.types.is_bool_dtype(dtype):
            values = cells.map({"true": True, "false": False, None: None})
        elif isinstance(dtype, pd.DatetimeTZDtype):
            values = pd.to_datetime(cells, utc=True, format="ISO8601")
        elif pd.api.types.is_string_dtype(dtype):
            values = cells
        else:
            values = pd.to_numeric(cells)
        columns[name] = values.astype(dtype)
    return pd.DataFrame(columns)


def _without_empty_text(table: pd.DataFrame) -> pd.DataFrame:
    """An empty string and a missing one are the same cell in a CSV."""
    text = [n for n, d in table.dtypes.items() if pd.api.types.is_string_dtype(d)]
    return table.assign(**{n: table[n].replace("", np.nan) for n in text})


def test_tables_are_the_csv_files_typed(sandiego_replay: ReplayResult) -> None:
    result = colregs9.Replay.of(sandiego_replay)
    for table, name, columns in (
        (result.pairs, "pairs.csv", PAIR_COLUMNS),
        (result.encounters, "encounters.csv", ENCOUNTER_COLUMNS),
    ):
        assert list(table.columns) == list(columns)
        assert not any(map(pd.api.types.is_object_dtype, table.dtypes))  # all typed
        from_file = _typed_csv(sandiego_replay.out_dir / name, table)
        pd.testing.assert_frame_equal(_without_empty_text(table), _without_empty_text(from_file))
    assert len(result.pairs) == len(sandiego_replay.pairs) > 0
    assert len(result.encounters) == len(sandiego_replay.encounters) == 2 * len(result.pairs)
    # Hand-picked: what a notebook filters and sorts on.
    pairs, seats = result.pairs, result.encounters
    assert str(pairs["trigger_utc"].dtype) == "datetime64[us, UTC]"
    assert str(pairs["actual_min_separation_utc"].dtype) == "datetime64[us, UTC]"
    assert pairs["mmsi_a"].dtype == np.int64 and str(pairs["nav_status_a"].dtype) == "Int64"
    assert pairs["cpa_m"].dtype == np.float64 and pairs["data_covers_cpa"].dtype == bool
    assert str(pairs["rule9_applied"].dtype) == "boolean"
    assert set(pairs["situation"].dropna()) <= {"head-on", "crossing", "overtaking"}
    assert set(seats["own_role_final"].dropna()) <= {"give-way", "stand-on"}
    first = sandiego_replay.pairs[0].summary
    assert pairs["trigger_utc"].iloc[0] == first.trigger_utc
    assert pairs["situation"].iloc[0] == (first.situation.value if first.situation else None)


def test_tracks_carry_utc_and_lat_lon_agreeing_with_the_series(
    sandiego_replay: ReplayResult,
) -> None:
    result = colregs9.Replay.of(sandiego_replay)
    tracks = result.tracks
    assert list(tracks.columns) == list(TRACK_COLUMNS)
    assert str(tracks["timestamp"].dtype) == "datetime64[us, UTC]"
    step = pd.Timedelta(seconds=sandiego_replay.manifest["parameters"]["replay"]["step_s"])
    seats = sandiego_replay.encounters
    assert len(tracks) == sum(2 * len(seat.own_track) for seat in seats)
    for seat in seats:
        s = seat.summary
        assert seat.in_run_frame  # San Diego lies in one harbour cell's frame
        for vessel, mmsi in (("own", s.own_mmsi), ("target", s.target_mmsi)):
            track = tracks[
                (tracks["encounter_id"] == s.encounter_id) & (tracks["vessel"] == vessel)
            ]
            assert (track["mmsi"] == mmsi).all() and (track["pair_id"] == s.pair_id).all()
            times = track["timestamp"]
            assert times.iloc[0] == s.start_utc and (times.diff().iloc[1:] == step).all()
            # Where the series runs (trigger to pass), the track is the series.
            at = track.set_index("timestamp").loc[seat.series["timestamp"]]
            for column in ("lat_deg", "lon_deg", "north_m", "east_m"):
                np.testing.assert_array_equal(
                    at[column].to_numpy(), seat.series[f"{vessel}_{column}"].to_numpy()
                )
            trigger = at.loc[s.trigger_utc]
            assert trigger["lat_deg"] == getattr(s, f"{vessel}_lat_deg_at_trigger")
            # The metres are the run frame's projection of the lat/lon.
            north, east = sandiego_replay.frame.to_local(track["lat_deg"], track["lon_deg"])
            np.testing.assert_allclose(north, track["north_m"], atol=1e-6)
            np.testing.assert_allclose(east, track["east_m"], atol=1e-6)


def _empty_run(tmp_path: Path) -> colregs9.Replay:
    """Two vessels on parallel courses about 11 km apart: no encounter."""
    ais = tmp_path / "apart.csv"
    if not ais.exists():
        rows = [
            (f"12/11/2013 12:{m:02d}:00", mmsi, lat, 10.0 + 0.0051 * m, 10.0, 90.0)
            for mmsi, lat in ((219000001, 57.05), (219000002, 57.15))
            for m in range(6)
        ]
        write_dma(ais, rows)
    return colregs9.replay([str(ais)])


def test_a_run_without_encounters_has_empty_typed_tables_and_claims_no_files(
    tmp_path: Path, sandiego_replay: ReplayResult
) -> None:
    result = _empty_run(tmp_path)
    full = colregs9.Replay.of(sandiego_replay)
    for empty, typed in (
        (result.pairs, full.pairs),
        (result.encounters, full.encounters),
        (result.tracks, full.tracks),
    ):
        assert empty.empty
        pd.testing.assert_series_equal(empty.dtypes, typed.dtypes)
    assert "No triggered encounters" in result.text
    assert not re.search(r"\.csv|header|written|wrote", result.text)
    assert result.result.files == ()
    # The command writes its header-only tables and prints the same text.
    written = run_replay([tmp_path / "apart.csv"], out_dir=tmp_path / "out", plots=False)
    assert written.text == result.text
    assert (tmp_path / "out" / "pairs.csv").read_text().count("\n") == 1


# Run in a fresh interpreter: this one has matplotlib's Agg backend (conftest.py) and
# whatever the other tests imported.
SIDE_EFFECTS = """
import gc, logging, os, signal, sys, warnings
import matplotlib
def state():
    return (
        {s: signal.getsignal(s) for s in signal.valid_signals()},
        dict.__getitem__(matplotlib.rcParams, "backend"),
        gc.get_threshold(),
        sys.excepthook,
        list(warnings.filters),
        dict(os.environ),
        list(logging.root.handlers),
    )
before = state()
import colregs9_cli.api
after = state()
names = ["signal handlers", "matplotlib backend", "gc thresholds", "excepthook",
         "warning filters", "environment", "logging handlers"]
changed = [n for n, b, a in zip(names, before, after) if b != a]
assert not changed, changed
assert "matplotlib.pyplot" not in sys.modules
print("unchanged")
"""


def test_importing_the_api_has_no_global_side_effects() -> None:
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    done = subprocess.run(
        [sys.executable, "-c", SIDE_EFFECTS], capture_output=True, text=True, env=env, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "unchanged"


def test_the_side_effect_check_can_fail() -> None:
    """The check above sees a handler installed or a backend chosen on import."""
    for effect in (
        "import signal; signal.signal(signal.SIGTERM, lambda *a: None)",
        "import matplotlib; matplotlib.use('Agg')",
    ):
        script = SIDE_EFFECTS.replace("import colregs9_cli.api", effect)
        done = subprocess.run([sys.executable, "-c", script], capture_output=True, check=False)
        assert done.returncode != 0
