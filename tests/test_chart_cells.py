"""S-57 cells: their edition, update number and issue date are reported, and a gap in their
update sequence is never silent (GDAL would apply the updates before it and stop)."""

from __future__ import annotations

import hashlib
import json
import re
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

from colregs9_cli.charts.cells import s57_cell_info
from colregs9_cli.charts.s57_records import record_count
from colregs9_cli.charts.sources import read_charts
from colregs9_cli.charts.water import project_charts
from colregs9_cli.cli import app
from colregs9_cli.errors import ChartError
from colregs9_cli.jobs.replay import run_replay

from fixture_files import ROOT, SANDIEGO_AIS, SANDIEGO_ENC


def test_the_sandiego_cell_with_both_updates() -> None:
    cell = s57_cell_info(SANDIEGO_ENC)
    assert (cell.edition, cell.update_number, cell.issue_date) == (56, 2, "20250428")
    assert (cell.purpose, cell.scale) == (5, 12_000)  # harbour, 1:12,000 (DSID)
    assert [p.name for p in cell.update_files] == ["US5CA72M.001", "US5CA72M.002"]
    assert cell.missing_updates == ()
    assert read_charts([SANDIEGO_ENC]).update_gaps == {}


def test_a_gap_in_the_middle_names_the_missing_update(tmp_path: Path) -> None:
    # .001 and .003 beside the base cell, .002 missing (the San Diego .002 stands in for .003)
    for source, name in (("000", "000"), ("001", "001"), ("002", "003")):
        shutil.copyfile(SANDIEGO_ENC.with_suffix(f".{source}"), tmp_path / f"US5CA72M.{name}")
    with pytest.raises(ChartError, match=r"US5CA72M\.002 missing beside US5CA72M\.001, "):
        read_charts([tmp_path / "US5CA72M.000"])
    (cell,) = read_charts([tmp_path / "US5CA72M.000"], accept_gaps=True).cells
    assert cell.missing_updates == ("US5CA72M.002",)
    assert cell.update_number == 1  # GDAL applied .001 and stopped at the gap


@pytest.fixture()
def gap(tmp_path: Path) -> Path:
    """The cell with .002 but without .001."""
    for name in ("US5CA72M.000", "US5CA72M.002"):
        shutil.copyfile(SANDIEGO_ENC.with_name(name), tmp_path / name)
    return tmp_path / "US5CA72M.000"


def test_a_gap_is_an_error_naming_the_missing_file(gap: Path) -> None:
    with pytest.raises(ChartError, match=r"US5CA72M\.001 missing.*--accept-chart-gaps"):
        read_charts([gap])


def test_an_accepted_gap_is_the_cell_as_updated_up_to_it(gap: Path) -> None:
    source = read_charts([gap], accept_gaps=True)
    (cell,) = source.cells
    assert cell.missing_updates == ("US5CA72M.001",)
    assert cell.update_number == 0  # nothing after the gap was applied
    assert cell.edition == 56
    # the acceptance is on the source and the chart, for run.json and the summary
    assert source.update_gaps == {"US5CA72M.000": ("US5CA72M.001",)}
    assert project_charts(source).update_gaps == source.update_gaps


