"""Times outside what AIS can hold (year 9999, before 1980) cost one row each in the ledger,
from every layout, instead of crashing later (pandas' nanosecond times end in 2262)."""

from __future__ import annotations

from pathlib import Path

import pytest

from colregs9_cli.ais.load import load_ais
from colregs9_cli.jobs.replay import run_replay

from fixture_files import DMA26


def _dma_with_year(tmp_path: Path, year: str) -> Path:
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    bad = lines[1].replace("/2024 ", f"/{year} ", 1)
    assert bad != lines[1]
    path = tmp_path / f"year_{year}.csv"
    path.write_text("\n".join([lines[0], bad, *lines[2:]]) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("year", ["9999", "1970", "2100"])
def test_a_csv_time_out_of_range_is_one_unparseable_row(tmp_path: Path, year: str) -> None:
    clean = load_ais([DMA26]).ledger
    data = load_ais([_dma_with_year(tmp_path, year)])
    ledger = data.ledger
    assert ledger.balanced
    assert ledger.rejects["unparseable"] == clean.rejects.get("unparseable", 0) + 1
    assert "lies outside 1980–2099" in ledger.examples["unparseable"][0]
    assert data.positions["timestamp"].dt.year.between(1980, 2099).all()


def _checksum(body: str) -> str:
    value = 0
    for char in body:
        value ^= ord(char)
    return f"{value:02X}"


def test_a_pghp_year_9999_with_a_valid_checksum_is_one_unparseable_row(tmp_path: Path) -> None:
    position = "!AIVDM,1,1,,A,13u?etPv2;0n:dDPwUM1U1Cb069D,0*24"
    lines = []
    for year in ("2013", "9999", "2013"):
        body = f"PGHP,1,{year},11,12,12,0,7,979,219,,2190067,1,00"
        lines += [f"${body}*{_checksum(body)}", position]
    log = tmp_path / "future.nmea"
    log.write_text("\n".join(lines) + "\n", encoding="ascii")
    ledger = load_ais([log], fmt="nmea").ledger
    assert ledger.balanced
    assert ledger.rejects.get("unparseable", 0) == 1


def test_replay_survives_a_time_in_year_9999(tmp_path: Path) -> None:
    result = run_replay([_dma_with_year(tmp_path, "9999")], out_dir=tmp_path / "out", plots=False)
    assert result.manifest["ledger"]["rejects_by_reason"]["unparseable"] >= 1
