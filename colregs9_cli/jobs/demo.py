"""``colregs9 demo``: the paper's Greenhopper case study end to end.

For each of the two scenarios (``greenhopper_restricted``, ``greenhopper_not_restricted``)
it simulates the scenario's AIS, replays it on the modelled Aalborg chart with the paper's
parameters (``greenhopper.toml``) with the scenario's own ship (the Greenhopper) in
the own-ship seat, and reports the verdict of her triggered encounter. Every file lands in
one output directory:

- ``simulate-<scenario>.csv``: the synthetic AIS;
- ``<scenario>/``: the replay's reports (index.html, pairs.csv, encounters.csv,
  encounters/<id>.csv and the figures, report.gpkg, index.md, run.json);
- ``<scenario>.png``: a copy of the encounter's figure, the paper's Figure "restricted" or
  "not restricted";
- ``run.json``: the inputs and both verdicts.

Like ``stats`` and ``replay``, the demo writes into a fresh directory that replaces the
output directory whole at the end, and refuses one that holds something else.

The inputs (the two scenarios, the modelled chart and the query) are package data in
``colregs9_cli/data/demo/``, so the demo runs from any directory after ``pip install``.
"""

from __future__ import annotations

import dataclasses
import json
import shutil
from dataclasses import dataclass
from enum import Enum
from importlib import resources
from pathlib import Path

from ..charts.provenance import charts_manifest
from ..core.replay_results import EncounterOutcome, ReplayResult
from ..errors import InputFileError, NoDataError
from ..outputs import FILES_KEY, REPORT_MARKER, check_out_dir, report_directory, write_json
from ..provenance import run_header
from ..report.replay_geopackage import Domains
from ..report.replay_report import ENCOUNTER_DIR
from ..timebase import DISPLAY_TIME_FORMAT
from .replay import domains_choice, run_replay
from .simulate import SimulationResult, simulate_scenario

SCENARIO_NAMES: tuple[str, ...] = ("greenhopper_restricted", "greenhopper_not_restricted")
DEFAULT_OUT_DIR = Path("reports") / "demo"
DEMO_DATA = Path(str(resources.files("colregs9_cli").joinpath("data", "demo")))
DEFAULT_SCENARIOS_DIR = DEMO_DATA
DEFAULT_CHART = DEMO_DATA / "aalborg_modelled.geojson"
DEFAULT_QUERY = DEMO_DATA / "greenhopper.toml"


@dataclass(frozen=True)
class PaperVerdict:
    """The outcome the paper reports for a scenario (section "Simulation results")."""

    target_estimated_restricted: str
    rule9_applied: bool
    own_role_final: str
    automaton_path: str


PAPER_VERDICTS: dict[str, PaperVerdict] = {
    "greenhopper_restricted": PaperVerdict("true", True, "give-way", "D1>D2>D3>D4"),
    "greenhopper_not_restricted": PaperVerdict("false", False, "stand-on", "D1>D2>D3>D1"),
}


@dataclass(frozen=True)
class ScenarioVerdict:
    """One scenario of the demo: its files and the verdict of the own ship's encounter."""

    scenario: str
    simulation: SimulationResult
    replay: ReplayResult
    outcome: EncounterOutcome
    figure: Path

    @property
    def as_in_paper(self) -> bool:
        expected = PAPER_VERDICTS.get(self.scenario)
        s = self.outcome.summary
        return expected is not None and expected == PaperVerdict(
            _shown(s.target_estimated_restricted),
            bool(s.rule9_applied),
            _shown(s.own_role_final),
            _shown(s.automaton_path),
        )


@dataclass(frozen=True)
class DemoResult:
    out_dir: Path
    verdicts: tuple[ScenarioVerdict, ...]

    @property
    def text(self) -> str:
        return format_demo(self)


def _yes_no(value: bool | None) -> str:
    return "-" if value is None else "yes" if value else "no"


def _shown(value: Enum | str | None) -> str:
    """A verdict value as printed; ``-`` where the pair is not an encounter and has none."""
    if value is None:
        return "-"
    return value.value if isinstance(value, Enum) else value


