"""A rerun into a report directory replaces colregs9's files (those its run.json lists) and
nothing else: the user's files stay, or the rerun refuses with one Error line (issue 30)."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from colregs9_cli.cli import app
from colregs9_cli.errors import OutputError
from colregs9_cli.outputs import (
    DATASET_MARKER,
    FILES_KEY,
    check_out_dir,
    check_out_file,
    report_directory,
    write_json,
    write_text,
)

from fixture_files import DMA26, NMEA


def _write_report(out: Path, command: str, files: dict[str, str], overwrite: bool = False) -> None:
    """A report of ``command`` holding ``files`` (path: content), as the commands write one."""
    with report_directory(out, overwrite) as staging:
        for name, text in files.items():
            write_text(staging / name, text)
        write_json(staging / "run.json", {"tool": "colregs9", "command": command})


def _tree(directory: Path) -> dict[str, str]:
    return {
        p.relative_to(directory).as_posix(): p.read_bytes().decode("latin-1")
        for p in sorted(directory.rglob("*"))
        if p.is_file()
    }


def _listed(directory: Path) -> list[str]:
    return json.loads((directory / "run.json").read_text())[FILES_KEY]


def test_run_json_lists_every_file_written(tmp_path: Path) -> None:
    out = tmp_path / "r"
    _write_report(out, "replay", {"pairs.csv": "p", "encounters/a.csv": "a"})
    assert _listed(out) == ["encounters/a.csv", "pairs.csv", "run.json"]


def test_the_users_files_refuse_a_rerun_naming_them(tmp_path: Path) -> None:
    out = tmp_path / "r"
    _write_report(out, "replay", {"pairs.csv": "p"})
    (out / "notes.txt").write_text("my notes")
    (out / "project.qgz").write_bytes(b"PK\x03\x04")
    with pytest.raises(OutputError) as refused:
        check_out_dir(out, command="replay")
    message = str(refused.value)
    assert "\n" not in message
    assert "holds 2 item(s) that colregs9 did not write there: notes.txt, project.qgz;" in message
    assert "--overwrite" in message
    # Many: the first three by name, and how many more.
    for k in range(4):
        (out / f"z{k}.txt").write_text("")
    with pytest.raises(
        OutputError, match=r"6 item\(s\) .*: notes\.txt, project\.qgz, z0\.txt and 3 more;"
    ):
        check_out_dir(out, command="replay")


def test_overwrite_replaces_only_colregs9s_files(tmp_path: Path) -> None:
    out = tmp_path / "r"
    _write_report(out, "replay", {"pairs.csv": "old", "encounters/old.csv": "old"})
    mine = {
        "notes.txt": "my notes",
        "project.qgz": "a QGIS project",
        "qgis/styles.qml": "a style",
        "encounters/remark.txt": "a remark beside the series",
    }
    for name, text in mine.items():
        (out / name).parent.mkdir(exist_ok=True)
        (out / name).write_text(text)
    check_out_dir(out, overwrite=True, command="replay")
    _write_report(out, "replay", {"pairs.csv": "new", "encounters/new.csv": "new"}, True)
    assert _tree(out) == {
        **mine,
        "pairs.csv": "new",
        "encounters/new.csv": "new",
        "run.json": (out / "run.json").read_text(),
    }
    assert _listed(out) == ["encounters/new.csv", "pairs.csv", "run.json"]
    assert [p.name for p in tmp_path.iterdir()] == ["r"]  # no staging left


def test_a_report_of_another_command_is_not_replaced_without_overwrite(tmp_path: Path) -> None:
    out = tmp_path / "r"
    _write_report(out, "replay", {"pairs.csv": "p"})
    with pytest.raises(OutputError) as refused:
        check_out_dir(out, command="stats")
    assert "holds a colregs9 replay report, which a stats report would replace" in str(
        refused.value
    )
    check_out_dir(out, command="replay")
    check_out_dir(out, overwrite=True, command="stats")


def test_a_report_from_before_the_list_owns_its_commands_files(tmp_path: Path) -> None:
    """A run.json without ``files``: the files a report of its command writes are colregs9's."""
    out = tmp_path / "r"
    out.mkdir()
    (out / "run.json").write_text(json.dumps({"tool": "colregs9", "command": "replay"}))
    for name in ("pairs.csv", "encounters.csv", "index.html", "encounters/x.csv"):
        (out / name).parent.mkdir(exist_ok=True)
        (out / name).write_text("old")
    check_out_dir(out, command="replay")  # only colregs9's files: no refusal
    (out / "encounters" / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match=r"1 item\(s\) .*: encounters/notes.txt;"):
        check_out_dir(out, command="replay")
    _write_report(out, "replay", {"pairs.csv": "new"}, overwrite=True)
    assert set(_tree(out)) == {"pairs.csv", "run.json", "encounters/notes.txt"}


