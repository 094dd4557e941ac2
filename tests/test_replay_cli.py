"""`colregs9 replay` through the CLI: the summary on stdout, and bad input as one `Error:` line."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pandas as pd
import pytest
from typer.testing import CliRunner

from colregs9_cli.cli import app
from colregs9_cli.core.rows import ENCOUNTER_COLUMNS

from fixture_files import NMEA, ROOT

ANNAPOLIS_ENC = ROOT / "fixtures" / "charts" / "noaa_enc_US5MD1MC.000"

DMA_HEADER = (
    "# Timestamp,Type of mobile,MMSI,Latitude,Longitude,Navigational status,ROT,SOG,COG,"
    "Heading,IMO,Callsign,Name,Ship type,Cargo type,Width,Length,"
    "Type of position fixing device,Draught,Destination,ETA,Data source type,A,B,C,D"
)


def write_dma(path: Path, rows: list[tuple[str, int, float, float, float, float]]) -> Path:
    """A DMA 26-column CSV from (time, MMSI, lat, lon, SOG kn, COG deg) tuples."""
    lines = [DMA_HEADER]
    for when, mmsi, lat, lon, sog, cog in rows:
        lines.append(
            f"{when},Class A,{mmsi},{lat:.6f},{lon:.6f},Under way using engine,0,{sog},{cog},"
            f"{round(cog) % 360},Unknown,Unknown,TEST {mmsi},Cargo,,8,30,GPS,3.0,Unknown,,AIS,"
            "20,10,4,4"
        )
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _eastbound(mmsi: int, lat: float, minutes: int = 5) -> list[tuple]:
    # 10 kn east at 57° N: 10 * 1852 / 3600 m/s over 111,320·cos(57°) m per degree.
    deg_per_s = 10 * 1852 / 3600 / (111_320 * 0.5446)
    return [
        (f"12/11/2013 12:{m:02d}:00", mmsi, lat, 10.0 + deg_per_s * 60 * m, 10.0, 90.0)
        for m in range(minutes + 1)
    ]


def _invoke(*args: str):
    return CliRunner().invoke(app, ["replay", *args], terminal_width=120)


def _one_error_line(result) -> str:
    assert "Traceback" not in result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1, result.output
    assert lines[0].startswith("Error: ")
    return lines[0]


def test_replay_prints_a_summary_and_writes_the_reports(tmp_path: Path) -> None:
    result = _invoke(str(NMEA), "--no-plots", "--quiet", "--out", str(tmp_path))
    assert result.exit_code == 0, result.output
    table = pd.read_csv(tmp_path / "encounters.csv")
    # The counts, the pairs by interaction, a header and one line per triggered pair.
    pairs = pd.read_csv(tmp_path / "pairs.csv")
    for pair_id in pairs["pair_id"]:
        assert pair_id in result.output
    assert len(result.output.splitlines()) == len(pairs) + 3
    by_kind = pairs["interaction"].value_counts()
    assert f"{len(pairs)} pairs: {by_kind['encounter']} encounters" in result.output
    assert "24 triggered" in result.output
    assert "Reports in" not in result.output  # --quiet drops the notice
    assert not list((tmp_path / "encounters").glob("*.png"))
    assert len(list((tmp_path / "encounters").glob("*.csv"))) == len(table) == 24


def test_cli_overrides_reach_the_trigger(tmp_path: Path) -> None:
    result = _invoke(str(NMEA), "--no-plots", "--out", str(tmp_path), "--cpa-req-m", "20")
    assert result.exit_code == 0, result.output
    table = pd.read_csv(tmp_path / "encounters.csv")
    assert 0 < len(table) < 24
    assert (table["cpa_m"] < 20).all()


def test_own_mmsi_not_in_the_data(tmp_path: Path) -> None:
    result = _invoke(str(NMEA), "--own-mmsi", "123456789", "--out", str(tmp_path))
    assert result.exit_code == 3
    assert "123456789" in _one_error_line(result)


def test_chart_that_does_not_overlap_the_ais(tmp_path: Path) -> None:
    # A chart of Annapolis, Maryland against AIS of Danish waters.
    result = _invoke(str(NMEA), "--chart", str(ANNAPOLIS_ENC), "--out", str(tmp_path))
    assert result.exit_code == 2
    line = _one_error_line(result)
    assert "does not cover" in line and ANNAPOLIS_ENC.name in line


def test_ais_with_a_single_vessel(tmp_path: Path) -> None:
    ais = write_dma(tmp_path / "one.csv", _eastbound(219000001, 57.05))
    result = _invoke(str(ais), "--out", str(tmp_path / "out"))
    assert result.exit_code == 3
    assert "1 vessel" in _one_error_line(result)
    assert not (tmp_path / "out").exists()


def test_no_encounters_is_not_an_error(tmp_path: Path) -> None:
    # Two vessels on parallel courses 0.1° of latitude (about 11 km) apart never meet.
    ais = write_dma(
        tmp_path / "two.csv", _eastbound(219000001, 57.05) + _eastbound(219000002, 57.15)
    )
    out = tmp_path / "out"
    result = _invoke(str(ais), "--out", str(out))
    assert result.exit_code == 0, result.output
    assert "No triggered encounters" in result.output
    table = pd.read_csv(out / "encounters.csv")
    assert table.empty and list(table.columns) == list(ENCOUNTER_COLUMNS)
    assert (out / "index.md").is_file() and (out / "run.json").is_file()


@pytest.mark.parametrize(
    ("option", "value", "key"),
    [("--cpa-req-m", "-5", "cpa_req_m"), ("--step-s", "0", "step_s"), ("--alpha", "2", "alpha")],
)
def test_out_of_range_parameters(tmp_path: Path, option: str, value: str, key: str) -> None:
    result = _invoke(str(NMEA), option, value, "--out", str(tmp_path))
    assert result.exit_code == 2
    assert key in _one_error_line(result)


def test_a_scratch_directory_that_cannot_be_written_is_one_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Root writes anywhere, so the refusal of the file system is simulated.
    def refuse(*args: object, **kwargs: object) -> None:
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "TemporaryDirectory", refuse)
    result = _invoke(
        str(NMEA), "--no-plots", "--scratch", str(tmp_path), "--out", str(tmp_path / "r")
    )
    assert result.exit_code == 2
    line = _one_error_line(result)
    assert f"--scratch {tmp_path}" in line and "Permission denied" in line
