"""`replay.py` end to end: the real national NMEA sample (no chart) and a synthetic crossing
with a chart where the target is restricted (D3 → D4).

The CPA/TCPA checks recompute every encounter from the two vessels' raw reports around the
trigger with plain numpy/pyproj (decoded by the NMEA reader, not by the replay pipeline):
position linear in time between the bracketing reports, SOG linear, COG along the shorter
arc (the interpolation rules of DESIGN §5 written out by hand), the velocity turned from true
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
from colregs9_cli.chart import load_chart
from colregs9_cli.errors import ParameterError
from colregs9_cli.query import everything_query
from colregs9_cli.replay import (
    ENCOUNTER_COLUMNS,
    _acted,
    _target_dimensions,
    run_params,
    run_replay,
)
from colregs9_cli.replay_params import ReplayParams, TargetDimensions
from colregs9_cli.simulate import simulate_scenario

from fixture_files import GREENHOPPER_QUERY, MODELLED_CHART, NMEA, SCENARIOS

KNOT_MPS = 1852.0 / 3600.0
GEOD = Geod(ellps="WGS84")

# The replay pipeline finds 13 close-quarters pairs in the sample, each reported from both
# sides. Every one of them is re-checked by hand below (CPA < 150 m, 0 <= TCPA <= 180 s).
NATIONAL_TRIGGERED = 26
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


def _encounters(result) -> pd.DataFrame:
    # "true"/"false"/"unknown" stays text even when a run has no "unknown".
    return pd.read_csv(
        result.out_dir / "encounters.csv", dtype={"target_estimated_restricted": str}
    )


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
    assert (table["target_estimated_restricted"] == "unknown").all()
    # Unknown is ¬d3: rule 9 can only come from a reported restricted status (d2).
    expected = (table["own_role_colregs"] == "stand-on") & table["target_reports_restricted"]
    assert (table["rule9_applied"] == expected).all()
    stand_on = table[table["own_role_colregs"] == "stand-on"]
    assert set(stand_on["automaton_path"]) <= {"D1>D2>D3>D1", "D1>D2>D4"}
    assert (table.loc[table["own_role_colregs"] != "stand-on", "automaton_path"] == "D1>D1").all()
    assert json.loads((national.out_dir / "run.json").read_text())["verdicts"][
        "target_estimated_restricted"
    ] == {"true": 0, "false": 0, "unknown": NATIONAL_TRIGGERED}


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
    # Pairs lie up to 2.4° of longitude from the frame's central meridian (9.42° to 12.69° E).
    first_reports = raw_reports.drop_duplicates("mmsi").set_index("mmsi")
    own_lon = first_reports.loc[table["own_mmsi"], "lon_deg"]
    assert (own_lon - frame["lon0_deg"]).abs().max() > 2.0
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
        assert (series["tcpa_s"] >= 0.0).all()
        assert (np.diff(series["step"]) == 1).all()
        assert series["timestamp"].iloc[-1] <= summary.end_utc
        assert series["automaton_path"].iloc[0] == summary.automaton_path
        assert series["situation"].iloc[0] == summary.situation.value
        assert summary.actual_min_separation_m <= series["range_m"].min() + 1e-9


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
    assert ledger["rejects_by_reason"]["duplicate"] == duplicates
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


@pytest.mark.parametrize(
    ("course_deg", "speed_kn", "acted"),
    [
        ([10.0, 12.0, 24.9], [10.0, 10.0, 10.0], False),  # 14.9° < 15°
        ([10.0, 12.0, 25.0], [10.0, 10.0, 10.0], True),  # exactly 15°
        ([355.0, 5.0, 9.0], [10.0, 10.0, 10.0], False),  # 14° across north
        ([350.0, 0.0, 5.0], [10.0, 10.0, 10.0], True),  # 15° across north
        ([90.0, 90.0, 90.0], [10.0, 8.0, 7.6], False),  # 24 % slower
        ([90.0, 90.0, 90.0], [10.0, 8.0, 7.5], True),  # 25 % slower
        ([90.0, 90.0, 90.0], [8.0, 9.0, 10.0], True),  # 25 % faster
    ],
)
def test_give_way_vessel_acted_thresholds(
    course_deg: list[float], speed_kn: list[float], acted: bool
) -> None:
    assert _acted(np.array(course_deg), np.array(speed_kn), ReplayParams()) is acted


def test_missing_dimensions_take_the_documented_defaults() -> None:
    vessels = pd.DataFrame(
        {"length_m": [120.0, np.nan], "breadth_m": [20.0, 8.0], "draught_m": [7.5, np.nan]},
        index=pd.Index([1, 2], name="mmsi"),
    )
    defaults = ReplayParams().target_defaults
    assert _target_dimensions(vessels, 1, defaults) == (120.0, 20.0, 7.5, False)
    assert _target_dimensions(vessels, 2, defaults) == (50.1, 8.0, 3.2, True)
    longer = ReplayParams(default_length_m=80.0, default_draught_m=4.5).target_defaults
    assert longer == TargetDimensions(80.0, 9.2, 4.5)
    assert _target_dimensions(vessels, 2, longer) == (80.0, 8.0, 4.5, True)


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
    assert not row["target_dimensions_defaulted"]
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
        age_s = (series["timestamp"] - series["restricted_assessed_utc"]).dt.total_seconds()
        assert reaches_d3.any()
        assert (age_s[reaches_d3] < result.params.replay.reassess_every_s).all()
        assert (age_s >= 0).all()
