"""A hand-built case per interaction kind (DESIGN §7), simulated and replayed end to end.

Each ``tests/scenarios/<kind>.toml`` models, in open water and without a chart, what issue 29
found misjudged in real AIS: tugs in company, a ship-to-ship transfer under way, a pilot boat
boarding a tanker, towboats drifting, a ferry berthing as the other leaves; and a plain
crossing as the control. Its ``description`` says what it models and which threshold of
``InteractionParams`` it exercises. Each is simulated (``colregs9 simulate``) and replayed
with the default parameters (``colregs9 replay``, no own ship, so both seats are reported),
and the written pairs.csv and encounters.csv are read back.

``tests/scenarios/boundary/`` holds the same cases with one figure moved just inside and
just outside its threshold; an outside case replayed again with that threshold relaxed past
the figure gets its kind back, so it is that threshold, and no other, that decided.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from colregs9_cli.cli import app
from colregs9_cli.core.interactions import InteractionKind, InteractionParams
from colregs9_cli.errors import QueryError
from colregs9_cli.jobs.replay import run_replay
from colregs9_cli.jobs.scenario import load_scenario
from colregs9_cli.jobs.simulate import simulate_scenario

from fixture_files import ROOT
from seat_checks import assert_seats_agree

SCENARIOS = ROOT / "tests" / "scenarios"
BOUNDARY = SCENARIOS / "boundary"
APPROACH = SCENARIOS / "approach"
THRESHOLDS = {field.name for field in fields(InteractionParams)} | {"min_sog_kn"}

# The verdict of rules 13–18 and rule 9, and the audit facts: only an encounter has them.
VERDICT_COLUMNS = (
    "situation",
    "situation_ambiguous",
    "situation_basis",
    "role_colregs_a",
    "role_colregs_b",
    "automaton_path_a",
    "automaton_path_b",
    "rule9_applied",
    "deciding_rule",
    "both_restricted",
    "role_final_a",
    "role_final_b",
    "give_way_vessels",
    "give_way_vessel_acted",
    "give_way_action",
    "stand_on_vessel_kept_course",
)
SEAT_VERDICT_COLUMNS = (
    "situation",
    "own_role_colregs",
    "target_role_colregs",
    "own_role_final",
    "target_role_final",
    "give_way_vessel",
    "give_way_vessels",
    "deciding_rule",
    "rule9_applied",
    "automaton_path",
)


@dataclass(frozen=True)
class Case:
    """A scenario, the pair it is about (MMSI order) and what the replay must make of it:
    its kind, and the interaction basis (a regular expression, searched) with the measured
    figures that decided."""

    scenario: str
    kind: InteractionKind
    mmsis: tuple[int, int]
    basis: str


CASES = (
    Case(
        "encounter_crossing",
        InteractionKind.ENCOUNTER,
        (219500001, 219500002),
        r"^none of the other kinds: 219500001 at 12\.0 kn and 219500002 at 14\.0 kn over "
        r"ground, .*relative speed 18\.4 kn",
    ),
    Case(
        "in_company_tugs",
        InteractionKind.IN_COMPANY,
        (219500011, 219500012),
        r"^range 70–71 m, relative position over ground within 7 m \(<= 30 m\), courses "
        r"within 0° at 6\.0 kn and 6\.1 kn for 1[2-9]\d s$",
    ),
    Case(
        "alongside_sts",
        InteractionKind.ALONGSIDE,
        (219500031, 219500032),
        # held to the predicted closest approach and a window past it (at most 600 s here)
        r"^range 38–39 m <= half-breadths 34\.5 m \+ margin 10 m for ([2-5]\d\d) s$",
    ),
    Case(
        "service_pilot",
        InteractionKind.SERVICE,
        (219500041, 219500042),
        r"^service craft 219500042 within 30 m of 219500041 \(half-length 92 m \+ margin "
        r"30 m\) at relative speed 0\.0–0\.9 kn for ([3-9]\d) s$",
    ),
    Case(
        "not_making_way_drifting",
        InteractionKind.NOT_MAKING_WAY,
        (219500051, 219500052),
        r"^219500051 moved 74 m in 240 s from -120 s \(< 1 kn over ground; reports SOG "
        r"0\.6 kn\); 219500052 moved 99 m in 240 s from -120 s \(< 1 kn over ground; "
        r"reports SOG 0\.8 kn\)$",
    ),
    Case(
        "not_making_way_berthing",
        InteractionKind.NOT_MAKING_WAY,
        (219500061, 219500062),
        # the inbound ferry stopping at her berth, the outbound one at hers before she sails
        r"^219500061 moved \d+ m in \d+ s from \+\d+ s \(< 1 kn over ground; reports SOG "
        r"0\.0–1\.0 kn\); 219500062 moved \d+ m in 1\d\d s from -120 s ",
    ),
)


@dataclass(frozen=True)
class Replayed:
    """One scenario's written reports: pairs.csv as text ('' when empty), encounters.csv
    typed as ``seat_checks`` reads it (empty cells missing)."""

    pairs: pd.DataFrame
    encounters: pd.DataFrame

    def pair(self, case: Case) -> pd.Series:
        rows = self.pairs[
            (self.pairs["mmsi_a"] == str(case.mmsis[0]))
            & (self.pairs["mmsi_b"] == str(case.mmsis[1]))
        ]
        assert len(rows) == 1, self.pairs[["mmsi_a", "mmsi_b", "interaction"]]
        return rows.iloc[0]


def _simulated(path: Path, out_dir: Path) -> Path:
    ais = out_dir / f"{path.stem}.csv"
    simulate_scenario(path, ais)
    return ais


@pytest.fixture(scope="module")
def replayed(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Replayed]:
    """Simulate and replay a scenario of ``tests/scenarios`` once for the module."""
    done: dict[str, Replayed] = {}

    def run(name: str) -> Replayed:
        if name not in done:
            out = tmp_path_factory.mktemp(name)
            ais = _simulated(SCENARIOS / f"{name}.toml", out)
            run_replay([ais], out_dir=out / "report", plots=False)
            done[name] = Replayed(
                pairs=pd.read_csv(out / "report" / "pairs.csv", dtype=str, keep_default_na=False),
                encounters=pd.read_csv(
                    out / "report" / "encounters.csv",
                    dtype={"give_way_vessels": str, "deciding_rule": str, "give_way_action": str},
                ),
            )
        return done[name]

    return run


@pytest.fixture(scope="module")
def boundary_ais(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Path]:
    """Simulate a scenario of ``tests/scenarios/boundary`` once for the module."""
    done: dict[str, Path] = {}

    def run(name: str) -> Path:
        if name not in done:
            done[name] = _simulated(BOUNDARY / f"{name}.toml", tmp_path_factory.mktemp("b"))
        return done[name]

    return run


def _replay_pairs(ais: Path, **thresholds: float) -> pd.DataFrame:
    """pairs.csv of ``ais`` in memory, with ``[replay]`` thresholds other than the defaults."""
    result = run_replay([ais], plots=False, write=False, overrides={"replay": thresholds})
    return result.pairs_table


# -- the scenario files ---------------------------------------------------------------------


@pytest.mark.parametrize(
    "path",
    sorted(SCENARIOS.glob("*.toml"))
    + sorted(BOUNDARY.glob("*.toml"))
    + sorted(APPROACH.glob("*.toml")),
    ids=str,
)
def test_each_scenario_says_what_it_models_and_which_threshold(path: Path) -> None:
    scenario = load_scenario(path)
    assert scenario.chart is None  # open water, or a modelled quay: no chart needed
    assert scenario.name == path.stem
    named = {word for word in re.findall(r"[a-z_]+_(?:kn|m|s|deg)\b", scenario.description)}
    assert named and named <= THRESHOLDS, named
    assert len(scenario.description) > 150


def test_one_scenario_per_kind() -> None:
    assert {case.kind for case in CASES} == set(InteractionKind)
    assert {case.scenario for case in CASES} == {p.stem for p in SCENARIOS.glob("*.toml")}


# -- each kind, end to end ------------------------------------------------------------------


@pytest.mark.parametrize("case", CASES, ids=lambda case: case.scenario)
def test_the_pair_gets_its_kind_and_the_basis_names_the_rule(
    replayed: Callable[[str], Replayed], case: Case
) -> None:
    pair = replayed(case.scenario).pair(case)
    assert pair["interaction"] == case.kind.value, pair["interaction_basis"]
    assert re.search(case.basis, pair["interaction_basis"]), pair["interaction_basis"]


@pytest.mark.parametrize("case", CASES, ids=lambda case: case.scenario)
def test_only_the_encounter_gets_a_verdict(replayed: Callable[[str], Replayed], case: Case) -> None:
    pair = replayed(case.scenario).pair(case)
    verdict = {column: pair[column] for column in VERDICT_COLUMNS}
    if case.kind is not InteractionKind.ENCOUNTER:
        assert set(verdict.values()) == {""}, verdict
        return
    assert all(verdict.values()), verdict
    # CROSSER B (219500002) is on CROSSER A's starboard side: A gives way (rule 15)
    assert verdict["situation"] == "crossing" and verdict["situation_ambiguous"] == "false"
    assert verdict["role_colregs_a"] == verdict["role_final_a"] == "give-way"
    assert verdict["role_colregs_b"] == verdict["role_final_b"] == "stand-on"
    assert verdict["give_way_vessels"] == "219500001" and verdict["deciding_rule"] == "15"
    assert verdict["rule9_applied"] == "false"


@pytest.mark.parametrize("case", CASES, ids=lambda case: case.scenario)
def test_both_seats_tell_the_same_story(replayed: Callable[[str], Replayed], case: Case) -> None:
    run = replayed(case.scenario)
    pair = run.pair(case)
    assert pair["seats_reported"] == "{};{}".format(*case.mmsis)
    seats = run.encounters[run.encounters["pair_id"] == pair["pair_id"]]
    assert sorted(seats["own_mmsi"]) == list(case.mmsis)
    assert (seats["interaction"] == case.kind.value).all()
    assert (seats["interaction_basis"] == pair["interaction_basis"]).all()
    assert assert_seats_agree(seats) == 1
    verdicts = seats[list(SEAT_VERDICT_COLUMNS)]
    if case.kind is InteractionKind.ENCOUNTER:
        assert verdicts.notna().all().all()
        assert set(seats["give_way_vessel"]) == {"own", "target"}
    else:
        assert verdicts.isna().all().all()


def test_vessels_lying_still_form_no_pair(
    replayed: Callable[[str], Replayed], boundary_ais: Callable[[str], Path]
) -> None:
    # the moored cargo ship reports SOG 0 throughout, under min_sog_kn: paired with nobody
    pairs = replayed("not_making_way_berthing").pairs
    assert len(pairs) == 1
    assert "219500063" not in set(pairs["mmsi_a"]) | set(pairs["mmsi_b"])
    # towboats drifting at 0.3 kn are under min_sog_kn too: no pair, no verdict
    assert _replay_pairs(boundary_ais("not_making_way_drifting_0.3kn")).empty


# -- each threshold, crossed -----------------------------------------------------------------


@dataclass(frozen=True)
class Boundary:
    """A boundary scenario, its kind and basis (searched); for one just outside, the
    threshold relaxed past its figure and the kind (and basis) it then gets back."""

    scenario: str
    kind: InteractionKind
    basis: str
    relaxed: dict[str, Any] | None = None
    relaxed_kind: InteractionKind | None = None
    relaxed_basis: str = ""


BOUNDARIES = (
    Boundary(
        "in_company_tugs_0.2kn",
        InteractionKind.IN_COMPANY,
        r"relative position over ground within 14 m \(<= 30 m\)",
    ),
    Boundary(
        # 35 m in the frame of their course: tugs that turn together keep their places
        # over ground, not in the frame of their course.
        "in_company_tugs_0.3kn",
        InteractionKind.IN_COMPANY,
        r"relative position over ground within 21 m \(<= 30 m\)",
    ),
    Boundary(
        "in_company_tugs_0.5kn",
        InteractionKind.ENCOUNTER,
        r"6\.0 kn and 219500012 at 6\.5 kn over ground, range 74–81 m, relative speed 0\.5 kn",
        {"company_drift_m": 40.0},
        InteractionKind.IN_COMPANY,
        r"relative position over ground within 31 m \(<= 40 m\)",
    ),
    Boundary(
        "alongside_sts_43.5m",
        InteractionKind.ALONGSIDE,
        r"^range 43–44 m <= half-breadths 34\.5 m \+ margin 10 m",
    ),
    Boundary(
        "alongside_sts_45.5m",
        InteractionKind.IN_COMPANY,
        r"^range 46 m, relative position over ground within \d m",
        {"alongside_margin_m": 12.0},
        InteractionKind.ALONGSIDE,
        r"^range 45–46 m <= half-breadths 34\.5 m \+ margin 12 m",
    ),
    Boundary(
        "service_pilot_122m",
        InteractionKind.SERVICE,
        r"within 122 m of 219500041 \(half-length 92 m \+ margin 30 m\)",
    ),
    Boundary(
        "service_pilot_125m",
        InteractionKind.ENCOUNTER,
        r"219500042 at \d\.\d–20\.0 kn over ground, range 125–\d+ m",
        {"service_margin_m": 35.0},
        InteractionKind.SERVICE,
        r"within 125 m of 219500041 \(half-length 92 m \+ margin 35 m\)",
    ),
    Boundary(
        "not_making_way_drifting_0.9kn",
        InteractionKind.NOT_MAKING_WAY,
        r"^219500051 moved \d+ m in 240 s from -120 s \(< 1 kn over ground; reports SOG 0\.9 kn\)$",
    ),
    Boundary(
        "not_making_way_drifting_1.1kn",
        InteractionKind.ENCOUNTER,
        r"219500051 at 1\.1 kn and 219500052 at 1\.3 kn over ground",
        {"making_way_kn": 1.2},
        InteractionKind.NOT_MAKING_WAY,
        r"^219500051 moved \d+ m in 240 s from -120 s \(< 1\.2 kn over ground; reports SOG "
        r"1\.1 kn\)$",
    ),
)


@pytest.mark.parametrize("boundary", BOUNDARIES, ids=lambda boundary: boundary.scenario)
def test_a_figure_across_its_threshold_changes_the_kind(
    boundary_ais: Callable[[str], Path], boundary: Boundary
) -> None:
    ais = boundary_ais(boundary.scenario)
    (pair,) = _replay_pairs(ais).itertuples()
    assert pair.interaction == boundary.kind.value, pair.interaction_basis
    assert re.search(boundary.basis, pair.interaction_basis), pair.interaction_basis
    if boundary.relaxed is None:
        return
    (relaxed,) = _replay_pairs(ais, **boundary.relaxed).itertuples()
    assert relaxed.interaction == boundary.relaxed_kind, relaxed.interaction_basis
    assert re.search(boundary.relaxed_basis, relaxed.interaction_basis), relaxed.interaction_basis


def test_each_kind_is_crossed_at_a_boundary() -> None:
    crossed = {b.scenario.rsplit("_", 1)[0] for b in BOUNDARIES if b.relaxed is not None}
    kinds = {case.kind for case in CASES if case.scenario in crossed}
    assert kinds == set(InteractionKind) - {InteractionKind.ENCOUNTER}


# -- depart_s: a vessel lying at her first waypoint -----------------------------------------


def test_a_vessel_lies_at_her_first_waypoint_until_depart_s(tmp_path: Path) -> None:
    path = SCENARIOS / "not_making_way_berthing.toml"
    scenario = {vessel.mmsi: vessel for vessel in load_scenario(path).vessels}
    rows = pd.read_csv(_simulated(path, tmp_path))
    seconds = (
        pd.to_datetime(rows["# Timestamp"], format="%d/%m/%Y %H:%M:%S")
        - pd.Timestamp("2024-09-09 10:00:00")
    ).dt.total_seconds()
    for mmsi, course_deg in ((219500062, 90.0), (219500063, 180.0)):
        vessel = scenario[mmsi]
        mine = rows["MMSI"] == mmsi
        waiting = mine & (seconds < vessel.depart_s)
        assert waiting.sum() == min(vessel.depart_s, 600.0) / 10.0
        assert (rows.loc[waiting, "SOG"] == 0.0).all()
        assert (rows.loc[waiting, "COG"] == course_deg).all()
        np.testing.assert_allclose(
            rows.loc[waiting, ["Latitude", "Longitude"]].to_numpy(),
            np.broadcast_to(vessel.route[0], (int(waiting.sum()), 2)),
            atol=1e-6,
        )
    # the outbound ferry sails at depart_s, at her first leg's speed
    sailing = (rows["MMSI"] == 219500062) & (seconds >= 350.0)
    assert rows.loc[sailing, "SOG"].iloc[0] == 1.0 and rows.loc[sailing, "SOG"].max() == 10.0
    assert rows.loc[sailing, "Longitude"].is_monotonic_increasing


@pytest.mark.parametrize(
    ("value", "message"),
    [("-10.0", "'depart_s' = -10 is before the start"), ('"soon"', "'depart_s' = 'soon'")],
)
def test_a_bad_depart_s_is_one_error_line(tmp_path: Path, value: str, message: str) -> None:
    text = (SCENARIOS / "not_making_way_berthing.toml").read_text(encoding="utf-8")
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("depart_s = 350.0", f"depart_s = {value}"), encoding="utf-8")
    result = CliRunner().invoke(app, ["simulate", str(bad), "--out", str(tmp_path / "x.csv")])
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert result.exit_code == QueryError.exit_code
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
    assert message in lines[0] and "FERRY OUTBOUND" in lines[0]
    assert not (tmp_path / "x.csv").exists()


# -- coming alongside, coming to work, turning together -------------------------------------

APPROACHES = (
    Case(
        "pilot_from_abeam",
        InteractionKind.SERVICE,
        (219500041, 219500042),
        r"^service craft 219500042 within 30 m of 219500041 .* for \d+ s$",
    ),
    Case(
        "sts_from_astern",
        InteractionKind.ALONGSIDE,
        (219500031, 219500032),
        r"^range 3\d–4\d m <= half-breadths 34\.5 m \+ margin 10 m for \d+ s$",
    ),
    Case(
        "tugs_turn_together_30deg",
        InteractionKind.IN_COMPANY,
        (219500011, 219500012),
        r"^range 70–71 m, relative position over ground within \d m \(<= 30 m\), courses "
        r"within 0°",
    ),
)


@pytest.mark.parametrize("case", APPROACHES, ids=lambda case: case.scenario)
def test_an_approach_is_judged_by_what_the_vessels_do_when_they_meet(
    tmp_path: Path, case: Case
) -> None:
    """The pilot boat and the STS daughter trigger while still closing (the 2 minutes after
    the trigger show only the approach); their kind comes from what they do at the
    predicted closest approach. The tugs turn 30° together: 36 m of drift in the frame of
    their course, none over ground."""
    ais = _simulated(APPROACH / f"{case.scenario}.toml", tmp_path)
    result = run_replay([ais], plots=False, write=False)
    (pair,) = [
        p.summary for p in result.pairs if (p.summary.mmsi_a, p.summary.mmsi_b) == case.mmsis
    ]
    assert pair.interaction is case.kind, pair.interaction_basis
    assert re.search(case.basis, pair.interaction_basis), pair.interaction_basis
    if case.kind is not InteractionKind.IN_COMPANY:
        # at the trigger, twice her final distance off and minutes from it
        assert pair.tcpa_s > 120.0 and pair.range_m_at_trigger > 90.0