def test_the_chart_command_prints_the_cell_and_refuses_a_gap(gap: Path) -> None:
    shown = CliRunner().invoke(app, ["chart", str(SANDIEGO_ENC), "--quiet"])
    assert shown.exit_code == 0, shown.output
    assert (
        "US5CA72M.000: edition 56, update 2, issued 20250428, purpose 5 (harbour), "
        "scale 1:12000 (2 update file(s))"
    ) in shown.output
    refused = CliRunner().invoke(app, ["chart", str(gap), "--quiet"])
    assert refused.exit_code == ChartError.exit_code
    lines = [line for line in refused.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: ") and "US5CA72M.001" in lines[0]
    accepted = CliRunner().invoke(app, ["chart", str(gap), "--quiet", "--accept-chart-gaps"])
    assert accepted.exit_code == 0 and "GAP ACCEPTED" in accepted.output


def test_replay_records_the_cells_in_run_json(tmp_path: Path, gap: Path) -> None:
    with pytest.raises(ChartError):
        run_replay([SANDIEGO_AIS], chart_paths=[gap], out_dir=tmp_path / "refused", plots=False)
    result = run_replay(
        [SANDIEGO_AIS],
        chart_paths=[gap],
        out_dir=tmp_path / "accepted",
        plots=False,
        accept_chart_gaps=True,
    )
    manifest = json.loads((result.out_dir / "run.json").read_text(encoding="utf-8"))
    (cell,) = manifest["chart_cells"]
    assert cell["edition"] == 56 and cell["update_number"] == 0
    assert cell["missing_updates"] == ["US5CA72M.001"]
    assert manifest["accept_chart_gaps"] is True
    # The update that the gap left unapplied is recorded too, with its hash.
    (chart,) = manifest["charts"]
    assert chart["missing_updates"] == ["US5CA72M.001"]
    files = {Path(f["path"]).name: f for f in chart["files"]}
    assert set(files) == {"US5CA72M.000", "US5CA72M.002"}
    assert files["US5CA72M.000"]["applied"] and not files["US5CA72M.002"]["applied"]
    for item in files.values():
        assert item["sha256"] == hashlib.sha256(Path(item["path"]).read_bytes()).hexdigest()


@pytest.mark.parametrize(
    ("broken", "applied"), [("001", "none: .001 could not"), ("002", "up to .001: .002 could not")]
)
def test_an_update_gdal_could_not_apply_is_an_error(
    tmp_path: Path, broken: str, applied: str
) -> None:
    # GDAL skips a corrupt update and every later one without a word. This one has whole
    # ISO 8211 record (the data descriptive record of another cell), so only GDAL can tell.
    for suffix in ("000", "001", "002"):
        shutil.copyfile(SANDIEGO_ENC.with_suffix(f".{suffix}"), tmp_path / f"US5CA72M.{suffix}")
    (tmp_path / f"US5CA72M.{broken}").write_bytes(
        ANNAPOLIS_ENC.read_bytes()[: _record_starts(ANNAPOLIS_ENC)[1]]
    )
    with pytest.raises(ChartError, match=f"GDAL applied {applied}"):
        read_charts([tmp_path / "US5CA72M.000"])


def test_a_cell_in_feet_is_refused(tmp_path: Path) -> None:

    annapolis = SANDIEGO_ENC.parents[1] / "charts" / "noaa_enc_US5MD1MC.000"
    data = bytearray(annapolis.read_bytes())
    # The DSPM record: RCNM 20 … CSCL 12000, then DUNI 1 (metres) and HUNI 1.
    found = re.search(rb"\x14....\x02\x10\x0c\xe0\x2e\x00\x00\x01\x01", data, re.S)
    assert found is not None
    data[found.start() + 12] = 3  # DUNI: feet
    feet = tmp_path / "US5MD1MC.000"
    feet.write_bytes(bytes(data))
    with pytest.raises(ChartError, match="depths in feet"):
        read_charts([feet])
    assert read_charts([annapolis]).cells[0].name


def test_charts_beyond_the_reach_of_one_frame_are_refused() -> None:
    annapolis = SANDIEGO_ENC.parents[1] / "charts" / "noaa_enc_US5MD1MC.000"
    source = read_charts([SANDIEGO_ENC, annapolis])
    with pytest.raises(ChartError, match="beyond 400 km of the centre of the one map frame"):
        project_charts(source)
    (near,) = source.near([32.7], [-117.2], margin_deg=0.25).paths
    assert near == SANDIEGO_ENC
    assert project_charts(source.near([32.7], [-117.2], margin_deg=0.25)).detail_order


ANNAPOLIS_ENC = ROOT / "fixtures" / "charts" / "noaa_enc_US5MD1MC.000"


def _record_starts(path: Path) -> list[int]:
    """Where each ISO 8211 record of ``path`` starts (each leader opens with its length)."""
    data = path.read_bytes()
    starts, position = [], 0
    while position < len(data):
        starts.append(position)
        position += int(data[position : position + 5])
    return starts


def test_the_real_cells_hold_every_record_their_dssi_lists() -> None:
    # Annapolis, by GDAL's DSSI: 37 meta and 3,252 geo feature records, 594 isolated and
    # 3,897 connected nodes, 4,281 edges; with the DDR, DSID and DSPM records 12,064.
    assert record_count(ANNAPOLIS_ENC) == len(_record_starts(ANNAPOLIS_ENC)) == 12_064
    # San Diego: 54 + 7,472 + 5 feature records, 695 + 10,899 nodes, 11,246 edges, + 3.
    assert record_count(SANDIEGO_ENC) == 30_374
    assert [record_count(u) for u in s57_cell_info(SANDIEGO_ENC).update_files] == [38, 3]


@pytest.mark.parametrize("kept", [0.05, 0.9, -1])
def test_a_cell_cut_between_two_records_is_refused(tmp_path: Path, kept: float) -> None:
    """GDAL reads it without a word: at 90 % of the records, 52 of the 249 depth areas."""
    starts = _record_starts(ANNAPOLIS_ENC)
    cut = starts[-1] if kept == -1 else starts[int(len(starts) * kept)]
    cell = tmp_path / ANNAPOLIS_ENC.name
    cell.write_bytes(ANNAPOLIS_ENC.read_bytes()[:cut])
    listed = 12_063
    with pytest.raises(ChartError, match=rf"cut short: its DSSI field lists {listed} records"):
        read_charts([cell])


def test_a_cell_cut_inside_a_record_is_refused(tmp_path: Path) -> None:
    cell = tmp_path / ANNAPOLIS_ENC.name
    cell.write_bytes(ANNAPOLIS_ENC.read_bytes()[:1_000_000])
    with pytest.raises(ChartError, match=r"cut short or corrupt: a record of the file runs past"):
        read_charts([cell])


def test_an_update_cut_inside_a_record_is_refused(tmp_path: Path) -> None:
    for suffix in ("000", "001", "002"):
        shutil.copyfile(SANDIEGO_ENC.with_suffix(f".{suffix}"), tmp_path / f"US5CA72M.{suffix}")
    update = tmp_path / "US5CA72M.001"
    update.write_bytes(update.read_bytes()[:-10])
    result = CliRunner().invoke(app, ["chart", str(tmp_path / "US5CA72M.000")])
    assert result.exit_code == 2
    assert result.stderr.strip().splitlines() == [
        f"Error: {update}: cut short or corrupt: a record of the file runs past its end or has "
        "no length in its leader (ISO 8211); download the cell and its updates again"
    ]


def test_swapped_updates_are_refused_naming_the_first_out_of_place(tmp_path: Path) -> None:
    shutil.copyfile(SANDIEGO_ENC, tmp_path / "US5CA72M.000")
    shutil.copyfile(SANDIEGO_ENC.with_suffix(".001"), tmp_path / "US5CA72M.002")
    shutil.copyfile(SANDIEGO_ENC.with_suffix(".002"), tmp_path / "US5CA72M.001")
    with pytest.raises(ChartError) as caught:
        read_charts([tmp_path / "US5CA72M.000"])
    assert str(caught.value).startswith(
        f"{tmp_path / 'US5CA72M.001'}: by its DSID, update 2 of edition 56 of cell US5CA72M, "
        "not update 1 of edition 56 of US5CA72M;"
    )


def test_an_update_of_another_cell_is_refused_naming_it(tmp_path: Path) -> None:
    """GDAL took the foreign file's update number (0), which blamed .001 for .002."""
    for suffix in ("000", "001"):
        shutil.copyfile(SANDIEGO_ENC.with_suffix(f".{suffix}"), tmp_path / f"US5CA72M.{suffix}")
    # The Annapolis cell's first records (DDR, DSID, DSPM) under the name of update 2.
    foreign = tmp_path / "US5CA72M.002"
    foreign.write_bytes(ANNAPOLIS_ENC.read_bytes()[: _record_starts(ANNAPOLIS_ENC)[3]])
    with pytest.raises(ChartError) as caught:
        read_charts([tmp_path / "US5CA72M.000"])
    assert str(caught.value).startswith(
        f"{foreign}: by its DSID, update 0 of edition 4 of cell US5MD1MC, not update 2 of "
        "edition 56 of US5CA72M;"
    )
