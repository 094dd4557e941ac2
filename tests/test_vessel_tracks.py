"""report.gpkg's ``vessel_tracks`` (every vessel's track, time as M) and ``--domains``
(issue 30): the vertices are the decided reports, thinned the same for any slab length and
number of workers; the layer's M values are the reports' times."""

from __future__ import annotations

import json
import sqlite3
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pyogrio
import pytest
import shapely
from typer.testing import CliRunner

from colregs9_cli.ais.load import load_ais
from colregs9_cli.cli import app
from colregs9_cli.core.tracks import TrackParams, empty_carry, report_table, segment_reports
from colregs9_cli.jobs.replay import run_replay
from colregs9_cli.jobs.slabs import TRACK_VERTEX_SLOT_S
from colregs9_cli.report.replay_geopackage import (
    Domains,
    encounter_layers,
    vessel_track_layer,
    write_replay_geopackage,
)

from fixture_files import NMEA


@pytest.fixture(scope="module")
def nmea_report(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("vessel-tracks")
    return run_replay([NMEA], out_dir=out, plots=False)


@pytest.fixture(scope="module")
def decided() -> pd.DataFrame:
    """The NMEA sample's decided reports, segmented in one go (no slabs)."""
    reports = report_table(load_ais([NMEA]).positions)
    return segment_reports(reports, empty_carry(), TrackParams(), None).kept


def _read(path: Path, layer: str) -> tuple[pd.DataFrame, np.ndarray]:
    """A layer's fields and geometries, M values kept (pyogrio's ``read_arrow`` gives GDAL's
    ISO WKB; it warns that it names the type without M)."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Measured \\(M\\) geometry types are not supported")
        meta, table = pyogrio.raw.read_arrow(path, layer=layer)
    frame = table.to_pandas()
    return frame.drop(columns=meta["geometry_name"]), shapely.from_wkb(
        frame[meta["geometry_name"]].to_numpy()
    )


def _layers(path: Path) -> list[str]:
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "Measured \\(M\\) geometry types are not supported")
        return [str(name) for name in pyogrio.list_layers(path)[:, 0]]


def test_the_vertices_are_the_decided_reports_thinned(nmea_report, decided) -> None:
    """Each vertex is a decided report (same time, latitude, longitude); each piece starts
    at a segment start; within a piece one vertex per 10 s slot of the UTC grid, plus the
    piece's last report; ``reports`` adds up to the decided reports between vertices."""
    vertices = nmea_report.vessel_tracks
    kept = decided.reset_index(drop=True)
    assert vertices["reports"].sum() == len(kept) == nmea_report.manifest["tracks"]["reports_used"]
    joined = vertices.merge(kept, on=["mmsi", "t_s"], how="left", validate="one_to_one")
    assert joined["lat_deg_x"].equals(joined["lat_deg_y"])
    assert joined["lon_deg_x"].equals(joined["lon_deg_y"])
    # The same rule, worked out on the one-go reports vessel by vessel.
    mmsi = kept["mmsi"].to_numpy()
    start = kept["segment_start"].to_numpy(bool) | np.r_[True, mmsi[1:] != mmsi[:-1]]
    kept = kept.assign(piece=kept.assign(s=start).groupby("mmsi")["s"].cumsum() - 1)
    slot = np.floor(kept["t_s"] / TRACK_VERTEX_SLOT_S)
    first_in_slot = ~kept.assign(slot=slot).duplicated(["mmsi", "piece", "slot"])
    last = ~kept.duplicated(["mmsi", "piece"], keep="last")
    expected = kept[first_in_slot | last]
    assert (
        vertices[["mmsi", "piece", "t_s"]]
        .reset_index(drop=True)
        .equals(expected[["mmsi", "piece", "t_s"]].reset_index(drop=True))
    )
    assert vertices.groupby(["mmsi", "piece"]).ngroups == nmea_report.counts.segments
    assert len(vertices) < len(kept)  # 20,541 of 24,652 in this sample


def test_the_vertices_do_not_depend_on_the_slab_length_or_the_workers(nmea_report) -> None:
    """One-minute slabs (spill files cut every minute) and two Dask workers (two parts of
    the vessels, each with its own files) give the same vertices."""
    overrides = {"replay": {"slab_s": 60.0}}
    short = run_replay([NMEA], overrides=overrides, write=False)
    pd.testing.assert_frame_equal(short.vessel_tracks, nmea_report.vessel_tracks)
    two = run_replay([NMEA], overrides=overrides, write=False, workers=2)
    pd.testing.assert_frame_equal(two.vessel_tracks, nmea_report.vessel_tracks)


def test_the_layer_has_time_as_m_at_every_vertex(nmea_report, decided) -> None:
    path = nmea_report.out_dir / "report.gpkg"
    fields, geometries = _read(path, "vessel_tracks")
    vertices = nmea_report.vessel_tracks
    assert (shapely.get_type_id(geometries) == shapely.GeometryType.MULTILINESTRING).all()
    assert shapely.has_m(geometries).all()
    coordinates, index = shapely.get_coordinates(geometries, include_m=True, return_index=True)
    # The sample lies far from the antimeridian: one part a piece, its vertices in order.
    assert (shapely.get_num_geometries(geometries) == 1).all()
    pieces = vertices.groupby(["mmsi", "piece"], sort=False)
    lines = vertices[pieces["t_s"].transform("size") >= 2]
    assert np.array_equal(coordinates[:, 0], lines["lon_deg"].to_numpy())
    assert np.array_equal(coordinates[:, 1], lines["lat_deg"].to_numpy())
    assert np.array_equal(coordinates[:, 2], lines["t_s"].to_numpy())
    same_feature = index[1:] == index[:-1]
    assert (np.diff(coordinates[:, 2])[same_feature] > 0).all()
    first = np.r_[True, ~same_feature]
    last = np.r_[~same_feature, True]
    milliseconds = np.round(coordinates[:, 2] * 1000.0).astype(np.int64)
    for column, at in (("start_utc", first), ("end_utc", last)):
        times = pd.to_datetime(fields[column], utc=True).dt.as_unit("ms").astype("int64")
        assert np.array_equal(times.to_numpy(), milliseconds[at])
    # Features per vessel: her pieces with two decided reports or more, counted on them.
    mmsi = decided["mmsi"].to_numpy()
    start_of_piece = decided["segment_start"].to_numpy(bool) | np.r_[True, mmsi[1:] != mmsi[:-1]]
    sizes = decided.assign(p=np.cumsum(start_of_piece)).groupby(["mmsi", "p"]).size()
    per_vessel = (sizes >= 2).groupby(level="mmsi").sum()
    found = fields.groupby("mmsi").size().reindex(per_vessel.index, fill_value=0)
    assert found.equals(per_vessel)
    # 1,110 of the sample's 1,435 vessels: the others have no piece of two reports (most
    # were heard once in its five minutes).
    assert (found >= 1).sum() == 1110 and len(found) == 1435
    # reports: the piece's decided reports.
    assert np.array_equal(fields["reports"].to_numpy(), sizes[sizes >= 2].to_numpy())


def test_a_track_across_the_antimeridian_is_cut_there() -> None:
    """Eastward across 180°: two parts, meeting at ±180° at the interpolated latitude and
    time; nothing drawn round the globe."""
    vertices = pd.DataFrame(
        {
            "mmsi": [1, 1, 1, 2],
            "piece": [0, 0, 0, 0],
            "t_s": [0.0, 10.0, 20.0, 0.0],
            "lat_deg": [10.0, 10.0, 11.0, 0.0],
            "lon_deg": [179.8, 179.9, -179.9, 0.0],
            "reports": [1, 1, 1, 1],
            "name": pd.Categorical(["A", "A", "A", "B"]),
            "ship_type": pd.Categorical([None] * 4),
            "length_m": pd.Categorical([50.0, 50.0, 50.0, np.nan]),
        }
    )
    wkb, table = vessel_track_layer(vertices)
    assert len(wkb) == 1 and table["mmsi"].tolist() == [1]  # one report is no line
    (line,) = shapely.from_wkb(wkb)
    west, east = (shapely.get_coordinates(part, include_m=True) for part in line.geoms)
    assert west.tolist() == [[179.8, 10.0, 0.0], [179.9, 10.0, 10.0], [180.0, 10.5, 15.0]]
    assert east.tolist() == [[-180.0, 10.5, 15.0], [-179.9, 11.0, 20.0]]
    assert table["length_m"].tolist() == [50.0] and table["reports"].tolist() == [3]


def test_domains_all_restricted_or_none(sandiego_replay, tmp_path: Path) -> None:
    """On the San Diego fixture with its ENC: all is every ellipse of every assessment (the
    13,680 the report had before the option), restricted only those not inside navigable
    water where the chart covers them, none no domains layer."""
    outcomes, frame = sandiego_replay.encounters, sandiego_replay.frame
    every = sum(len(o.assessment.step) for o in outcomes)
    restricted = sum(int((o.assessment.restricted & o.assessment.covered).sum()) for o in outcomes)
    assert every == 13_680 and 0 < restricted < every
    assert len(encounter_layers(outcomes, frame, Domains.ALL)["domains"][0]) == every
    wkb, table = encounter_layers(outcomes, frame, Domains.RESTRICTED)["domains"]
    assert len(wkb) == len(table) == restricted
    assert table["restricted"].all() and (table["state"] == "restricted").all()
    assert "domains" not in encounter_layers(outcomes, frame, Domains.NONE)
    # The default report holds the restricted ones, a GeoPackage 1.3 (no GDAL 3.6 warning).
    written = sandiego_replay.out_dir / "report.gpkg"
    fields, _ = _read(written, "domains")
    assert len(fields) == restricted and set(fields["state"]) == {"restricted"}
    with sqlite3.connect(written) as db:
        assert db.execute("PRAGMA user_version").fetchone() == (10300,)
    none = tmp_path / "none.gpkg"
    write_replay_geopackage(none, sandiego_replay, None, domains=Domains.NONE)
    assert "domains" not in _layers(none) and "vessel_tracks" in _layers(none)


def _style(path: Path, layer: str) -> str:
    """The QML of a layer's default style in the GeoPackage's layer_styles table."""
    with sqlite3.connect(path) as db:
        (qml,) = db.execute(
            "SELECT styleQML FROM layer_styles WHERE f_table_name = ?", (layer,)
        ).fetchone()
    return str(qml)


def test_vessel_tracks_carry_a_temporal_style(nmea_report) -> None:
    """QGIS's default style of vessel_tracks sets the Temporal Controller to the start and
    end fields and draws the position at the frame's time from the M values."""
    qml = _style(nmea_report.out_dir / "report.gpkg", "vessel_tracks")
    assert '<temporal enabled="1" mode="2" startField="start_utc" endField="end_utc"' in qml
    assert 'limitMode="0"' in qml
    assert "GeometryGenerator" in qml and "epoch(@map_end_time)" in qml


def test_lone_reports_show_in_the_frame_that_begins_at_them(nmea_report) -> None:
    """A lone report starts where it ends: with QGIS's limit mode 0 (a frame shows the
    features whose end is after its beginning) it would show in no frame; its style keeps
    the end in (mode 1: QGIS 3.22 then filters ``"end_utc" >= <frame begin>``)."""
    qml = _style(nmea_report.out_dir / "report.gpkg", "lone_reports")
    assert '<temporal enabled="1" mode="2" startField="start_utc" endField="end_utc"' in qml
    assert 'limitMode="1"' in qml


def test_the_domains_option_on_the_command_line(tmp_path: Path) -> None:
    """--domains none: no domains layer, and run.json's parameters record it; a bad value
    is one Error: line before any work."""
    out = tmp_path / "none"
    result = CliRunner().invoke(
        app, ["replay", str(NMEA), "--quiet", "--no-plots", "--out", str(out), "--domains", "none"]
    )
    assert result.exit_code == 0, result.output
    assert "domains" not in _layers(out / "report.gpkg")
    assert "vessel_tracks" in _layers(out / "report.gpkg")
    manifest = json.loads((out / "run.json").read_text(encoding="utf-8"))
    assert manifest["parameters"]["domains"] == "none"
    for command in (["replay", str(NMEA), "--quiet"], ["demo"]):
        bad = CliRunner().invoke(
            app, [*command, "--out", str(tmp_path / "bad"), "--domains", "red"]
        )
        assert bad.exit_code == 2, bad.output
        lines = [line for line in bad.output.splitlines() if line.strip()]
        assert lines == ["Error: --domains 'red' is not one of all, restricted, none"]
        assert not (tmp_path / "bad").exists()


def test_vessel_tracks_can_be_left_out(nmea_report, tmp_path: Path) -> None:
    """--no-vessel-tracks: neither vessel_tracks nor lone_reports, run.json says so, and the
    encounters are those of the run with them."""
    out = tmp_path / "without"
    result = CliRunner().invoke(
        app, ["replay", str(NMEA), "--quiet", "--no-plots", "--no-vessel-tracks", "--out", str(out)]
    )
    assert result.exit_code == 0, result.output
    layers = _layers(out / "report.gpkg")
    assert "vessel_tracks" not in layers and "lone_reports" not in layers
    assert "encounters" in layers
    manifest = json.loads((out / "run.json").read_text(encoding="utf-8"))
    assert manifest["parameters"]["vessel_tracks"] is False
    with_them = json.loads((nmea_report.out_dir / "run.json").read_text(encoding="utf-8"))
    assert with_them["parameters"]["vessel_tracks"] is True
    for name in ("pairs.csv", "encounters.csv"):
        assert (out / name).read_bytes() == (nmea_report.out_dir / name).read_bytes()


def test_every_vessel_is_a_track_or_a_lone_report(sandiego_replay) -> None:
    """San Diego: 41 of its 272 vessels have only pieces of one vertex (heard once, or at rest
    reporting further apart than max_gap_s); ``lone_reports`` holds them as points at their
    reports, so that the two layers together hold every vessel of the run."""
    path = sandiego_replay.out_dir / "report.gpkg"
    lines, _ = _read(path, "vessel_tracks")
    fields, points = _read(path, "lone_reports")
    vertices = sandiego_replay.vessel_tracks
    sizes = vertices.groupby(["mmsi", "piece"])["t_s"].transform("size")
    lone = vertices[sizes == 1]
    assert len(fields) == len(lone) > 0
    assert (shapely.get_type_id(points) == shapely.GeometryType.POINT).all()
    assert np.array_equal(shapely.get_x(points), lone["lon_deg"].to_numpy())
    assert np.array_equal(shapely.get_y(points), lone["lat_deg"].to_numpy())
    assert np.array_equal(fields["mmsi"].to_numpy(), lone["mmsi"].to_numpy())
    times = pd.to_datetime(fields["start_utc"], utc=True).dt.as_unit("ms").astype("int64")
    assert np.array_equal(times.to_numpy(), np.round(lone["t_s"].to_numpy() * 1000.0))
    assert fields["start_utc"].equals(fields["end_utc"])
    every = set(vertices["mmsi"])
    assert set(lines["mmsi"]) | set(fields["mmsi"]) == every
    assert len(every) == 272 and len(every - set(lines["mmsi"])) == 41
