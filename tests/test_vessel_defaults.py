"""Dimensions for vessels that do not report them (vessel_defaults.py)."""

from __future__ import annotations

import math

import pytest

from colregs9_cli.core.vessel_defaults import DIMENSIONS, default_table, vessel_dimensions
from colregs9_cli.errors import ParameterError
from colregs9_cli.jobs.replay_params import ReplayParams


def test_reported_dimensions_are_kept() -> None:
    dims = vessel_dimensions(
        {"length_m": 120.0, "breadth_m": 20.0, "draught_m": 7.5, "mobile_type": "Class A"}
    )
    assert (dims.length_m, dims.breadth_m, dims.draught_m) == (120.0, 20.0, 7.5)
    assert dims.defaulted == () and dims.defaulted_text == "" and dims.basis == ""


@pytest.mark.parametrize(
    ("static", "expected"),
    [
        ({"mobile_type": "Class B", "ship_type": "Sailing"}, (12.0, 3.9, 2.0)),
        ({"mobile_type": "Class B", "ship_type": "pleasure"}, (12.0, 4.0, 1.2)),
        ({"mobile_type": "Class B", "ship_type": "Cargo"}, (12.0, 4.0, 1.5)),
        ({"mobile_type": "Class B"}, (12.0, 4.0, 1.5)),
        ({"mobile_type": "Class A", "ship_type": "Tug"}, (30.0, 10.0, 4.5)),
        ({"mobile_type": "Class A", "ship_type": "Cargo"}, (50.1, 9.2, 3.2)),
        ({}, (50.1, 9.2, 3.2)),
    ],
)
def test_defaults_by_class_and_ship_type(static: dict, expected: tuple) -> None:
    dims = vessel_dimensions(static)
    assert (dims.length_m, dims.breadth_m, dims.draught_m) == expected
    assert dims.defaulted == DIMENSIONS
    assert dims.defaulted_text == "length;breadth;draught"
    assert dims.basis


def test_only_missing_dimensions_are_defaulted_and_named() -> None:
    dims = vessel_dimensions(
        {"mobile_type": "Class B", "ship_type": "Sailing", "length_m": 14.0, "breadth_m": 0.0}
    )
    assert (dims.length_m, dims.breadth_m, dims.draught_m) == (14.0, 3.9, 2.0)
    assert dims.defaulted_text == "breadth;draught"  # 0 is AIS "not available"
    assert vessel_dimensions({"draught_m": math.nan}).defaulted_text == "length;breadth;draught"


def test_query_overrides_replace_the_table() -> None:
    overrides = ReplayParams(default_draught_m=4.5).dimension_defaults
    dims = vessel_dimensions({"mobile_type": "Class B", "length_m": 10.0}, overrides)
    assert (dims.length_m, dims.breadth_m, dims.draught_m) == (10.0, 4.0, 4.5)
    assert "override" in dims.basis


@pytest.mark.parametrize(
    ("name", "value"),
    [
        ("default_length_m", 10_000.0),
        ("default_breadth_m", 1e9),
        ("default_draught_m", 100.0),
        ("default_length_m", 0.0),
    ],
)
def test_query_overrides_beyond_a_ship_are_one_error(name: str, value: float) -> None:
    with pytest.raises(ParameterError, match=f"{name} = {value!r}: give a number above 0"):
        ReplayParams(**{name: value})
    assert ReplayParams(**{name: 20.0 if name != "default_length_m" else 500.0})


def test_the_table_is_complete_and_plausible() -> None:
    table = default_table()
    assert ((table["mobile_type"] == "*") & (table["ship_type"] == "*")).sum() == 1
    assert (table[list(DIMENSIONS)] > 0).all().all()
    assert (table["length_m"] > table["breadth_m"]).all()
    assert (table["breadth_m"] > table["draught_m"]).all()
    class_b = table[table["mobile_type"] == "Class B"]
    assert (class_b["length_m"] < 20.0).all()  # small craft
