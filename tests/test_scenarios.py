"""The Greenhopper scenarios: they parse, they are physically plausible on the modelled chart,
they trigger the assessment with the target on own ship's port side, and bad scenario files
give one ``Error:`` line through the CLI."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Point
from typer.testing import CliRunner

from colregs9_cli.charts.water import load_chart
from colregs9_cli.cli import app
from colregs9_cli.errors import QueryError
from colregs9_cli.geo import LocalFrame
from colregs9_cli.jobs.scenario import VesselRole, check_scenario_chart, load_scenario
from colregs9_cli.jobs.simulate import simulate
from colregs9_cli.units import knots_to_mps

from fixture_files import MODELLED_CHART, SCENARIOS

NAMES = ("greenhopper_restricted", "greenhopper_not_restricted")


FRAME = LocalFrame.centred_on(57.044196, 57.062865, 9.909933, 9.971545)  # region R


@pytest.fixture(scope="module")
def depth_chart():
    return load_chart([MODELLED_CHART], FRAME)


@pytest.mark.parametrize("name", NAMES)
def test_scenario_parses_with_the_papers_parameters(name: str) -> None:
    scenario = load_scenario(SCENARIOS / f"{name}.toml")
    assert scenario.name == name
    assert (scenario.duration_s, scenario.step_s) == (420.0, 1.0)  # 7.0 min at 1.0 s
    assert scenario.chart == MODELLED_CHART.resolve()
    own = scenario.own
    assert own is not None and own.name == "GREENHOPPER"
    assert (own.length_m, own.draught_m, set(own.speed_kn)) == (11.0, 0.5, {2.0})
    (target,) = [v for v in scenario.vessels if v.role is VesselRole.TARGET]
    assert (target.length_m, target.breadth_m, target.draught_m) == (50.0, 9.0, 5.0)
    assert set(target.speed_kn) == {7.0}


def test_scenarios_differ_only_in_the_targets_route() -> None:
    restricted, free = (load_scenario(SCENARIOS / f"{n}.toml") for n in NAMES)
    assert restricted.own == free.own
    target_a, target_b = restricted.vessels[1], free.vessels[1]
    assert dataclasses.replace(target_a, route=target_b.route) == target_b
    assert target_a.route != target_b.route


@pytest.mark.parametrize("name", NAMES)
def test_every_simulated_position_is_in_navigable_water(name: str, depth_chart) -> None:
    scenario = load_scenario(SCENARIOS / f"{name}.toml")
    check_scenario_chart(scenario)  # waypoints and legs
    for track in simulate(scenario):
        water = depth_chart.navigable_water(track.vessel.draught_m)
        north_m, east_m = FRAME.to_local(track.lat_deg, track.lon_deg)
        outside = [
            t
            for t, n, e in zip(track.time_s, north_m, east_m, strict=True)
            if not water.covers(Point(e, n))
        ]
        assert outside == [], f"{track.vessel.name} out of navigable water at t = {outside[:3]}"


@pytest.mark.parametrize("name", NAMES)
def test_own_route_runs_from_shore_to_shore(name: str, depth_chart) -> None:
    own = load_scenario(SCENARIOS / f"{name}.toml").own
    assert own is not None
    distances_m = []
    for lat, lon in (own.route[0], own.route[-1]):
        north_m, east_m = FRAME.to_local(lat, lon)
        distances_m.append(depth_chart.land.distance(Point(float(east_m), float(north_m))))
    assert all(40.0 <= d <= 100.0 for d in distances_m), distances_m
    start, end = own.route[0], own.route[-1]
    assert end[0] < start[0]  # southbound: from the north (Nørresundby) shore to the south


def _cpa_series(name: str):
    scenario = load_scenario(SCENARIOS / f"{name}.toml")
    own, target = simulate(scenario)
    assert own.vessel.role is VesselRole.OWN

    def velocity(track):
        course_rad = np.radians(track.cog_deg)
        speed_mps = knots_to_mps(track.sog_kn)
        return speed_mps * np.cos(course_rad), speed_mps * np.sin(course_rad)

    own_vn, own_ve = velocity(own)
    target_vn, target_ve = velocity(target)
    rel_n, rel_e = target.north_m - own.north_m, target.east_m - own.east_m
    vel_n, vel_e = target_vn - own_vn, target_ve - own_ve
    tcpa_s = -(rel_n * vel_n + rel_e * vel_e) / (vel_n**2 + vel_e**2)
    cpa_m = np.hypot(rel_n + vel_n * tcpa_s, rel_e + vel_e * tcpa_s)
    bearing_deg = np.degrees(np.arctan2(rel_e, rel_n)) % 360.0
    relative_bearing_deg = (bearing_deg - own.cog_deg) % 360.0
    return own, target, cpa_m, tcpa_s, relative_bearing_deg


@pytest.mark.parametrize(("name", "trigger_s"), [(NAMES[0], 62.0), (NAMES[1], 40.0)])
def test_assessment_triggers_with_the_target_on_the_port_side(name: str, trigger_s: float) -> None:
    own, target, cpa_m, tcpa_s, relative_bearing_deg = _cpa_series(name)
    triggered = np.flatnonzero((tcpa_s >= 0.0) & (tcpa_s <= 180.0) & (cpa_m < 150.0))
    assert triggered.size > 0
    first = triggered[0]
    # the design in colregs9_cli/data/demo/README.md: trigger time, CPA 50–60 m
    assert own.time_s[first] == trigger_s
    assert 40.0 < cpa_m[first] < 70.0
    # port side (relative bearing 180–360°), forward of the overtaking sector, not head-on
    assert 247.5 < relative_bearing_deg[first] < 354.0
    # the CPA comes within the 7 minutes and the vessels pass
    assert own.time_s[first] + tcpa_s[first] < 300.0
    assert (own.sog_kn[: first + 1] == 2.0).all() and (target.sog_kn[: first + 1] == 7.0).all()


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    return path


def _restricted_text() -> str:
    text = (SCENARIOS / "greenhopper_restricted.toml").read_text(encoding="utf-8")
    chart = MODELLED_CHART.resolve().as_posix()
    return text.replace('chart = "aalborg_modelled.geojson"', f'chart = "{chart}"')


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda t: t.replace("duration_s = 420.0\n", ""), "missing key 'duration_s'"),
        (lambda t: t.replace("draught_m = 0.5\n", ""), "missing key 'draught_m'"),
        (lambda t: t.replace("speed_kn = 2.0", "speed_kn = 0.0"), "must be positive"),
        (lambda t: t.replace("nav_status = 0\n", "nav_status = 0\ncolour = 1\n", 1), "'colour'"),
        # own ship's first waypoint moved ashore into Nørresundby
        (lambda t: t.replace("[57.075500, 9.966800]", "[57.065000, 9.925000]"), "waypoint 0"),
        # the target's (5 m draught) first waypoint moved onto own ship's start, in the 4–6 m band
        (lambda t: t.replace("[57.077358, 9.980206]", "[57.075500, 9.966800]"), "MODEL TARGET"),
        (lambda t: t.replace("speed_kn = 7.0", "speed_kn = [7.0, 7.0]"), "speed_kn has 2 values"),
    ],
)
def test_bad_scenarios_give_one_error_line(tmp_path: Path, edit, message: str) -> None:
    text = _restricted_text()
    bad = edit(text)
    assert bad != text
    path = _write(tmp_path, bad)
    result = CliRunner().invoke(app, ["simulate", str(path), "--out", str(tmp_path / "x.csv")])
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert result.exit_code == QueryError.exit_code
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
    assert message in lines[0] and "Traceback" not in result.output
    assert not (tmp_path / "x.csv").exists()


def test_shallow_water_error_names_vessel_and_waypoint(tmp_path: Path) -> None:
    path = _write(
        tmp_path,
        _restricted_text().replace("[57.077358, 9.980206]", "[57.075500, 9.966800]"),
    )
    with pytest.raises(QueryError, match=r"MODEL TARGET.*waypoint 0.*draught 5 m"):
        check_scenario_chart(load_scenario(path))
    # the same water is navigable for own ship's 0.5 m draught
    check_scenario_chart(load_scenario(SCENARIOS / "greenhopper_restricted.toml"))


def test_too_few_waypoints(tmp_path: Path) -> None:
    text = _restricted_text().replace("route = [\n    [57.075500, 9.966800],\n", "route = [\n")
    with pytest.raises(QueryError, match="route has 1 waypoint"):
        load_scenario(_write(tmp_path, text))
