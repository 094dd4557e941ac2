"""``colregs9 simulate``: the DMA 26-column layout and kinematically consistent tracks."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from colregs9_cli.ais.layouts import DMA_COLUMNS
from colregs9_cli.cli import app
from colregs9_cli.geo import LocalFrame
from colregs9_cli.jobs.simulate import simulate_scenario
from colregs9_cli.units import knots_to_mps

from fixture_files import DMA26

# A hand-built route: 5.144 m/s (10 kn) north for exactly 85 s (437.3 m), then 5 kn due east
# for 600 m; the second vessel's single leg (300 m at 5 kn, 116.6 s) ends inside the run.
ORIGIN = (57.07, 9.97)
FRAME = LocalFrame(*ORIGIN)
LEG1_M = float(knots_to_mps(10.0)) * 85.0


def _latlon(north_m: float, east_m: float) -> list[float]:
    lat, lon = FRAME.to_geodetic(north_m, east_m)
    return [float(lat), float(lon)]


def _scenario_text(**overrides: str) -> str:
    first = [_latlon(0.0, 0.0), _latlon(LEG1_M, 0.0), _latlon(LEG1_M, 600.0)]
    second = [_latlon(-200.0, 0.0), _latlon(-200.0, 300.0)]
    fields = {
        "name": '"unit"',
        "description": '"hand-built"',
        "start_utc": "2024-09-09T23:59:00Z",
        "duration_s": "180.0",
        "step_s": "1.0",
        "ais_interval_s": "10.0",
    }
    fields.update(overrides)
    head = "".join(f"{k} = {v}\n" for k, v in fields.items())
    return (
        head
        + f"""
[[vessel]]
role = "own"
mmsi = 219000001
name = "FIRST"
callsign = "OZAA1"
ship_type = "Passenger"
nav_status = 0
length_m = 11.0
breadth_m = 4.0
draught_m = 0.5
imo = 9271248
route = {first}
speed_kn = [10.0, 5.0]

