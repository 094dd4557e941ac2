"""Scenario files for ``colregs9 simulate``: a strict TOML model and its plausibility check.

A scenario names a start time, a duration, an integration step and an AIS reporting
interval, an optional chart, and ``[[vessel]]`` entries, each with its static data, a
route of waypoints (lat, lon) with a speed per leg and an optional time at which she leaves
her first waypoint (``depart_s``: a ferry at her berth, a ship at anchor). The format is
documented in ``colregs9_cli/data/demo/README.md``. Every key is checked: unknown or missing
keys, wrong types and impossible values raise ``QueryError`` naming the file, the vessel and
the key.

The plausibility check puts every waypoint and every leg of every route in water navigable
for that vessel's draught on the scenario's chart (``charts.water.load_chart(...).navigable_water``:
depth areas with DRVAL1 >= draught, minus land), in the scenario's local frame.
"""

from __future__ import annotations

import datetime as dt
import math
import os
import stat
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from typing import Any

import numpy as np
from shapely.geometry import LineString, Point

from ..charts.water import Chart, load_chart
from ..config import read_toml
from ..errors import QueryError
from ..geo import LocalFrame
from ..query import is_report_name
from ..vessels import MAX_BREADTH_M, MAX_DRAUGHT_M, MAX_LENGTH_M, MMSI_MAX, MMSI_MIN

_SCENARIO_KEYS = {
    "name": str,
    "description": str,
    "start_utc": dt.datetime,
    "duration_s": float,
    "step_s": float,
    "ais_interval_s": float,
    "chart": str,
    "vessel": list,
}
_OPTIONAL_SCENARIO_KEYS = frozenset({"chart"})
_VESSEL_KEYS = {
    "role": str,
    "mmsi": int,
    "name": str,
    "length_m": float,
    "breadth_m": float,
    "draught_m": float,
    "ship_type": str,
    "nav_status": int,
    "callsign": str,
    "imo": int,
    "route": list,
    "speed_kn": object,
    "depart_s": float,
}
_OPTIONAL_VESSEL_KEYS = frozenset({"role", "imo", "depart_s"})
# A vessel's dimensions are held to what ships have, as AIS input is (``ais.clean``), and her
# speed to what AIS can report (SOG 102.2 kn; 102.3 means "not available").
DIMENSION_LIMITS_M = {
    "length_m": MAX_LENGTH_M,
    "breadth_m": MAX_BREADTH_M,
    "draught_m": MAX_DRAUGHT_M,
}
MAX_SPEED_KN = 102.2
# A scenario's times lie in the years AIS data may have (as ingest checks its input).
TIME_MIN = dt.datetime(1980, 1, 1, tzinfo=dt.UTC)
TIME_END = dt.datetime(2100, 1, 1, tzinfo=dt.UTC)


class VesselRole(StrEnum):
    OWN = "own"
    TARGET = "target"


@dataclass(frozen=True)
class VesselSpec:
    """One simulated vessel: static data and a route with one speed per leg. She lies at
    her first waypoint until ``depart_s`` (seconds after the start; 0: she sets off at once,
    ``duration_s`` or more: she never does)."""

    role: VesselRole
    mmsi: int
    name: str
    length_m: float
    breadth_m: float
    draught_m: float
    ship_type: str
    nav_status: int
    callsign: str
    imo: int | None
    route: tuple[tuple[float, float], ...]  # (lat_deg, lon_deg) waypoints
    speed_kn: tuple[float, ...]  # one per leg
    depart_s: float = 0.0

    @property
    def label(self) -> str:
        return f"vessel {self.name!r} (MMSI {self.mmsi})"


@dataclass(frozen=True)
class Scenario:
    """A parsed scenario file. ``chart`` is resolved relative to the scenario file."""

    name: str
    description: str
    start_utc: dt.datetime
    duration_s: float
    step_s: float
    ais_interval_s: float
    chart: Path | None
    vessels: tuple[VesselSpec, ...]
    source: Path

    @property
    def own(self) -> VesselSpec | None:
        owns = [v for v in self.vessels if v.role is VesselRole.OWN]
        return owns[0] if owns else None


