"""Non-finite and impossible dimensions (``inf``, ``1e400``, a 900 m ship) are "not
available": never in the statistics, never an error in the replay."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from colregs9_cli.ais.load import load_ais
from colregs9_cli.replay import run_replay
from colregs9_cli.stats import run_stats
from colregs9_cli.vessel_defaults import vessel_dimensions

from fixture_files import DMA26


def _with_length(tmp_path: Path, value: str) -> Path:
    lines = DMA26.read_text(encoding="utf-8").splitlines()
    header = lines[0].lstrip("# ").split(",")
    column = header.index("Length")
    a_column = header.index("A")
    rows = []
    for line in lines[1:]:
        fields = line.split(",")
        fields[column] = value
        fields[a_column] = ""  # the length comes from the Length column, not A+B
        rows.append(",".join(fields))
    path = tmp_path / f"length_{value}.csv"
    path.write_text("\n".join([lines[0], *rows]) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("value", ["inf", "1e400", "-inf", "900", "nan"])
def test_an_impossible_length_is_not_available(tmp_path: Path, value: str) -> None:
    path = _with_length(tmp_path, value)
    data = load_ais([path])
    assert data.ledger.balanced
    lengths = data.positions["length_m"].to_numpy(dtype=float)
    assert not np.isfinite(lengths).any()
    assert (data.dimension_reports["length_m"].dropna() <= 500.0).all()
    table = run_stats([path], out_dir=tmp_path / "stats").result.to_frame()
    counts = table.set_index("dimension")["count"]
    assert counts["length_m"] == 0  # no length is left, and nothing crashed on one
    assert counts["breadth_m"] > 0
    run_replay([path], out_dir=tmp_path / "replay", plots=False)


def test_vessel_defaults_replace_an_impossible_value() -> None:
    dims = vessel_dimensions({"length_m": 1e400, "breadth_m": 90.0, "draught_m": 5.0})
    assert dims.defaulted == ("length_m", "breadth_m")
    assert dims.draught_m == 5.0


@pytest.mark.parametrize("mmsi", ["12345678901234567890", "1e30", "-99999999999999999999"])
def test_an_mmsi_too_long_for_any_vessel_is_invalid_without_a_warning(
    tmp_path: Path, mmsi: str
) -> None:
    import warnings

    lines = DMA26.read_text(encoding="utf-8").splitlines()
    lines[1] = lines[1].replace("257739000", mmsi)
    path = tmp_path / "long_mmsi.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        data = load_ais([path])
    assert data.ledger.balanced
    assert data.ledger.to_dict()["rejects_by_reason"].get("invalid_mmsi", 0) >= 1
