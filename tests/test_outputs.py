"""Report directories: written whole or not at all, never mixed with an earlier run, modes
from the umask, and a bad --out refused with one Error line before any work."""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path

import pytest
from typer.testing import CliRunner

from colregs9_cli.cli import app
from colregs9_cli.errors import OutputError
from colregs9_cli.outputs import FILES_KEY, check_out_dir, report_directory, write_text

from fixture_files import DMA26, NMEA


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


@pytest.mark.parametrize(
    ("umask", "file_mode", "dir_mode"), [(0o022, 0o644, 0o755), (0o077, 0o600, 0o700)]
)
def test_modes_follow_the_umask(tmp_path: Path, umask: int, file_mode: int, dir_mode: int) -> None:
    previous = os.umask(umask)
    try:
        with report_directory(tmp_path / "report") as staging:
            write_text(staging / "sub" / "a.txt", "x")
        write_text(tmp_path / "single.txt", "y")
    finally:
        os.umask(previous)
    assert _mode(tmp_path / "report") == dir_mode
    assert _mode(tmp_path / "report" / "sub") == dir_mode
    assert _mode(tmp_path / "report" / "sub" / "a.txt") == file_mode
    assert _mode(tmp_path / "single.txt") == file_mode


def _invoke(*args: str):
    return CliRunner().invoke(app, list(args))


def _one_error_line(output: str) -> str:
    lines = [line for line in output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: "), output
    return lines[0]


def test_a_rerun_leaves_no_stale_file(tmp_path: Path) -> None:
    out = tmp_path / "out"
    first = _invoke("replay", str(NMEA), "--no-plots", "--quiet", "--out", str(out))
    assert first.exit_code == 0, first.output
    before = {p.name for p in (out / "encounters").iterdir()}
    stricter = _invoke(
        "replay", str(NMEA), "--no-plots", "--quiet", "--out", str(out), "--cpa-req-m", "20"
    )
    assert stricter.exit_code == 0, stricter.output
    after = {p.name for p in (out / "encounters").iterdir()}
    assert after < before  # the encounters of the first run are gone, not left beside
    listed = (out / "encounters.csv").read_text().count("\n") - 1
    assert len(after) == listed
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no staging left


def test_a_foreign_directory_is_refused_unless_overwrite(tmp_path: Path) -> None:
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    refused = _invoke("stats", str(DMA26), "--quiet", "--out", str(out))
    assert refused.exit_code == OutputError.exit_code
    line = _one_error_line(refused.output)
    assert "not a colregs9 report and holds 1 item(s): thesis.tex;" in line
    assert (out / "thesis.tex").read_text() == "precious"
    # --overwrite writes the report beside the user's file, which stays
    beside = _invoke("stats", str(DMA26), "--quiet", "--out", str(out), "--overwrite")
    assert beside.exit_code == 0, beside.output
    assert (out / "thesis.tex").read_text() == "precious" and (out / "run.json").is_file()
    # a colregs9 report is replaced without --overwrite once only its own files are there
    (out / "thesis.tex").unlink()
    again = _invoke("stats", str(DMA26), "--quiet", "--out", str(out))
    assert again.exit_code == 0, again.output


@pytest.mark.parametrize("kind", ["file", "under-a-file", "current-directory"])
def test_a_bad_out_is_one_error_before_any_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, kind: str
) -> None:
    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    out = {"file": a_file, "under-a-file": a_file / "report", "current-directory": Path(".")}[kind]
    monkeypatch.chdir(tmp_path)
    for command in (["replay", str(NMEA), "--no-plots"], ["stats", str(DMA26)]):
        result = _invoke(*command, "--quiet", "--out", str(out))
        assert result.exit_code == OutputError.exit_code, result.output
        assert str(out) in _one_error_line(result.output)
    assert a_file.read_text() == "x"


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write anywhere")
def test_an_unwritable_parent_is_refused(tmp_path: Path) -> None:
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        with pytest.raises(OutputError, match="no permission"):
            check_out_dir(locked / "report", command="replay")
    finally:
        locked.chmod(0o700)