def verdict_rows(verdict: ScenarioVerdict) -> tuple[tuple[str, str], ...]:
    """(label, value) of one scenario's verdict, in the order printed."""
    s = verdict.outcome.summary
    return (
        ("trigger (UTC)", s.trigger_utc.strftime(DISPLAY_TIME_FORMAT)),
        ("interaction", s.interaction.value),
        ("situation", _shown(s.situation)),
        ("own role under COLREGs", _shown(s.own_role_colregs)),
        ("target reports restricted", _yes_no(s.target_reports_restricted)),
        ("target estimated restricted", _shown(s.target_estimated_restricted)),
        ("rule 9 applied", _yes_no(s.rule9_applied)),
        ("own role after rule 9", _shown(s.own_role_final)),
        ("automaton path", _shown(s.automaton_path)),
        ("range at trigger", f"{s.range_m_at_trigger:.0f} m"),
        ("CPA at trigger", f"{s.cpa_m:.0f} m"),
        ("TCPA at trigger", f"{s.tcpa_s:.0f} s"),
        ("as in the paper", _yes_no(verdict.as_in_paper)),
    )


def format_demo(result: DemoResult) -> str:
    """The verdict table (one column per scenario) and where the files are."""
    columns = [verdict_rows(v) for v in result.verdicts]
    labels = [label for label, _ in columns[0]]
    rows = [("", [v.scenario for v in result.verdicts])]
    rows += [(label, [column[i][1] for column in columns]) for i, label in enumerate(labels)]
    label_width = max(len(label) for label, _ in rows)
    widths = [max(len(cells[i]) for _, cells in rows) for i in range(len(result.verdicts))]
    first = result.verdicts[0].outcome.summary
    lines = [
        'Greenhopper case study (the paper\'s section "Simulation results"), modelled chart.',
        f"Own ship {first.own_name} (MMSI {first.own_mmsi}); target {first.target_name} "
        f"(MMSI {first.target_mmsi}).",
        "",
    ]
    for label, cells in rows:
        cells_text = "  ".join(c.ljust(w) for c, w in zip(cells, widths, strict=True))
        lines.append(f"{label.ljust(label_width)}  {cells_text}".rstrip())
    lines += ["", f"Files in {result.out_dir}:"]
    for verdict in result.verdicts:
        lines += [
            f"  {verdict.scenario}",
            f"    figure   {verdict.figure}",
            f"    AIS      {verdict.simulation.out_path}",
            f"    reports  {verdict.replay.out_dir}/ (index.html, pairs.csv, encounters.csv, "
            "report.gpkg, index.md, run.json)",
        ]
    return "\n".join(lines) + "\n"


def _require(path: Path, option: str, kind: str) -> None:
    exists = path.is_dir() if kind == "directory" else path.is_file()
    if not exists:
        raise InputFileError(
            f"{path}: no such {kind} ({option}); give an existing one, or leave them out to "
            "use the package's own"
        )


def _own_outcome(replay: ReplayResult, own_mmsi: int, scenario: str) -> EncounterOutcome:
    """The own ship's first triggered encounter; none is an error: the demo shows nothing."""
    outcomes = [o for o in replay.encounters if o.summary.own_mmsi == own_mmsi]
    if not outcomes:
        raise NoDataError(
            f"scenario {scenario}: the replay found no triggered encounter for own ship MMSI "
            f"{own_mmsi} (CPA < {replay.params.encounters.cpa_req_m:g} m within 0 <= TCPA <= "
            f"{replay.params.encounters.tcpa_act_s:g} s); check the scenario and the query"
        )
    return min(outcomes, key=lambda o: o.summary.trigger_utc)


def run_scenario(
    scenario_path: Path,
    out_dir: Path,
    chart: Path,
    query: Path,
    quiet: bool = True,
    overrides: dict[str, dict[str, object]] | None = None,
    domains: Domains = Domains.ALL,
) -> ScenarioVerdict:
    """Simulate one scenario into ``out_dir`` and replay it with its own ship in the own seat
    (``domains``: the ship-domain ellipses its report.gpkg holds)."""
    simulation = simulate_scenario(
        scenario_path, out_dir / f"simulate-{scenario_path.stem}.csv", quiet=quiet
    )
    own = simulation.scenario.own
    if own is None:
        raise InputFileError(
            f"{scenario_path}: no vessel has role = 'own'; the demo needs the Greenhopper's seat"
        )
    name = simulation.scenario.name
    replay = run_replay(
        [simulation.out_path],
        chart_paths=[chart],
        query_path=query,
        own_mmsi=[own.mmsi],
        out_dir=out_dir / name,
        plots=True,
        overrides=overrides,
        quiet=quiet,
        domains=domains,
    )
    outcome = _own_outcome(replay, own.mmsi, name)
    figure = out_dir / f"{name}.png"
    shutil.copyfile(replay.out_dir / ENCOUNTER_DIR / f"{outcome.summary.encounter_id}.png", figure)
    return ScenarioVerdict(
        scenario=name, simulation=simulation, replay=replay, outcome=outcome, figure=figure
    )