[[vessel]]
mmsi = 219000002
name = "SECOND"
callsign = "OZAA2"
ship_type = "Cargo"
nav_status = 3
length_m = 50.0
breadth_m = 9.0
draught_m = 5.0
route = {second}
speed_kn = 5.0
"""
    )


@pytest.fixture()
def simulated(tmp_path: Path) -> tuple[pd.DataFrame, Path]:
    scenario = tmp_path / "unit.toml"
    scenario.write_text(_scenario_text(), encoding="utf-8")
    out = tmp_path / "out.csv"
    result = simulate_scenario(scenario, out)
    assert result.out_path == out and result.rows == 36
    return pd.read_csv(out, dtype=str, keep_default_na=False), out


def test_header_is_the_dma_26_column_layout(simulated) -> None:
    frame, out = simulated
    expected = DMA26.read_text(encoding="utf-8").splitlines()[0]
    assert out.read_text(encoding="utf-8").splitlines()[0] == expected
    assert tuple(frame.columns) == DMA_COLUMNS and len(DMA_COLUMNS) == 26


def test_timestamps_and_row_counts(simulated) -> None:
    frame, _ = simulated
    assert all(re.fullmatch(r"\d\d/\d\d/\d{4} \d\d:\d\d:\d\d", t) for t in frame["# Timestamp"])
    # 180 s every 10 s: 18 reports per vessel, crossing midnight into 10/09/2024
    assert frame.groupby("MMSI").size().to_dict() == {"219000001": 18, "219000002": 18}
    first = frame[frame["MMSI"] == "219000001"]["# Timestamp"].tolist()
    assert first[0] == "09/09/2024 23:59:00" and first[-1] == "10/09/2024 00:01:50"


def test_static_data(simulated) -> None:
    frame, _ = simulated
    for mmsi, length, breadth in (("219000001", 11.0, 4.0), ("219000002", 50.0, 9.0)):
        rows = frame[frame["MMSI"] == mmsi]
        a, b, c, d = (rows[k].astype(float) for k in "ABCD")
        assert ((a + b) == length).all() and ((c + d) == breadth).all()
        assert (rows["Length"].astype(float) == length).all()
        assert (rows["Width"].astype(float) == breadth).all()
    first = frame[frame["MMSI"] == "219000001"].iloc[0]
    second = frame[frame["MMSI"] == "219000002"].iloc[0]
    assert first["IMO"] == "9271248" and second["IMO"] == "Unknown"
    assert first["Navigational status"] == "Under way using engine"
    assert second["Navigational status"] == "Restricted manoeuverability"
    assert set(frame["Type of mobile"]) == {"Class A"} and set(frame["ROT"]) == {"0"}
    assert second["Ship type"] == "Cargo" and second["Draught"] == "5"


def _local(rows: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    return FRAME.to_local(rows["Latitude"].astype(float), rows["Longitude"].astype(float))


def test_speed_and_course_match_the_movement(simulated) -> None:
    frame, _ = simulated
    rows = frame[frame["MMSI"] == "219000001"]
    north, east = _local(rows)
    sog = rows["SOG"].astype(float).to_numpy()
    cog = rows["COG"].astype(float).to_numpy()
    # leg 1 lasts 85 s: reports 0..80 s north at 10 kn, from 90 s east at 5 kn
    assert (sog[:9] == 10.0).all() and (sog[9:] == 5.0).all()
    assert (cog[:9] == 0.0).all() and (cog[9:] == 90.0).all()
    assert rows["Heading"].tolist() == ["0"] * 9 + ["90"] * 9
    step_m = np.hypot(np.diff(north), np.diff(east))
    bearing = np.degrees(np.arctan2(np.diff(east), np.diff(north))) % 360.0
    same_leg = np.r_[np.arange(8), np.arange(9, 17)]
    expected_m = knots_to_mps(sog[same_leg]) * 10.0
    np.testing.assert_allclose(step_m[same_leg], expected_m, atol=0.2)
    diff = (bearing[same_leg] - cog[same_leg] + 180.0) % 360.0 - 180.0
    assert np.abs(diff).max() < 0.5
    # the report at 90 s is 5 s past the turn: 437.3 m north, 5 s x 2.572 m/s east
    assert north[9] == pytest.approx(LEG1_M, abs=0.2)
    assert east[9] == pytest.approx(5.0 * float(knots_to_mps(5.0)), abs=0.2)


def test_vessel_stops_at_the_end_of_her_route(simulated) -> None:
    frame, _ = simulated
    rows = frame[frame["MMSI"] == "219000002"]
    north, east = _local(rows)
    sog = rows["SOG"].astype(float).to_numpy()
    arrival_s = 300.0 / float(knots_to_mps(5.0))  # 116.6 s
    times = np.arange(18) * 10.0
    assert (sog[times < arrival_s] == 5.0).all() and (sog[times >= arrival_s] == 0.0).all()
    assert east[-1] == pytest.approx(300.0, abs=0.2) and north[-1] == pytest.approx(-200.0, abs=0.2)
    assert set(rows["COG"][times >= arrival_s]) == {"90.0"}


def test_cli_writes_the_default_path(tmp_path: Path, monkeypatch) -> None:
    scenario = tmp_path / "unit.toml"
    scenario.write_text(_scenario_text(), encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, ["simulate", str(scenario), "--quiet"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "reports" / "simulate-unit.csv").is_file()
    assert "36 AIS reports" in result.output


@pytest.mark.parametrize(
    ("old", "new", "says"),
    [
        ("    [57.067271, 9.972291],\n", "    [57.075500, 9.966800],\n", "repeats the one before"),
        ("mmsi = 219999002", "mmsi = 999999002", "is not a ship's MMSI"),
    ],
)
def test_a_scenario_no_reader_could_use_is_one_error(
    tmp_path: Path, old: str, new: str, says: str
) -> None:
    from fixture_files import SCENARIOS

    text = (SCENARIOS / "greenhopper_restricted.toml").read_text(encoding="utf-8")
    assert old in text
    scenario = tmp_path / "bad.toml"
    scenario.write_text(text.replace(old, new, 1))
    result = CliRunner().invoke(app, ["simulate", str(scenario), "--out", str(tmp_path / "o.csv")])
    assert result.exit_code == 2, result.output
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith("Error: ") and says in line
