"""Every command has help text with an example; the README's CLI section matches --help."""

from __future__ import annotations

import re

import pytest
from typer.testing import CliRunner

from colregs9_cli.cli import app

from fixture_files import ROOT


def _command_names() -> list[str]:
    import typer.main

    group = typer.main.get_command(app)
    return sorted(group.commands)  # type: ignore[attr-defined]


def test_there_are_commands() -> None:
    assert _command_names(), "the CLI registers no commands"


@pytest.mark.parametrize("name", _command_names())
def test_every_command_has_an_example(name: str) -> None:
    result = CliRunner().invoke(app, [name, "--help"], terminal_width=100)
    assert result.exit_code == 0, result.output
    assert re.search(r"Example:\s*\n?\s*colregs9 " + re.escape(name), result.output), (
        f"`colregs9 {name} --help` has no 'Example: colregs9 {name} …' line"
    )


@pytest.mark.parametrize("name", _command_names())
def test_readme_documents_every_command_and_its_options(name: str) -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert f"colregs9 {name}" in readme, f"README has no section for `colregs9 {name}`"
    result = CliRunner().invoke(app, [name, "--help"], terminal_width=100)
    options = set(re.findall(r"(--[a-z][a-z0-9-]+)", result.output)) - {"--help"}
    section = readme.split(f"### `colregs9 {name}`", 1)
    assert len(section) == 2, f"README has no heading ### `colregs9 {name}`"
    body = section[1].split("\n### ", 1)[0]
    missing = sorted(o for o in options if o not in body)
    assert not missing, f"README section for {name} does not mention {missing}"


def test_python_dash_m_runs_the_cli() -> None:
    import subprocess
    import sys

    from colregs9_cli import __version__

    done = subprocess.run(
        [sys.executable, "-m", "colregs9_cli", "--version"],
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"colregs9 {__version__}"