def test_a_failed_run_leaves_the_old_report(tmp_path: Path) -> None:
    out = tmp_path / "report"
    with report_directory(out) as staging:
        write_text(staging / "run.json", '{"tool": "colregs9"}')
    with pytest.raises(RuntimeError), report_directory(out) as staging:
        write_text(staging / "half.txt", "half")
        raise RuntimeError("the analysis failed")
    assert sorted(p.name for p in out.iterdir()) == ["run.json"]
    assert [p.name for p in tmp_path.iterdir()] == ["report"]


@pytest.mark.parametrize(
    "command",
    [
        ["simulate", "SCENARIO", "--out", "OUT/x.csv"],
        ["swing", "--out", "OUT/swing"],
        ["chart", "CHART", "--draught", "2", "--out", "OUT/chart.png"],
        ["demo", "--out", "OUT/demo"],
    ],
)
def test_every_writer_gives_one_error_line_for_an_out_under_a_file(
    tmp_path: Path, command: list[str]
) -> None:
    from fixture_files import SANDIEGO_ENC, SCENARIOS

    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    replacements = {
        "SCENARIO": str(SCENARIOS / "greenhopper_restricted.toml"),
        "CHART": str(SANDIEGO_ENC),
    }
    args = [replacements.get(a, a).replace("OUT", str(a_file)) for a in command]
    result = _invoke(*args, "--quiet")
    assert result.exit_code == OutputError.exit_code, result.output
    assert f"lies under {a_file}, which is a file" in _one_error_line(result.output)


def _demo(out: Path, *options: str):
    from fixture_files import GREENHOPPER_QUERY, MODELLED_CHART, SCENARIOS

    return _invoke(
        *("demo", "--out", str(out), "--scenarios", str(SCENARIOS)),
        *("--chart", str(MODELLED_CHART), "--query", str(GREENHOPPER_QUERY), "--quiet"),
        *options,
    )


def _swing(out: Path, *options: str):
    return _invoke("swing", "--out", str(out), "--quiet", *options)


@pytest.mark.parametrize("run", [_swing, _demo], ids=["swing", "demo"])
def test_swing_and_demo_refuse_a_foreign_directory_unless_overwrite(tmp_path: Path, run) -> None:
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    refused = run(out)
    assert refused.exit_code == OutputError.exit_code == 2
    assert "not a colregs9 report" in _one_error_line(refused.output)
    assert [p.name for p in out.iterdir()] == ["thesis.tex"]
    assert [p.name for p in tmp_path.iterdir()] == ["mine"]  # no staging left either
    beside = run(out, "--overwrite")
    assert beside.exit_code == 0, beside.output
    assert (out / "thesis.tex").read_text() == "precious" and (out / "run.json").is_file()
    assert "thesis.tex" not in json.loads((out / "run.json").read_text())[FILES_KEY]


@pytest.mark.parametrize("run", [_swing, _demo], ids=["swing", "demo"])
def test_swing_and_demo_rerun_into_a_fresh_directory(tmp_path: Path, run) -> None:
    out = tmp_path / "out"
    first = run(out)
    assert first.exit_code == 0, first.output
    written = sorted(p.relative_to(out) for p in out.rglob("*"))
    listed = json.loads((out / "run.json").read_text())[FILES_KEY]
    assert listed == sorted(str(p) for p in written if (out / p).is_file())
    # Files of an earlier run, which its run.json lists (the demo's replays too).
    stale = ["stale.png", *(f"{p.name}/stale.csv" for p in out.iterdir() if p.is_dir())]
    for name in stale:
        (out / name).write_text("an earlier run's file")
    (out / "run.json").write_text(
        json.dumps({**json.loads((out / "run.json").read_text()), FILES_KEY: listed + stale})
    )
    again = run(out)  # a colregs9 report: replaced without --overwrite
    assert again.exit_code == 0, again.output
    assert sorted(p.relative_to(out) for p in out.rglob("*")) == written
    assert [p.name for p in tmp_path.iterdir()] == ["out"]