def _typed(value: Any, kind: type, where: str, key: str) -> Any:
    if kind is object:
        return value
    if kind is float:
        ok = isinstance(value, int | float) and not isinstance(value, bool)
        if ok and not math.isfinite(float(value)):
            ok = False
        if not ok:
            raise QueryError(f"{where}: key {key!r} = {value!r} is not a number; give a number")
        return float(value)
    if kind is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise QueryError(f"{where}: key {key!r} = {value!r} is not an integer")
        return value
    if kind is dt.datetime:
        if not isinstance(value, dt.datetime) or value.tzinfo is None:
            raise QueryError(
                f"{where}: key {key!r} = {value!r} is not a UTC date-time; "
                "write it like 2024-09-09T12:00:00Z"
            )
        try:
            return value.astimezone(dt.UTC)
        except OverflowError:
            raise QueryError(
                f"{where}: key {key!r} = {value.isoformat()} is beyond the range of times; "
                "give a time between 1980 and 2099"
            ) from None
    if not isinstance(value, kind):
        raise QueryError(f"{where}: key {key!r} = {value!r} is not a {kind.__name__}")
    return value


def _check_keys(
    table: dict[str, Any], allowed: dict[str, type], optional: frozenset[str], where: str
) -> None:
    unknown = sorted(set(table) - set(allowed))
    if unknown:
        raise QueryError(
            f"{where}: unknown key {unknown[0]!r}; allowed keys are {', '.join(sorted(allowed))}"
        )
    missing = [key for key in allowed if key not in table and key not in optional]
    if missing:
        raise QueryError(f"{where}: missing key {missing[0]!r}; add it")


def _positive(value: float, where: str, key: str) -> float:
    if value <= 0.0:
        raise QueryError(f"{where}: key {key!r} = {value!r} must be positive")
    return value


def _route(value: list[Any], where: str) -> tuple[tuple[float, float], ...]:
    points: list[tuple[float, float]] = []
    for index, item in enumerate(value):
        if (
            not isinstance(item, list)
            or len(item) != 2
            or not all(isinstance(c, int | float) and not isinstance(c, bool) for c in item)
        ):
            raise QueryError(
                f"{where}: route waypoint {index} = {item!r} is not a [lat, lon] pair of numbers"
            )
        lat_deg, lon_deg = float(item[0]), float(item[1])
        if not (-90.0 < lat_deg < 90.0 and -180.0 <= lon_deg <= 180.0):
            raise QueryError(
                f"{where}: route waypoint {index} = {item!r} is not a position; give [lat, lon] "
                "in degrees, latitude first"
            )
        if points and points[-1] == (lat_deg, lon_deg):
            raise QueryError(
                f"{where}: route waypoint {index} = {item!r} repeats the one before it; a leg "
                "needs two different waypoints"
            )
        points.append((lat_deg, lon_deg))
    if len(points) < 2:
        raise QueryError(f"{where}: route has {len(points)} waypoint(s); give at least 2")
    return tuple(points)


def _speeds(value: Any, legs: int, where: str) -> tuple[float, ...]:
    raw = value if isinstance(value, list) else [value]
    speeds = tuple(_typed(item, float, where, "speed_kn") for item in raw)
    if len(speeds) == 1:
        speeds = speeds * legs
    if len(speeds) != legs:
        raise QueryError(
            f"{where}: speed_kn has {len(speeds)} values for a route of {legs} legs; "
            "give one speed per leg or one number for all"
        )
    for leg, speed in enumerate(speeds):
        if speed > MAX_SPEED_KN:
            raise QueryError(
                f"{where}: speed_kn = {speed:g} on leg {leg} (waypoint {leg} to {leg + 1}) is "
                f"more than AIS can report ({MAX_SPEED_KN:g} kn); give a ship's speed in knots"
            )
        if speed <= 0.0:
            raise QueryError(
                f"{where}: speed_kn = {speed!r} on leg {leg} (waypoint {leg} to {leg + 1}) "
                "must be positive; a vessel stops at the end of her route, and lies at her "
                "first waypoint until depart_s"
            )
    return speeds


