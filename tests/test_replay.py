"""`replay.py` end to end: the real national NMEA sample (no chart) and a synthetic crossing
with a chart where the target is restricted (D3 → D4).

The CPA/TCPA checks recompute every encounter from the two vessels' raw reports around the
trigger with plain numpy/pyproj (decoded by the NMEA reader, not by the replay pipeline):
position linear in time between the bracketing reports, SOG linear, COG along the shorter
arc (docs/design.md §5, written out by hand), the velocity turned from true
to grid north by projecting a 1 m step along the COG (pyproj Geod), then
``TCPA = −p·v/|v|²``, ``CPA = |p + v·TCPA|``.
"""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from pyproj import Geod, Transformer

from colregs9_cli.ais.ledger import RejectsLedger
from colregs9_cli.ais.nmea import read_nmea
from colregs9_cli.charts.water import load_chart
from colregs9_cli.core.manoeuvrability import (
    RestrictionPolicy,
    SwingModel,
    target_rate_of_swing_deg_per_m,
    verdict,
)
from colregs9_cli.core.passing import opening_threshold_m
from colregs9_cli.core.rows import ENCOUNTER_COLUMNS, PAIR_COLUMNS
from colregs9_cli.errors import ParameterError
from colregs9_cli.jobs.replay import run_params, run_replay
from colregs9_cli.jobs.replay_params import ReplayParams
from colregs9_cli.jobs.simulate import simulate_scenario
from colregs9_cli.query import everything_query

from fixture_files import GREENHOPPER_QUERY, MODELLED_CHART, NMEA, SCENARIOS
from seat_checks import assert_seats_agree

KNOT_MPS = 1852.0 / 3600.0
GEOD = Geod(ellps="WGS84")

# The replay pipeline finds 12 close-quarters pairs in the sample, each reported from both
# sides. Every one of them is re-checked by hand below (CPA < 150 m, 0 <= TCPA <= 180 s).
# (With times floored to the second there were 13: a second encounter of 211440340 and
# 211457700 came out at CPA 149.9 m, which the millisecond times put above 150 m.)
NATIONAL_TRIGGERED = 24
# 24,688 vessel positions (fixtures/SOURCES.md), before duplicates and speed jumps.
NATIONAL_POSITIONS = 24_688


