"""The stage tables documented in queries/README.md load, and their values are the defaults."""

from __future__ import annotations

import dataclasses
import re
import tomllib

from colregs9_cli.ais.time_sources import IngestParams
from colregs9_cli.config import dataclass_from_table
from colregs9_cli.core.colregs import ColregsParams, colregs_params_from_table
from colregs9_cli.core.manoeuvrability import ManoeuvrabilityParams
from colregs9_cli.jobs.replay_params import ReplayParams, replay_params_from_table

from fixture_files import ROOT


def _stage_block() -> str:
    text = (ROOT / "queries" / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```toml\n(.*?)```", text, flags=re.DOTALL)
    stage_blocks = [b for b in blocks if "swing_model" in b and "restricted_nav_statuses" in b]
    assert len(stage_blocks) == 1, "queries/README.md must document the stage tables once"
    return stage_blocks[0]


def _documented_tables() -> dict[str, dict[str, object]]:
    return tomllib.loads(_stage_block())


def _commented_out_keys() -> set[str]:
    """Keys shown as ``# name = value``: optional parameters whose default is "not set"."""
    return set(re.findall(r"^# (\w+) = ", _stage_block(), flags=re.MULTILINE))


def test_documented_stage_tables_are_the_defaults() -> None:
    tables = _documented_tables()
    assert set(tables) == {"ingest", "manoeuvrability", "colregs", "replay"}
    where = "queries/README.md"
    assert dataclass_from_table(IngestParams, tables["ingest"], where) == IngestParams()
    assert ManoeuvrabilityParams.from_table(tables["manoeuvrability"], where) == (
        ManoeuvrabilityParams()
    )
    assert colregs_params_from_table(tables["colregs"], where) == ColregsParams()
    assert replay_params_from_table(tables["replay"], where) == ReplayParams()


def test_every_parameter_is_documented() -> None:
    tables = _documented_tables()
    for name, cls in (
        ("manoeuvrability", ManoeuvrabilityParams),
        ("colregs", ColregsParams),
        ("replay", ReplayParams),
        ("ingest", IngestParams),
    ):
        fields = {f.name for f in dataclasses.fields(cls) if f.init}
        unset = {f.name for f in dataclasses.fields(cls) if f.init and f.default is None}
        assert unset <= _commented_out_keys(), f"[{name}]: document {unset} as comments"
        assert set(tables[name]) == fields - unset, (
            f"[{name}] in queries/README.md != {cls.__name__}"
        )
