"""The README's Python API example runs as written, and the API writes nothing."""

from __future__ import annotations

import contextlib
import io
import os
import re

import pytest

import colregs9_cli.api as colregs9
from colregs9_cli.errors import ParameterError

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


def test_api_results_match_the_commands() -> None:
    positions = colregs9.read_ais([str(DMA26)])
    assert {"timestamp", "mmsi", "lat_deg", "lon_deg"} <= set(positions.columns)
    table = colregs9.vessel_stats([DMA26], by="ship_type")
    assert "ship_type" in table.columns
    with pytest.raises(ParameterError, match="per is one of"):
        colregs9.vessel_stats([DMA26], per="ship")