def test_the_demo_names_its_files_where_they_are_after_the_swap(tmp_path: Path) -> None:
    out = tmp_path / "demo"
    result = _demo(out)
    assert result.exit_code == 0, result.output
    assert ".new" not in result.output
    for scenario in ("greenhopper_restricted", "greenhopper_not_restricted"):
        assert str(out / f"{scenario}.png") in result.output
        manifest = json.loads((out / scenario / "run.json").read_text())
        (ais,) = manifest["inputs"]
        assert Path(ais["path"]) == out / f"simulate-{scenario}.csv"
        # each replay still lists its own files, relative to its directory
        assert "pairs.csv" in manifest[FILES_KEY] and "run.json" in manifest[FILES_KEY]
    assert json.loads((out / "run.json").read_text())["command"] == "demo"


@pytest.mark.parametrize(
    ("command", "notice"),
    [
        (["replay", str(NMEA), "--no-plots", "--out", "OUT"], "Reports in OUT"),
        (["stats", str(DMA26), "--out", "OUT"], "Reports in OUT"),
        (["swing", "--out", "OUT"], "Reports in OUT"),
        (["simulate", "SCENARIO", "--out", "OUT/x.csv"], "AIS written to OUT/x.csv"),
        (["ingest", str(DMA26), "--out", "OUT"], "Dataset in OUT"),
    ],
    ids=["replay", "stats", "swing", "simulate", "ingest"],
)
def test_the_notice_of_what_was_written_is_on_stderr_and_quiet_drops_it(
    tmp_path: Path, command: list[str], notice: str
) -> None:
    from fixture_files import SCENARIOS

    out = str(tmp_path / "out")
    scenario = str(SCENARIOS / "greenhopper_restricted.toml")
    args = [a.replace("OUT", out).replace("SCENARIO", scenario) for a in command]
    notice = notice.replace("OUT", out)
    loud = _invoke(*args)
    assert loud.exit_code == 0, loud.output
    assert notice in loud.stderr and notice not in loud.stdout
    assert loud.stdout.strip(), "the results are on stdout"
    # Into another dataset: a second ingest of the same file into one adds nothing.
    again = out + "-again" if command[0] == "ingest" else out
    quiet = _invoke(*[a.replace(out, again) for a in args], "--quiet")
    assert quiet.exit_code == 0, quiet.output
    assert quiet.stderr == "" and quiet.stdout == loud.stdout.replace(out, again)


@pytest.mark.parametrize("command", ["stats", "replay"])
def test_an_out_that_holds_an_input_is_refused_even_with_overwrite(
    tmp_path: Path, command: str
) -> None:
    from colregs9_cli.jobs.ingest import ingest

    given = tmp_path / DMA26.name
    given.write_bytes(DMA26.read_bytes())
    dataset = tmp_path / "dataset"
    ingest([given], dataset)
    for source, out in ((given, tmp_path), (dataset, dataset)):
        result = CliRunner().invoke(app, [command, str(source), "--out", str(out), "--overwrite"])
        assert result.exit_code == 2, result.output
        (line,) = result.stderr.strip().splitlines()
        assert line.startswith(f"Error: {out}: --out is or holds the input {source}")
    assert given.read_bytes() == DMA26.read_bytes()
    assert (dataset / "colregs9-dataset.json").exists()


def test_a_file_its_writer_made_again_follows_the_umask(tmp_path: Path) -> None:
    from colregs9_cli.outputs import atomic_path

    previous = os.umask(0o002)
    try:
        with atomic_path(tmp_path / "made.gpkg", suffix=".gpkg") as tmp:
            tmp.unlink()  # as GDAL does, then SQLite creates it 0644
            fd = os.open(tmp, os.O_CREAT | os.O_WRONLY, 0o644)
            os.close(fd)
    finally:
        os.umask(previous)
    assert _mode(tmp_path / "made.gpkg") == 0o664


def test_an_out_that_holds_the_query_is_refused(tmp_path: Path) -> None:
    query = tmp_path / "q.toml"
    query.write_text('name = "q"\n')
    result = CliRunner().invoke(
        app, ["stats", str(DMA26), "--query", str(query), "--out", str(tmp_path), "--overwrite"]
    )
    assert result.exit_code == 2, result.output
    assert f"--out is or holds the input {query}" in result.stderr
    assert query.exists()