@pytest.fixture(scope="module")
def national(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("national")
    return run_replay([NMEA], out_dir=out, plots=False)


@pytest.fixture(scope="module")
def raw_reports() -> pd.DataFrame:
    with gzip.open(NMEA, "rt", encoding="ascii", errors="replace") as handle:
        batch = next(read_nmea(handle, NMEA.name, RejectsLedger()))
    return batch.positions.to_pandas()


def _state_at(reports: pd.DataFrame, when: pd.Timestamp, to_grid: Transformer) -> np.ndarray:
    """(north, east, v_north, v_east) of one vessel at ``when`` from its bracketing reports."""
    reports = reports.drop_duplicates("timestamp").sort_values("timestamp")
    before = reports[reports["timestamp"] <= when].iloc[-1]
    after = reports[reports["timestamp"] >= when].iloc[0]
    span = (after["timestamp"] - before["timestamp"]).total_seconds()
    w = 0.0 if span == 0 else (when - before["timestamp"]).total_seconds() / span
    e0, n0 = to_grid.transform(before["lon_deg"], before["lat_deg"])
    e1, n1 = to_grid.transform(after["lon_deg"], after["lat_deg"])
    sog_mps = (before["sog_kn"] + w * (after["sog_kn"] - before["sog_kn"])) * KNOT_MPS
    turn = (after["cog_deg"] - before["cog_deg"] + 180.0) % 360.0 - 180.0
    north, east = n0 + w * (n1 - n0), e0 + w * (e1 - e0)
    lon, lat = to_grid.transform(east, north, direction="INVERSE")
    ahead_lon, ahead_lat, _ = GEOD.fwd(lon, lat, before["cog_deg"] + w * turn, 1.0)
    ahead_e, ahead_n = to_grid.transform(ahead_lon, ahead_lat)
    grid_cog_rad = np.arctan2(ahead_e - east, ahead_n - north)
    return np.array([north, east, sog_mps * np.cos(grid_cog_rad), sog_mps * np.sin(grid_cog_rad)])


def _hand_cpa(
    raw: pd.DataFrame, own: int, target: int, when: pd.Timestamp, lat0: float, lon0: float
) -> tuple[float, float, float]:
    to_grid = Transformer.from_crs(
        "EPSG:4326",
        f"+proj=tmerc +lat_0={lat0} +lon_0={lon0} +ellps=WGS84 +units=m",
        always_xy=True,
    )
    a = _state_at(raw[raw["mmsi"] == own], when, to_grid)
    b = _state_at(raw[raw["mmsi"] == target], when, to_grid)
    p, v = b[:2] - a[:2], b[2:] - a[2:]
    tcpa = -float(p @ v) / float(v @ v)
    return float(np.hypot(*p)), float(np.hypot(*(p + v * tcpa))), tcpa


TEXT_COLUMNS = {
    name: str
    for name in (
        "target_estimated_restricted",
        "own_estimated_restricted",
        "give_way_vessels",
        "give_way_vessel_acted",
        "stand_on_vessel_kept_course",
        "give_way_action",
        "action_before_cpa_s",
        "deciding_rule",
        "own_dimensions_defaulted",
        "target_dimensions_defaulted",
    )
}


def _encounters(result) -> pd.DataFrame:
    # Three-valued and list columns stay text even when a run has only one kind of value.
    return pd.read_csv(result.out_dir / "encounters.csv", dtype=TEXT_COLUMNS)


def _pairs(result) -> pd.DataFrame:
    return pd.read_csv(result.out_dir / "pairs.csv", dtype=str, keep_default_na=False)


def test_national_sample_finds_the_close_quarters_pairs(national) -> None:
    table = _encounters(national)
    assert national.counts.triggered == NATIONAL_TRIGGERED
    assert len(table) == NATIONAL_TRIGGERED
    assert list(table.columns) == list(ENCOUNTER_COLUMNS)
    # Without --own-mmsi every pair is reported from both seats, with the same geometry.
    mirrored = table.merge(
        table,
        left_on=["own_mmsi", "target_mmsi", "trigger_utc"],
        right_on=["target_mmsi", "own_mmsi", "trigger_utc"],
        suffixes=("", "_other"),
    )
    assert len(mirrored) == NATIONAL_TRIGGERED
    np.testing.assert_allclose(mirrored["cpa_m"], mirrored["cpa_m_other"], atol=1e-6)
    assert (table["cpa_m"] < 150.0).all()
    assert table["tcpa_s"].between(0.0, 180.0).all()


def test_national_sample_has_no_chart_so_manoeuvrability_is_unknown(national) -> None:
    table = _encounters(national)
    table = table[table["interaction"] == "encounter"]
    assert (table["target_estimated_restricted"] == "unknown").all()
    assert (table["own_estimated_restricted"] == "unknown").all()
    # Unknown is ¬d3: G_d reaches D4 only from a reported restricted status (d2).
    gives_way = table["target_role_colregs"] == "give-way"
    assert set(table.loc[gives_way, "automaton_path"]) <= {"D1>D2>D3>D1", "D1>D2>D4"}
    assert (table.loc[~gives_way, "automaton_path"] == "D1>D1").all()
    assert not table["rule9_applied"].any()
    verdicts = json.loads((national.out_dir / "run.json").read_text())["verdicts"]
    assert verdicts["estimated_restricted"] == {"unknown": len(table)}
    assert verdicts["pairs"] == NATIONAL_TRIGGERED // 2
    assert verdicts["encounters"] == len(table) // 2
    assert sum(verdicts["interaction"].values()) == NATIONAL_TRIGGERED // 2


def test_national_sample_seats_agree(national) -> None:
    table = _encounters(national)
    assert assert_seats_agree(table) == NATIONAL_TRIGGERED // 2
    pairs = _pairs(national)
    assert list(pairs.columns) == list(PAIR_COLUMNS)
    assert len(pairs) == NATIONAL_TRIGGERED // 2
    assert set(pairs["pair_id"]) == set(table["pair_id"])
    # Two pairs that once got contradictory roles (bearings 353.9°/352.5° and 31.4°/10.0°)
    # at their triggers: two vessels at rest in the Kiel Canal, one of them reporting
    # 0.7–1.8 kn while her fixes moved 5 m, are no encounter at all ...
    by_pair = pairs.set_index(["mmsi_a", "mmsi_b"])
    canal = by_pair.loc[("211440340", "211457700")]
    assert canal["interaction"] == "not-making-way"
    assert canal["situation"] == canal["give_way_vessels"] == ""
    # ... and the Helsingør ferries, one at her berth at the trigger, are judged once both
    # are under way: meeting nearly end on, each gives way (rule 14(c)).
    ferries = by_pair.loc[("219230000", "219622000")]
    assert ferries["interaction"] == "encounter"
    assert ferries["interaction_basis"].startswith("judged from 12:01:09, both under way")
    assert (ferries["situation"], ferries["situation_basis"]) == ("head-on", "head-on in doubt")
    assert ferries["give_way_vessels"] == "219230000;219622000"


def test_no_audit_fact_is_judged_on_data_that_stops(national) -> None:
    table = _encounters(national)
    stops = ~table["data_covers_cpa"]
    assert stops.any() and (~stops).any()
    # The least range so far is observed; the closest approach may lie past the data.
    stopped = table[stops]
    assert (stopped["actual_min_separation_m"] <= stopped["range_m_at_trigger"] + 1e-6).all()
    for column in ("give_way_vessel_acted", "stand_on_vessel_kept_course"):
        judged = table.loc[stops, column].dropna()
        assert (judged == "insufficient-data").all(), column
    assert table.loc[~stops, "actual_min_separation_m"].notna().all()
    assert set(table["give_way_vessel_acted"].dropna()) <= {"true", "false", "insufficient-data"}
    for outcome in national.encounters:
        summary = outcome.summary
        if not summary.data_covers_cpa and summary.give_way_action is not None:
            assert set(summary.give_way_action.split(";")) == {"insufficient-data"}
            assert summary.action_before_cpa_s.strip(";") == ""


def test_national_cpa_by_hand(national, raw_reports: pd.DataFrame) -> None:
    frame = json.loads((national.out_dir / "run.json").read_text())["frame"]
    table = _encounters(national)
    for row in table.itertuples():
        when = pd.Timestamp(row.trigger_utc)
        range_m, cpa_m, tcpa_s = _hand_cpa(
            raw_reports, row.own_mmsi, row.target_mmsi, when, frame["lat0_deg"], frame["lon0_deg"]
        )
        assert row.range_m_at_trigger == pytest.approx(range_m, abs=0.5)
        assert row.cpa_m == pytest.approx(cpa_m, abs=0.5)
        assert row.tcpa_s == pytest.approx(tcpa_s, abs=0.5)


def test_national_cpa_in_a_frame_centred_on_the_pair(national, raw_reports) -> None:
    # The run's frame is centred on the whole of Denmark. Far from its central meridian grid
    # north differs from true north (meridian convergence, up to ~2° here), so the replay turns
    # the true COGs to grid north before building velocities. The CPA must then not depend on
    # the frame: against a frame centred on the pair the only difference left is the
    # projection's scale factor (< 4e-4 of a distance within Denmark: 0.02 m on these CPAs).
    # Without the turn the pair 234607000/636092297 at 1.6 km range had CPA 13.8 m in the
    # national frame against 66.6 m centred on the pair.
    frame = json.loads((national.out_dir / "run.json").read_text())["frame"]
    table = _encounters(national)
    assert len(table) == NATIONAL_TRIGGERED
    # Pairs lie up to 1.8° of longitude from the frame's central meridian (9.42° to 12.69° E).
    first_reports = raw_reports.drop_duplicates("mmsi").set_index("mmsi")
    own_lon = first_reports.loc[table["own_mmsi"], "lon_deg"]
    assert (own_lon - frame["lon0_deg"]).abs().max() > 1.5
    for row in table.itertuples():
        own = raw_reports[raw_reports["mmsi"] == row.own_mmsi].iloc[0]
        _, cpa_m, _ = _hand_cpa(
            raw_reports,
            row.own_mmsi,
            row.target_mmsi,
            pd.Timestamp(row.trigger_utc),
            own["lat_deg"],
            own["lon_deg"],
        )
        assert row.cpa_m == pytest.approx(cpa_m, abs=0.1)


def test_national_time_series_runs_from_the_trigger_until_the_pass(national) -> None:
    for outcome in national.encounters:
        series = outcome.series
        summary = outcome.summary
        assert series["timestamp"].iloc[0] == summary.trigger_utc
        # to the pass: the first step at which the range has opened clearly past its least
        # value so far (core/passing.py), when the data reach it
        ranges = series["range_m"].to_numpy()
        least = np.minimum.accumulate(ranges)
        opened = ranges > opening_threshold_m(least, national.params.passing)
        assert not opened[:-1].any()
        assert opened[-1] == summary.data_covers_cpa
        assert (np.diff(series["step"]) == 1).all()
        follow_s = summary.tcpa_s + national.params.passing.follow_s + 1
        assert series["timestamp"].iloc[-1] <= summary.trigger_utc + pd.Timedelta(seconds=follow_s)
        if summary.actual_min_separation_m is not None:
            assert summary.actual_min_separation_m == pytest.approx(ranges.min())
        if summary.situation is None:
            # not an encounter: the series keeps its geometry, without a verdict
            assert series["situation"].isna().all() and series["automaton_path"].isna().all()
            continue
        assert series["automaton_path"].iloc[0] == summary.automaton_path
        # the situation is held from where it was read (the trigger, or the first step with
        # both courses reported); the instantaneous one may change
        assert (series["situation"] == summary.situation.value).all()
        read_at = pd.to_datetime(series["timestamp"], utc=True) == summary.situation_utc
        assert read_at.sum() == 1
        assert series.loc[read_at, "situation_now"].iloc[0] == summary.situation.value
        if summary.data_covers_cpa:
            # the audit's closest approach is a row of the series
            closest = series["range_m"].idxmin()
            assert summary.actual_min_separation_m == series["range_m"][closest]
            assert summary.actual_min_separation_utc == series["timestamp"][closest]


def test_national_ledger_counts_track_drops(national, raw_reports: pd.DataFrame) -> None:
    manifest = json.loads((national.out_dir / "run.json").read_text())
    ledger = manifest["ledger"]
    assert manifest["ledger_balanced"]
    assert ledger["rows_read"] == (
        ledger["rows_used"] + ledger["rows_outside_query"] + ledger["rows_rejected"]
    )
    # The loader drops invalid MMSIs (not nine digits with a MID in 201–775) and rows equal in
    # every column; segmentation then drops a vessel's second, different report in the same
    # second. Counted here from the raw decoded reports.
    assert len(raw_reports) == NATIONAL_POSITIONS
    valid = raw_reports[raw_reports["mmsi"].between(201_000_000, 775_999_999)]
    distinct = valid.drop_duplicates()
    same_second = int(distinct.duplicated(["mmsi", "timestamp"]).sum())
    tracks = manifest["tracks"]
    assert tracks["reports_in"] == len(distinct)
    assert tracks["same_time_dropped"] == same_second
    assert tracks["reports_used"] == len(distinct) - same_second - tracks["speed_jump_dropped"]
    duplicates = len(valid) - len(distinct) + same_second
    assert ledger["rejects_by_reason"].get("duplicate", 0) == duplicates
    assert ledger["rejects_by_reason"]["speed_jump"] == tracks["speed_jump_dropped"]


def test_own_mmsi_takes_the_own_ship_seat_only(tmp_path: Path) -> None:
    result = run_replay([NMEA], own_mmsi=[211356520], out_dir=tmp_path, plots=False)
    table = _encounters(result)
    assert set(table["own_mmsi"]) == {211356520}
    assert list(table["target_mmsi"]) == [211558470]
    # The target crosses from own ship's port side: own ship stands on, the target gives way.
    row = table.iloc[0]
    assert (row["situation"], row["own_role_colregs"], row["give_way_vessel"]) == (
        "crossing",
        "stand-on",
        "target",
    )


def test_overrides_replace_the_query_values_and_are_validated() -> None:
    params = run_params(
        everything_query(), overrides={"replay": {"cpa_req_m": 50.0, "tcpa_act_s": None}}
    )
    assert params.replay.cpa_req_m == 50.0
    assert params.replay.tcpa_act_s == ReplayParams().tcpa_act_s
    with pytest.raises(ParameterError, match="cpa_req_m"):
        run_params(everything_query(), overrides={"replay": {"cpa_req_m": -1.0}})


def test_a_stricter_trigger_finds_fewer_encounters(tmp_path: Path) -> None:
    result = run_replay(
        [NMEA], out_dir=tmp_path, plots=False, overrides={"replay": {"cpa_req_m": 20.0}}
    )
    table = _encounters(result)
    assert 0 < len(table) < NATIONAL_TRIGGERED
    assert (table["cpa_m"] < 20.0).all()


GREENHOPPER, TARGET = 219999001, 219999002


def _greenhopper(tmp_path_factory: pytest.TempPathFactory, scenario: str):
    work = tmp_path_factory.mktemp(scenario)
    simulated = simulate_scenario(SCENARIOS / f"{scenario}.toml", out=work / "ais.csv")
    return run_replay(
        [simulated.out_path],
        chart_paths=[MODELLED_CHART],
        query_path=GREENHOPPER_QUERY,
        out_dir=work / "replay",
        plots=False,
    )


@pytest.fixture(scope="module")
def restricted(tmp_path_factory: pytest.TempPathFactory):
    return _greenhopper(tmp_path_factory, "greenhopper_restricted")


@pytest.fixture(scope="module")
def not_restricted(tmp_path_factory: pytest.TempPathFactory):
    return _greenhopper(tmp_path_factory, "greenhopper_not_restricted")


def _seat(result, own_mmsi: int):
    (outcome,) = [o for o in result.encounters if o.summary.own_mmsi == own_mmsi]
    return outcome


VERDICT_COLUMNS = [
    "situation",
    "own_role_colregs",
    "target_estimated_restricted",
    "rule9_applied",
    "own_role_final",
    "automaton_path",
]


def test_restricted_crossing_goes_through_d3_to_d4(restricted) -> None:
    table = _encounters(restricted).set_index("own_mmsi")
    assert table.loc[GREENHOPPER, VERDICT_COLUMNS].tolist() == [
        "crossing",
        "stand-on",
        "true",
        True,
        "give-way",
        "D1>D2>D3>D4",
    ]
    row = table.loc[GREENHOPPER]
    assert (row["target_length_m"], row["target_breadth_m"], row["target_draught_m"]) == (
        50.0,
        9.0,
        5.0,
    )
    assert pd.isna(row["target_dimensions_defaulted"])  # all three from AIS
    assert not row["target_reports_restricted"]  # nav status 0: d3, not d2, decides
    assert row["give_way_vessel"] == "own"
    assert row["cpa_m"] < 150.0 and 0.0 <= row["tcpa_s"] <= 180.0
    # From the target's seat the Greenhopper is on her starboard side: she gives way anyway.
    assert table.loc[TARGET, ["own_role_colregs", "automaton_path"]].tolist() == [
        "give-way",
        "D1>D1",
    ]


def test_unrestricted_crossing_returns_to_d1(not_restricted) -> None:
    table = _encounters(not_restricted).set_index("own_mmsi")
    assert table.loc[GREENHOPPER, VERDICT_COLUMNS].tolist() == [
        "crossing",
        "stand-on",
        "false",
        False,
        "stand-on",
        "D1>D2>D3>D1",
    ]


def test_trigger_estimate_matches_the_chart(restricted) -> None:
    # Each red (restricted) ellipse is the one not inside the 5 m water, checked with shapely.
    outcome = _seat(restricted, GREENHOPPER)
    assessment = outcome.assessment
    water = load_chart([MODELLED_CHART], restricted.frame).navigable_water(5.0, 0.0)
    inside = np.array([water.contains(ellipse) for ellipse in assessment.ellipses])
    np.testing.assert_array_equal(assessment.restricted, ~inside)
    assert assessment.restricted.any() and assessment.covered.all()
    trigger = outcome.series.iloc[0]
    assert assessment.north_m[0] != trigger["target_north_m"] or assessment.step[0] > 0


def test_estimates_are_fresh_wherever_g_d_reaches_d3(restricted, not_restricted) -> None:
    for result in (restricted, not_restricted):
        series = _seat(result, GREENHOPPER).series
        reaches_d3 = series["automaton_path"].str.contains("D3")
        age_s = (series["timestamp"] - series["target_assessed_utc"]).dt.total_seconds()
        assert reaches_d3.any()
        assert (age_s[reaches_d3] < result.params.rule9.reassess_every_s).all()
        assert (age_s >= 0).all()


# --- every path of G_d through a replay, from scenarios written here ---------------------

HEAD_ON_SCENARIO = """
name = "{name}"
description = "Head-on: the Greenhopper northbound, the 5 m target southbound."
start_utc = 2024-09-09T12:00:00Z
duration_s = {duration_s}
step_s = 1.0
ais_interval_s = 2.0

[[vessel]]
role = "own"
mmsi = 219999001
name = "GREENHOPPER"
callsign = "OZGH1"
ship_type = "Passenger"
nav_status = 0
length_m = 11.0
breadth_m = 4.0
draught_m = 0.5
route = [[57.0560, 9.9560], [57.0640, 9.9640]]
speed_kn = 2.0

[[vessel]]
role = "target"
mmsi = 219999002
name = "MODEL TARGET"
callsign = "OZMT2"
ship_type = "Cargo"
nav_status = {target_status}
length_m = 50.0
breadth_m = 9.0
draught_m = 5.0
route = [[57.0680, 9.9682], [57.0560, 9.9562]]
speed_kn = 7.0
"""


def _replay_scenario(work: Path, text: str, overrides=None):
    scenario = work / "scenario.toml"
    # a copied scenario names its chart relative to colregs9_cli/data/demo/
    chart_dir = MODELLED_CHART.parent.as_posix()
    text = text.replace('chart = "aalborg_', f'chart = "{chart_dir}/aalborg_')
    scenario.write_text(text, encoding="utf-8")
    simulated = simulate_scenario(scenario, out=work / "ais.csv")
    return run_replay(
        [simulated.out_path],
        chart_paths=[MODELLED_CHART],
        query_path=GREENHOPPER_QUERY,
        out_dir=work / "replay",
        plots=False,
        overrides=overrides,
    )


def _head_on(tmp_path: Path, target_status: int = 0, duration_s: float = 420.0):
    text = HEAD_ON_SCENARIO.format(
        name="head_on", duration_s=duration_s, target_status=target_status
    )
    return _encounters(_replay_scenario(tmp_path, text)).set_index("own_mmsi")


def test_head_on_with_a_restricted_target_she_stands_on(tmp_path: Path) -> None:
    table = _head_on(tmp_path)
    assert_seats_agree(table.reset_index())
    own = table.loc[GREENHOPPER]
    assert (own["situation"], own["own_role_colregs"], own["target_role_colregs"]) == (
        "head-on",
        "give-way",
        "give-way",
    )
    # d1 (the target must give way, as in every head-on) → D2 → D3 (estimated) → D4
    assert own["automaton_path"] == "D1>D2>D3>D4"
    assert own["target_seat_automaton_path"] == "D1>D2>D3>D1"  # the Greenhopper has room
    assert (own["own_role_final"], own["target_role_final"]) == ("give-way", "stand-on")
    assert own["deciding_rule"] == "9" and bool(own["rule9_applied"])
    assert own["give_way_vessels"] == str(GREENHOPPER)
    assert bool(own["data_covers_cpa"])


def test_head_on_with_a_target_reporting_status_3_goes_d1_d2_d4(tmp_path: Path) -> None:
    own = _head_on(tmp_path, target_status=3).loc[GREENHOPPER]
    assert own["automaton_path"] == "D1>D2>D4"
    assert bool(own["target_reports_restricted"])
    assert (own["own_role_final"], own["target_role_final"]) == ("give-way", "stand-on")
    assert own["deciding_rule"] == "18" and not bool(own["rule9_applied"])


def test_crossing_with_a_target_reporting_status_3_goes_d1_d2_d4(
    tmp_path: Path,
) -> None:
    text = (SCENARIOS / "greenhopper_not_restricted.toml").read_text(encoding="utf-8")
    # the target is the second vessel: give her status 3 (restricted manoeuvrability)
    head, target = text.split('role = "target"')
    target = target.replace("nav_status = 0", "nav_status = 3", 1)
    table = _encounters(_replay_scenario(tmp_path, head + 'role = "target"' + target))
    assert_seats_agree(table)
    own = table.set_index("own_mmsi").loc[GREENHOPPER]
    assert own["automaton_path"] == "D1>D2>D4"
    assert (own["own_role_final"], own["target_role_final"]) == ("give-way", "stand-on")
    assert own["deciding_rule"] == "18"


def test_tracks_that_stop_before_cpa_give_insufficient_data(tmp_path: Path) -> None:
    table = _head_on(tmp_path, duration_s=200.0)
    assert not table["data_covers_cpa"].any()
    # the least range seen before the data stop, not the closest approach
    assert (table["actual_min_separation_m"] > table["cpa_m"]).all()
    assert (table["give_way_vessel_acted"] == "insufficient-data").all()
    assert (table["give_way_action"] == "insufficient-data").all()
    # the verdict itself stands: it is made at the trigger
    assert (table["give_way_vessels"] == str(GREENHOPPER)).all()


@pytest.mark.parametrize(
    "manoeuvrability",
    [
        {"policy": RestrictionPolicy.BOTH_SIDES},
        {"policy": RestrictionPolicy.STARBOARD},
        {"swing_model": SwingModel.NEAREST_LENGTH},
        {"swing_model": SwingModel.LOWER_BOUND},
    ],
)
def test_policies_and_swing_models_through_a_replay_on_a_chart(
    tmp_path: Path, manoeuvrability: dict
) -> None:
    text = (SCENARIOS / "greenhopper_restricted.toml").read_text(encoding="utf-8")
    result = _replay_scenario(tmp_path, text, overrides={"manoeuvrability": manoeuvrability})
    params = result.params.manoeuvrability
    for name, value in manoeuvrability.items():
        assert getattr(params, name) is value
    own = _seat(result, GREENHOPPER)
    assessment = own.assessment
    assert assessment.policy is params.policy
    # δ' = α·δ_swing of the chosen model for the 50 m target
    assert assessment.rate_of_swing_deg_per_m == pytest.approx(
        params.alpha * target_rate_of_swing_deg_per_m(50.0, params)
    )
    # the replay's verdict is the policy applied to the flags of the ellipses it drew
    assert own.summary.target_estimated_restricted is verdict(
        params.policy, assessment.arc, assessment.restricted, assessment.covered, True
    )
    expected_path = (
        "D1>D2>D3>D4" if own.summary.target_estimated_restricted.value == "true" else "D1>D2>D3>D1"
    )
    assert own.summary.automaton_path == expected_path
    assert_seats_agree(_encounters(result))


def test_positions_at_the_trigger_and_at_cpa(national) -> None:
    table = _encounters(national)
    _, _, apart_m = GEOD.inv(
        table["own_lon_deg_at_cpa"],
        table["own_lat_deg_at_cpa"],
        table["target_lon_deg_at_cpa"],
        table["target_lat_deg_at_cpa"],
    )
    # the predicted positions at TCPA are the CPA apart
    np.testing.assert_allclose(apart_m, table["cpa_m"], atol=1.0, rtol=0.002)
    _, _, range_m = GEOD.inv(
        table["own_lon_deg_at_trigger"],
        table["own_lat_deg_at_trigger"],
        table["target_lon_deg_at_trigger"],
        table["target_lat_deg_at_trigger"],
    )
    np.testing.assert_allclose(range_m, table["range_m_at_trigger"], atol=1e-3)
    pairs = _pairs(national).astype({"lat_deg_at_cpa_a": float, "cpa_m": float})
    assert pairs["lat_deg_at_cpa_a"].between(54.0, 58.5).all()