def test_a_legacy_demo_owns_its_scenarios_replays(tmp_path: Path) -> None:
    out = tmp_path / "demo"
    (out / "s").mkdir(parents=True)
    (out / "run.json").write_text(json.dumps({"tool": "colregs9", "command": "demo"}))
    (out / "s" / "run.json").write_text(json.dumps({"tool": "colregs9", "command": "replay"}))
    for name in ("simulate-s.csv", "s.png", "s/pairs.csv"):
        (out / name).write_text("old")
    check_out_dir(out, command="demo")
    (out / "s" / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match=r"s/notes\.txt"):
        check_out_dir(out, command="demo")


def test_readers_sidecars_go_with_their_file_and_litter_is_no_reason_to_refuse(
    tmp_path: Path,
) -> None:
    out = tmp_path / "r"
    _write_report(out, "replay", {"report.gpkg": "g", "pairs.csv": "p"})
    for name in ("report.gpkg-wal", "report.gpkg-shm", ".DS_Store", ".~lock.pairs.csv#"):
        (out / name).write_text("")
    check_out_dir(out, command="replay")
    _write_report(out, "replay", {"report.gpkg": "g2"})
    # SQLite's files went with the GeoPackage they belong to; the litter stays
    assert set(_tree(out)) == {"report.gpkg", "run.json", ".DS_Store", ".~lock.pairs.csv#"}


def test_a_dataset_never_takes_a_report(tmp_path: Path) -> None:
    out = tmp_path / "dataset"
    out.mkdir()
    (out / DATASET_MARKER).write_text("{}")
    for overwrite in (False, True):
        with pytest.raises(OutputError, match="is a dataset of colregs9 ingest"):
            check_out_dir(out, overwrite, command="replay")
        # Nor does a directory inside it, new or already there.
        for inside in (out / "report", out / "date=2024-09-09" / "report"):
            with pytest.raises(OutputError, match=r"lies inside .*, a dataset of colregs9 ingest"):
                check_out_dir(inside, overwrite, command="replay")


def test_a_file_of_a_report_is_not_an_out_file(tmp_path: Path) -> None:
    """``chart --out`` and ``simulate --out`` do not replace a file that a report lists."""
    out = tmp_path / "r"
    _write_report(out, "replay", {"report.gpkg": "g", "encounters/a.png": "a"})
    for name in ("report.gpkg", "encounters/a.png", "run.json"):
        with pytest.raises(OutputError, match="is a file of the colregs9 replay report in"):
            check_out_file(out / name)
    check_out_file(out / "chart.png")  # beside the report: the user's file
    check_out_file(tmp_path / "elsewhere.png")


def test_a_file_put_there_during_the_run_with_a_reports_name_refuses(tmp_path: Path) -> None:
    out = tmp_path / "r"
    _write_report(out, "replay", {"pairs.csv": "p"})
    clash = r"with the names of files of the new report: index\.md;"
    with pytest.raises(OutputError, match=clash), report_directory(out) as staging:
        write_text(staging / "pairs.csv", "new")
        write_text(staging / "index.md", "new")
        write_json(staging / "run.json", {"tool": "colregs9", "command": "replay"})
        (out / "index.md").write_text("the user's, made while the run ran")
    assert _tree(out)["index.md"] == "the user's, made while the run ran"
    assert _tree(out)["pairs.csv"] == "p"
    assert [p.name for p in tmp_path.iterdir()] == ["r"]


