"""Dimensions for vessels that do not report them (docs/design.md §5, "Missing dimensions").

A vessel without an AIS length, breadth or draught takes, for each missing dimension, the
value of the first row of ``data/default_dimensions.csv`` that matches what AIS does say: her
mobile type (Class A or B) and ship type, then her mobile type with any ship type, then
neither. The paper's Table 1 means (50.1 m, 9.2 m, 3.2 m) fit a Class A merchant vessel, not a
Class B pleasure craft, so small craft take small-craft values. A query may override a
dimension for every vessel (``[replay] default_length_m`` …). Every dimension that was
defaulted is named in ``VesselDimensions.defaulted``, so that a verdict that rests on it is
flagged.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from importlib import resources
from typing import Any

import pandas as pd

from ..vessels import DIMENSIONS, MAX_BREADTH_M, MAX_DRAUGHT_M, MAX_LENGTH_M

ANY = "*"


@dataclass(frozen=True)
class VesselDimensions:
    """A vessel's dimensions for the estimator; ``defaulted`` names those not from AIS."""

    length_m: float
    breadth_m: float
    draught_m: float
    defaulted: tuple[str, ...]
    basis: str  # the table row (or override) the defaults came from; empty when none

    @property
    def defaulted_text(self) -> str:
        """E.g. ``draught`` or ``length;breadth;draught``; empty when AIS gave all three."""
        return ";".join(name.removesuffix("_m") for name in self.defaulted)


@functools.cache
def default_table() -> pd.DataFrame:
    """The documented table (package data), in lookup order."""
    path = resources.files("colregs9_cli").joinpath("data/default_dimensions.csv")
    with path.open("rb") as handle:
        return pd.read_csv(handle, keep_default_na=False)


def _table_row(mobile_type: str | None, ship_type: str | None) -> pd.Series:
    table = default_table()
    mobile = (mobile_type or "").strip()
    ship = (ship_type or "").strip().casefold()
    for wanted_mobile, wanted_ship in ((mobile, ship), (mobile, ANY), (ANY, ANY)):
        rows = table[
            (table["mobile_type"] == wanted_mobile)
            & (table["ship_type"].str.casefold() == wanted_ship)
        ]
        if len(rows):
            return rows.iloc[0]
    raise LookupError("data/default_dimensions.csv has no '*,*' row")


@dataclass(frozen=True)
class DimensionDefaults:
    """Values that replace the table for every vessel that does not report a dimension (the
    ``[replay]`` keys ``default_length_m``, ``default_breadth_m``, ``default_draught_m``);
    ``None``: take the table's value by mobile type and ship type."""

    length_m: float | None = None
    breadth_m: float | None = None
    draught_m: float | None = None

    def get(self, name: str) -> float | None:
        """The override of dimension ``name`` (``length_m`` …), if any."""
        value: float | None = getattr(self, name)
        return value


_LIMITS_M = {"length_m": MAX_LENGTH_M, "breadth_m": MAX_BREADTH_M, "draught_m": MAX_DRAUGHT_M}


def _reported(name: str, value: Any) -> float | None:
    """A usable AIS dimension, or None (missing, zero, negative, not finite or beyond what a
    ship has: ``ais.clean``'s limits)."""
    if value is None or pd.isna(value):
        return None
    number = float(value)
    return number if math.isfinite(number) and 0.0 < number <= _LIMITS_M[name] else None


def vessel_dimensions(
    static: dict[str, Any], overrides: DimensionDefaults | None = None
) -> VesselDimensions:
    """Dimensions of one vessel from her static AIS (``length_m``, ``breadth_m``,
    ``draught_m``, ``ship_type``, ``mobile_type``; any may be missing).

    ``overrides`` give values that replace the table for every vessel that does not report
    a dimension (``None``: use the table).
    """
    given = {name: _reported(name, static.get(name)) for name in DIMENSIONS}
    missing = tuple(name for name, value in given.items() if value is None)
    row = _table_row(_text(static.get("mobile_type")), _text(static.get("ship_type")))
    overrides = overrides or DimensionDefaults()
    values: dict[str, float] = {}
    for name in DIMENSIONS:
        reported, override = given[name], overrides.get(name)
        values[name] = (
            reported if reported is not None else override if override is not None else row[name]
        )
    if not missing:
        basis = ""
    elif any(overrides.get(name) is not None for name in missing):
        basis = "[replay] default_* override, else the table"
    else:
        basis = f"{row['mobile_type']} / {row['ship_type']}: {row['basis']}"
    return VesselDimensions(
        float(values["length_m"]),
        float(values["breadth_m"]),
        float(values["draught_m"]),
        missing,
        basis,
    )


def _text(value: Any) -> str | None:
    return None if value is None or (isinstance(value, float) and math.isnan(value)) else str(value)
