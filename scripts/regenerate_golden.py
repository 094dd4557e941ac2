"""Regenerate the Greenhopper golden files and the committed example figures.

Runs the demo (``colregs9_cli.jobs.demo.run_demo``: simulate and replay both scenarios, own ship
the Greenhopper) in a temporary directory, then copies for each scenario:

- its ``encounters.csv`` to ``tests/golden/<scenario>_encounters.csv`` (what
  ``tests/test_greenhopper.py`` compares against) and to
  ``reports/examples/<scenario>_encounters.csv``;
- its encounter figure to ``reports/examples/<scenario>.png`` (shown in the README).

Run from anywhere: ``python scripts/regenerate_golden.py``. Review the diff before
committing: a changed verdict column is a changed result, not a refresh.
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

from colregs9_cli.jobs.demo import run_demo
from colregs9_cli.report.replay_report import ENCOUNTERS_NAME

ROOT = Path(__file__).resolve().parents[1]
GOLDEN_DIR = ROOT / "tests" / "golden"
EXAMPLES_DIR = ROOT / "reports" / "examples"


def regenerate() -> list[Path]:
    """Write the golden CSVs and the example figures; returns the paths written."""
    written: list[Path] = []
    with tempfile.TemporaryDirectory(prefix="colregs9-golden-") as tmp:
        result = run_demo(
            Path(tmp),
            quiet=True,
            scenarios_dir=ROOT / "colregs9_cli" / "data" / "demo",
            chart=ROOT / "colregs9_cli" / "data" / "demo" / "aalborg_modelled.geojson",
            query=ROOT / "colregs9_cli" / "data" / "demo" / "greenhopper.toml",
        )
        for verdict in result.verdicts:
            encounters = verdict.replay.out_dir / ENCOUNTERS_NAME
            copies = [
                (encounters, GOLDEN_DIR / f"{verdict.scenario}_encounters.csv"),
                (encounters, EXAMPLES_DIR / f"{verdict.scenario}_encounters.csv"),
                (verdict.figure, EXAMPLES_DIR / f"{verdict.scenario}.png"),
            ]
            for source, target in copies:
                target.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(source, target)
                written.append(target)
        sys.stdout.write(result.text.split("\nFiles in", 1)[0] + "\n")
    return written


if __name__ == "__main__":
    for path in regenerate():
        print(f"wrote {path.relative_to(ROOT)}")