def test_a_failed_swap_puts_the_users_files_back(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "r"
    _write_report(out, "replay", {"pairs.csv": "old"})
    (out / "notes.txt").write_text("mine")
    replace = os.replace

    def failing_swap(source, target) -> None:
        if str(source).endswith(".new"):
            raise OSError(28, "No space left on device")
        replace(source, target)

    monkeypatch.setattr(os, "replace", failing_swap)
    with pytest.raises(OutputError, match="No space left on device"):
        _write_report(out, "replay", {"pairs.csv": "new"}, overwrite=True)
    monkeypatch.undo()
    assert set(_tree(out)) == {"pairs.csv", "notes.txt", "run.json"}
    assert _tree(out)["pairs.csv"] == "old" and _tree(out)["notes.txt"] == "mine"
    assert [p.name for p in tmp_path.iterdir()] == ["r"]


_NAMES = st.sampled_from(["a.csv", "b.png", "notes.txt", "x.qgz", "sub/c.csv", "sub/d.txt", "e"])


@settings(max_examples=25, deadline=None)
@given(
    old=st.sets(_NAMES, max_size=5),
    new=st.sets(_NAMES, max_size=5),
    users=st.sets(_NAMES, max_size=4),
)
def test_every_users_file_survives_or_the_rerun_refuses(
    old: set[str], new: set[str], users: set[str]
) -> None:
    """Whatever the old report, the new one and the user's files: a rerun without
    --overwrite refuses and changes nothing, or leaves every file of the user's as it was;
    with --overwrite, every one of them whose name the new report does not take; and no
    file of the old report stays unless the new one wrote it again."""
    users = users - old  # a user's file is one colregs9 did not write
    for overwrite in (False, True):
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "r"
            _write_report(out, "replay", {name: "old" for name in old})
            placed = {}
            for name in users:
                if (out / name).parent.is_file() or (out / name).exists():
                    continue
                (out / name).parent.mkdir(exist_ok=True)
                (out / name).write_text("user")
                placed[name] = "user"
            before = _tree(out)
            try:
                check_out_dir(out, overwrite, command="replay")
                _write_report(out, "replay", {name: "new" for name in new}, overwrite)
            except OutputError:
                assert placed and not overwrite
                assert _tree(out) == before
                continue
            after = _tree(out)
            assert overwrite or not placed
            for name, text in placed.items():
                assert after[name] == ("new" if name in new else text), name
            for name in old - new - {"run.json"}:
                assert name not in after, name
            assert {n for n, t in after.items() if t == "new"} == new
            assert [p.name for p in Path(tmp).iterdir()] == ["r"]


def _invoke(*args: str):
    return CliRunner().invoke(app, list(args))


def _one_error_line(output: str) -> str:
    lines = [line for line in output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: "), output
    return lines[0]


def test_a_replay_rerun_keeps_the_users_notes_and_qgis_project(tmp_path: Path) -> None:
    """The issue's case, through the CLI: refused (exit 2, one line naming the files) without
    --overwrite, the user's files untouched; with --overwrite, the report is replaced and
    they stay."""
    out = tmp_path / "replay"
    first = _invoke("replay", str(NMEA), "--no-plots", "--quiet", "--out", str(out))
    assert first.exit_code == 0, first.output
    report = _tree(out)
    (out / "notes.txt").write_text("TRADITION: check the pilot's log")
    (out / "project.qgz").write_bytes(b"PK\x03\x04 a QGIS project")
    refused = _invoke("replay", str(NMEA), "--no-plots", "--quiet", "--out", str(out))
    assert refused.exit_code == 2
    line = _one_error_line(refused.output)
    assert "notes.txt, project.qgz" in line and str(out) in line
    assert {k: v for k, v in _tree(out).items() if k in report} == report
    kept = _invoke(
        *("replay", str(NMEA), "--no-plots", "--quiet", "--out", str(out)),
        *("--cpa-req-m", "20", "--overwrite"),
    )
    assert kept.exit_code == 0, kept.output
    assert (out / "notes.txt").read_text() == "TRADITION: check the pilot's log"
    assert (out / "project.qgz").read_bytes() == b"PK\x03\x04 a QGIS project"
    listed = _listed(out)
    assert "notes.txt" not in listed and "project.qgz" not in listed
    assert sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file()) == sorted(
        [*listed, "notes.txt", "project.qgz"]
    )


def test_stats_into_a_replay_report_refuses(tmp_path: Path) -> None:
    out = tmp_path / "report"
    first = _invoke("replay", str(NMEA), "--no-plots", "--quiet", "--out", str(out))
    assert first.exit_code == 0, first.output
    report = _tree(out)
    refused = _invoke("stats", str(DMA26), "--quiet", "--out", str(out))
    assert refused.exit_code == 2
    line = _one_error_line(refused.output)
    assert "a colregs9 replay report, which a stats report would replace" in line
    assert _tree(out) == report
    ingest = _invoke("ingest", str(DMA26), "--quiet", "--out", str(out))
    assert ingest.exit_code == 2
    assert "holds a colregs9 replay report, not a dataset" in _one_error_line(ingest.output)
    assert _tree(out) == report