def _vessel(table: Any, index: int, source: Path) -> VesselSpec:
    where = f"{source} [[vessel]] {index}"
    if not isinstance(table, dict):
        raise QueryError(f"{where}: expected a table, got {table!r}")
    if "name" in table and isinstance(table["name"], str):
        where = f"{source} [[vessel]] {index} ({table['name']})"
    _check_keys(table, _VESSEL_KEYS, _OPTIONAL_VESSEL_KEYS, where)
    values = {
        key: _typed(table[key], kind, where, key)
        for key, kind in _VESSEL_KEYS.items()
        if key in table
    }
    role_text = values.get("role", VesselRole.TARGET.value)
    if role_text not in {r.value for r in VesselRole}:
        raise QueryError(f"{where}: key 'role' = {role_text!r}; give 'own' or 'target'")
    if not MMSI_MIN <= values["mmsi"] <= MMSI_MAX:
        # Other MMSIs (base stations, SAR aircraft, AtoN) are no vessel to every reader.
        raise QueryError(
            f"{where}: key 'mmsi' = {values['mmsi']!r} is not a ship's MMSI; give 9 digits "
            f"from {MMSI_MIN} to {MMSI_MAX}"
        )
    for key, limit_m in DIMENSION_LIMITS_M.items():
        _positive(values[key], where, key)
        if values[key] > limit_m:
            raise QueryError(
                f"{where}: key {key!r} = {values[key]:g} m is more than any ship has "
                f"({limit_m:g} m at the most); give a plausible {key.split('_')[0]}"
            )
    if not 0 <= values["nav_status"] <= 15:
        raise QueryError(
            f"{where}: key 'nav_status' = {values['nav_status']!r}; give an ITU code 0–15"
        )
    route = _route(values["route"], where)
    depart_s = values.get("depart_s", 0.0)
    if depart_s < 0.0:
        raise QueryError(
            f"{where}: key 'depart_s' = {depart_s:g} is before the start; give the seconds "
            "after start_utc at which she leaves her first waypoint (0 or more)"
        )
    return VesselSpec(
        role=VesselRole(role_text),
        mmsi=values["mmsi"],
        name=values["name"],
        length_m=values["length_m"],
        breadth_m=values["breadth_m"],
        draught_m=values["draught_m"],
        ship_type=values["ship_type"],
        nav_status=values["nav_status"],
        callsign=values["callsign"],
        imo=values.get("imo"),
        route=route,
        speed_kn=_speeds(values["speed_kn"], len(route) - 1, where),
        depart_s=depart_s,
    )


# The most integration steps a scenario may take (a vessel's arrays hold one row each).
MAX_SCENARIO_STEPS = 1e7


def load_scenario(path: Path) -> Scenario:
    """Parse and validate a scenario TOML file (without the chart check)."""
    table = read_toml(path)
    where = str(path)
    _check_keys(table, _SCENARIO_KEYS, _OPTIONAL_SCENARIO_KEYS, where)
    values = {
        key: _typed(table[key], kind, where, key)
        for key, kind in _SCENARIO_KEYS.items()
        if key in table
    }
    if not is_report_name(values["name"]):
        raise QueryError(
            f"{where}: name = {values['name']!r}; use letters, digits, '_', '-' and '.' "
            "(it names the output files)"
        )
    for key in ("duration_s", "step_s", "ais_interval_s"):
        _positive(values[key], where, key)
    steps = values["duration_s"] / values["step_s"]
    if steps > MAX_SCENARIO_STEPS:
        raise QueryError(
            f"{where}: duration_s / step_s = {steps:.3g} integration steps, more than "
            f"{MAX_SCENARIO_STEPS:.0e}; give a shorter duration_s or a longer step_s"
        )
    start = values["start_utc"]
    if TIME_MIN <= start < TIME_END:  # then the end cannot overflow
        end = start + dt.timedelta(seconds=min(values["duration_s"], 200 * 365.25 * 86_400.0))
    if not (TIME_MIN <= start < TIME_END and end < TIME_END):
        raise QueryError(
            f"{where}: start_utc = {start.isoformat()} and duration_s = "
            f"{values['duration_s']:g} run outside the years 1980 to 2099; give a start_utc "
            "(and duration) within them"
        )
    ratio = values["ais_interval_s"] / values["step_s"]
    if ratio < 1.0 - 1e-9:
        raise QueryError(
            f"{where}: ais_interval_s = {values['ais_interval_s']} is shorter than step_s = "
            f"{values['step_s']}; reports are emitted at integration steps"
        )
    if abs(ratio - round(ratio)) > 1e-9:
        raise QueryError(
            f"{where}: ais_interval_s = {values['ais_interval_s']} is not a multiple of "
            f"step_s = {values['step_s']}; reports are emitted at integration steps"
        )
    vessels = tuple(_vessel(item, index, path) for index, item in enumerate(values["vessel"]))
    if not vessels:
        raise QueryError(f"{where}: no [[vessel]] entries; add at least one")
    mmsis = [v.mmsi for v in vessels]
    duplicated = sorted({m for m in mmsis if mmsis.count(m) > 1})
    if duplicated:
        raise QueryError(f"{where}: MMSI {duplicated[0]} is used by two vessels; give each its own")
    if sum(v.role is VesselRole.OWN for v in vessels) > 1:
        raise QueryError(f"{where}: more than one vessel has role = 'own'; give at most one")
    chart = _chart_path(path, values["chart"]) if "chart" in values else None
    return Scenario(
        name=values["name"],
        description=values["description"],
        start_utc=values["start_utc"],
        duration_s=values["duration_s"],
        step_s=values["step_s"],
        ais_interval_s=values["ais_interval_s"],
        chart=chart,
        vessels=vessels,
        source=path,
    )