def _moved(verdict: ScenarioVerdict, staging: Path, out_dir: Path) -> ScenarioVerdict:
    """The verdict with its paths, and the inputs its replay's manifest names, where the
    staging directory's files are after the swap."""

    def moved(path: Path) -> Path:
        return out_dir / path.relative_to(staging) if path.is_relative_to(staging) else path

    replay = verdict.replay
    inputs = [
        {**item, "path": str(moved(Path(item["path"])))} for item in replay.manifest["inputs"]
    ]
    return dataclasses.replace(
        verdict,
        simulation=dataclasses.replace(
            verdict.simulation, out_path=moved(verdict.simulation.out_path)
        ),
        replay=dataclasses.replace(
            replay,
            out_dir=moved(replay.out_dir),
            files=tuple(moved(path) for path in replay.files),
            manifest={**replay.manifest, "inputs": inputs},
        ),
        figure=moved(verdict.figure),
    )


def demo_manifest(
    verdicts: tuple[ScenarioVerdict, ...], scenario_paths: list[Path], chart: Path, query: Path
) -> dict[str, object]:
    """The content of the demo's run.json (each scenario's replay has its own)."""
    return {
        **run_header("demo"),
        "scenarios": [str(path) for path in scenario_paths],
        "charts": charts_manifest([chart]),
        "query": str(query),
        "verdicts": {v.scenario: dict(verdict_rows(v)) for v in verdicts},
    }


def run_demo(
    out_dir: Path | None = None,
    quiet: bool = True,
    scenarios_dir: Path = DEFAULT_SCENARIOS_DIR,
    chart: Path = DEFAULT_CHART,
    query: Path = DEFAULT_QUERY,
    overwrite: bool = False,
    domains: Domains | str = Domains.ALL,
) -> DemoResult:
    """Both Greenhopper scenarios: simulate, replay, and the verdicts (module docstring).
    ``domains``: the ship-domain ellipses of the replays' report.gpkg; all by default, as
    the paper's figures draw them, red and blue (a few hundred ellipses).

    Errors: a missing scenario directory, scenario file, chart or query (``InputFileError``,
    exit 2); an ``out_dir`` that cannot take a report, or, unless ``overwrite``, holds a
    report of another command or files colregs9 did not write (``OutputError``, exit 2,
    ``outputs.check_out_dir``), both before any work; a scenario whose replay has no
    triggered encounter for own ship (``NoDataError``, exit 3), which leaves ``out_dir`` as
    it was.
    """
    target = out_dir if out_dir is not None else DEFAULT_OUT_DIR
    choice = domains_choice(domains)
    _require(scenarios_dir, "--scenarios", "directory")
    _require(chart, "--chart", "file")
    _require(query, "--query", "file")
    paths = [scenarios_dir / f"{name}.toml" for name in SCENARIO_NAMES]
    for path in paths:
        _require(path, "--scenarios", "file")
    check_out_dir(target, overwrite, command="demo")
    with report_directory(target, overwrite) as staging:
        staged = tuple(
            run_scenario(path, staging, chart, query, quiet, domains=choice) for path in paths
        )
        verdicts = tuple(_moved(verdict, staging, target) for verdict in staged)
        for staged_verdict, verdict in zip(staged, verdicts, strict=True):
            # Each replay read its AIS in the staging directory; its run.json is to name the
            # file where it stays, beside the report, and still list the replay's files.
            staged_json = staged_verdict.replay.out_dir / REPORT_MARKER
            files = json.loads(staged_json.read_text(encoding="utf-8"))[FILES_KEY]
            write_json(staged_json, {**verdict.replay.manifest, FILES_KEY: files})
        write_json(staging / REPORT_MARKER, demo_manifest(verdicts, paths, chart, query))
    return DemoResult(out_dir=target, verdicts=verdicts)
