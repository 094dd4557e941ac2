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


def _help(args: list[str]) -> str:
    result = CliRunner().invoke(app, [*args, "--help"], terminal_width=100)
    assert result.exit_code == 0, result.output
    return result.output


def _help_in_80_columns(name: str) -> str:
    """The help as an 80-column terminal gets it: typer's CliRunner would lay it out 80
    wide, where click gives a terminal of COLUMNS=80 a help 78 wide."""
    import os
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-m", "colregs9_cli", name, "--help"],
        capture_output=True,
        text=True,
        check=False,
        timeout=120,
        env={**os.environ, "COLUMNS": "80", "TERMINAL_WIDTH": "80"},
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def _typer_type_labels() -> set[str]:
    """Every ``<type>`` label typer would print for a parameter (``<list[Path]>``, …)."""
    import typer.main

    group = typer.main.get_command(app)
    commands = [group, *group.commands.values()]  # type: ignore[attr-defined]
    labels = set()
    for command in commands:
        ctx = typer.Context(command)
        for param in command.params:
            if hasattr(param, "display_type"):
                labels.add(param.display_type(ctx))
    return labels


@pytest.mark.parametrize("args", [[], *([name] for name in _command_names())], ids=str)
def test_help_shows_no_internal_type_names(args: list[str]) -> None:
    output = _help(args)
    labels = _typer_type_labels()
    assert labels, "typer gives no type labels to check against"
    shown = sorted(label for label in labels if label in output)
    assert not shown, f"`colregs9 {' '.join(args)} --help` shows {shown}"
    assert not re.search(r"<(list\[|path>|Path>|int>|float>|str>|text>|bool>)", output), output


def _examples(name: str) -> list[list[str]]:
    """The examples of a command's docstring, each as its lines (a ``\\`` continues one)."""
    import inspect

    import typer.main

    command = typer.main.get_command(app).commands[name]  # type: ignore[attr-defined]
    lines = [line.strip() for line in inspect.cleandoc(command.help or "").splitlines()]
    examples: list[list[str]] = []
    for i, line in enumerate(lines):
        _, found, rest = line.partition("Example:")
        if not found:
            continue
        after = iter(lines[i + 1 :])
        example = [rest.strip() or next(after)]
        while example[-1].endswith("\\"):
            example.append(next(after))
        examples.append(example)
    return examples


@pytest.mark.parametrize("name", _command_names())
def test_examples_fit_an_80_column_terminal(name: str) -> None:
    output = _help_in_80_columns(name)
    shown = [line.rstrip() for line in output.splitlines()]
    examples = _examples(name)
    assert examples, f"`colregs9 {name}` has no example"
    for example in examples:
        assert example[0].startswith(f"colregs9 {name}")
        for part in example:
            # whole on one line of the help, and that line fits: the example is not wrapped
            (line,) = [line for line in shown if line.strip() in (part, f"Example: {part}")]
            assert len(line) <= 80, f"{line!r} is wider than 80 columns"


AIS_COMMANDS = ("replay", "stats", "ingest")


@pytest.mark.parametrize("name", AIS_COMMANDS)
def test_ais_commands_name_every_input_format_and_layout(name: str) -> None:
    from colregs9_cli.ais.layouts import LAYOUTS

    output = " ".join(_help([name]).split())
    for kind in ("DMA CSV", "MarineCadastre CSV", "NMEA", "Parquet"):
        assert kind in output, f"`colregs9 {name} --help` does not name {kind}"
    for compression in ("gzip", "bzip2", "xz", "zstd", "zip"):
        assert compression in output, f"`colregs9 {name} --help` does not name {compression}"
    if name != "ingest":
        assert "dataset directories made by colregs9 ingest" in output
    layout_help = output.split("--format LAYOUT", 1)[1].split(" --", 1)[0]
    assert all(layout in layout_help for layout in LAYOUTS), layout_help


@pytest.mark.parametrize(
    ("name", "marker"),
    [("replay", "--chart CHART"), ("chart", "CHART..."), ("demo", "--chart CHART")],
)
def test_chart_inputs_name_every_chart_format(name: str, marker: str) -> None:
    from colregs9_cli.charts.read import S57_SUFFIXES, VECTOR_SUFFIXES

    output = " ".join(_help([name]).split())
    chart_help = output.split(marker, 1)[1].split(" --", 1)[0]
    for kind in ("S-57", "GeoJSON", "GeoPackage", *S57_SUFFIXES, *VECTOR_SUFFIXES):
        assert kind in chart_help, f"`colregs9 {name} --help`: {marker} does not name {kind}"


def test_replay_and_stats_help_name_what_they_write() -> None:
    from colregs9_cli.report import replay_report, stats_report
    from colregs9_cli.report.html_page import HTML_NAME
    from colregs9_cli.report.replay_geopackage import GEOPACKAGE_NAME

    written = {
        "replay": (
            replay_report.PAIRS_NAME,
            replay_report.ENCOUNTERS_NAME,
            GEOPACKAGE_NAME,
            HTML_NAME,
            replay_report.INDEX_NAME,
            replay_report.MANIFEST_NAME,
        ),
        "stats": (
            stats_report.CSV_NAME,
            stats_report.MARKDOWN_NAME,
            stats_report.HISTOGRAM_NAME,
            HTML_NAME,
            stats_report.MANIFEST_NAME,
        ),
    }
    for name, files in written.items():
        output = " ".join(_help([name]).split())
        missing = [f for f in files if f not in output]
        assert not missing, f"`colregs9 {name} --help` does not name {missing}"


def test_quiet_says_the_same_in_every_command() -> None:
    texts = {}
    for name in _command_names():
        output = " ".join(_help([name]).split())
        assert "--quiet" in output, f"`colregs9 {name}` has no --quiet"
        texts[name] = output.split("--quiet", 1)[1].split(" --", 1)[0]
    assert len(set(texts.values())) == 1, texts
    assert "progress bars" in texts["stats"] and "files written" in texts["stats"]