def _chart_path(path: Path, relative: str) -> Path:
    """The scenario's chart, relative to its file. realpath leaves a symbolic link that loops
    as it is (``Path.resolve`` raises), so that ``stat`` reports it."""
    where = str(path)
    chart = Path(os.path.realpath(path.parent / relative))
    try:
        mode = chart.stat().st_mode
    except FileNotFoundError:
        return chart  # said where the chart is read, with the other chart errors
    except OSError as exc:
        raise QueryError(
            f"{where}: chart = {relative!r}: {exc.strerror}; give the path of a chart file"
        ) from None
    if not stat.S_ISREG(mode):
        what = "a directory, not a file" if stat.S_ISDIR(mode) else "not a regular file"
        raise QueryError(
            f"{where}: chart = {relative!r} is {chart}, {what}; give the chart file (S-57 "
            ".000, GeoJSON or GeoPackage)"
        )
    return chart


def scenario_frame(scenario: Scenario) -> LocalFrame:
    """The scenario's local frame, centred on the extent of every vessel's waypoints."""
    lats = [lat for v in scenario.vessels for lat, _ in v.route]
    lons = [lon for v in scenario.vessels for _, lon in v.route]
    return LocalFrame.centred_on(min(lats), max(lats), min(lons), max(lons))


def check_routes_navigable(scenario: Scenario, chart: Chart) -> None:
    """Every waypoint and leg of every vessel in water navigable for her draught."""
    for vessel in scenario.vessels:
        water = chart.navigable_water(vessel.draught_m)
        lats, lons = zip(*vessel.route, strict=True)
        north_m, east_m = chart.frame.to_local(np.array(lats), np.array(lons))
        for index, (lat_deg, lon_deg) in enumerate(vessel.route):
            if not water.covers(Point(east_m[index], north_m[index])):
                raise QueryError(
                    f"{scenario.source}: {vessel.label}: waypoint {index} [{lat_deg}, {lon_deg}] "
                    f"is on land or in water shallower than her draught {vessel.draught_m:g} m "
                    "on the chart; move it into navigable water"
                )
        for index in range(len(vessel.route) - 1):
            leg = LineString(
                [(east_m[index], north_m[index]), (east_m[index + 1], north_m[index + 1])]
            )
            if not water.covers(leg):
                raise QueryError(
                    f"{scenario.source}: {vessel.label}: the leg from waypoint {index} to "
                    f"{index + 1} crosses land or water shallower than her draught "
                    f"{vessel.draught_m:g} m on the chart; add a waypoint to route it through "
                    "navigable water"
                )


def check_scenario_chart(scenario: Scenario) -> None:
    """The plausibility check against the scenario's chart; no chart, no check."""
    if scenario.chart is not None:
        check_routes_navigable(scenario, load_chart([scenario.chart], scenario_frame(scenario)))
