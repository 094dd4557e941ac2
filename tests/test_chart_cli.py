"""`colregs9 chart` and the estimator's bad-input paths through the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure
from typer.testing import CliRunner

from colregs9_cli.cli import app

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures"
ENC = FIXTURES / "charts" / "noaa_enc_US5MD1MC.000"


def _run(*args: str) -> object:
    return CliRunner().invoke(app, list(args))


def test_chart_summary() -> None:
    result = _run("chart", str(ENC))
    assert result.exit_code == 0, result.output
    assert "DEPARE     239" in result.output
    assert "DRVAL1 -0.5 .. 9.1 m" in result.output
    assert "lat 38.92500 .. 39.00000, lon -76.50000 .. -76.42500" in result.output
    assert "Navigable" not in result.output


def test_chart_with_a_draught_prints_the_area_and_draws(tmp_path: Path) -> None:
    out = tmp_path / "enc.png"
    args = ["--draught", "4.5", "--ukc", "0.5", "--out", str(out), "--quiet"]
    result = _run("chart", str(ENC), *args)
    assert result.exit_code == 0, result.output
    line = next(x for x in result.output.splitlines() if x.startswith("Navigable water"))
    assert "draught 4.5 m + UKC 0.5 m" in line
    # 4.5 m + 0.5 m needs DRVAL1 >= 5 m: the 5 m navigable area of test_chart.
    assert line.endswith(": 10.070 km²")
    assert out.stat().st_size > 10_000
    assert "Plot:" not in result.output  # --quiet drops the notice


def test_the_notice_of_what_was_written_goes_to_stderr(tmp_path: Path) -> None:
    out = tmp_path / "enc.png"
    result = _run("chart", str(ENC), "--draught", "5", "--out", str(out))
    assert result.exit_code == 0, result.output
    assert result.stderr.strip() == f"Plot: {out}"
    assert "Plot:" not in result.stdout


def _one_error_line(result: object, *fragments: str) -> None:
    assert result.exit_code != 0
    assert result.exception is None or isinstance(result.exception, SystemExit)
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
    assert "Traceback" not in result.output
    for fragment in fragments:
        assert fragment in lines[0]


def test_not_a_chart(tmp_path: Path) -> None:
    text = tmp_path / "readme.000"
    text.write_text("hello\n")
    _one_error_line(_run("chart", str(text)), "readme.000")
    noise = tmp_path / "random.geojson"
    noise.write_text(
        '{"type": "FeatureCollection", "features": [{"type": "Feature", '
        '"properties": {"a": 1}, "geometry": {"type": "Point", '
        '"coordinates": [1, 2]}}]}'
    )
    _one_error_line(_run("chart", str(noise)), "random.geojson", "OBJL")
    garbage = tmp_path / "garbage.geojson"
    garbage.write_bytes(b"\x00\x01 not json")
    _one_error_line(_run("chart", str(garbage)), "garbage.geojson")


def _geojson(path: Path, **properties: object) -> Path:
    feature = {
        "type": "Feature",
        "properties": properties,
        "geometry": {
            "type": "Polygon",
            "coordinates": [[[9.9, 57.0], [9.95, 57.0], [9.95, 57.05], [9.9, 57.0]]],
        },
    }
    path.write_text(json.dumps({"type": "FeatureCollection", "features": [feature]}))
    return path


def test_a_chart_with_no_depth_areas(tmp_path: Path) -> None:
    path = _geojson(tmp_path / "land.geojson", OBJL="LNDARE", DRVAL1=None)
    _one_error_line(_run("chart", str(path)), "land.geojson", "no depth areas")


def test_a_geojson_without_drval1(tmp_path: Path) -> None:
    path = _geojson(tmp_path / "nodepth.geojson", OBJL="DEPARE", DEPTH=4.0)
    _one_error_line(_run("chart", str(path)), "nodepth.geojson", "DRVAL1")


@pytest.mark.parametrize(("option", "value"), [("--draught", "-5"), ("--ukc", "-1")])
def test_negative_draught_or_ukc(option: str, value: str) -> None:
    _one_error_line(_run("chart", str(ENC), option, value), option, value)


def test_alpha_outside_zero_one(tmp_path: Path) -> None:
    ais = FIXTURES / "ais" / "aisdk_2024-09-09_sample.csv"
    result = _run("replay", str(ais), "--alpha", "1.5", "--no-plots", "--out", str(tmp_path))
    _one_error_line(result, "alpha 1.5 is outside [0, 1]")


@pytest.mark.parametrize("name", ["chart.txt", "chart", "chart.shp"])
def test_an_out_of_another_kind_is_refused(tmp_path: Path, name: str) -> None:
    out = tmp_path / name
    result = _run("chart", str(ENC), "--draught", "5", "--out", str(out), "--quiet")
    _one_error_line(result, name, ".gpkg", ".png")
    assert result.exit_code == 2
    assert list(tmp_path.iterdir()) == []  # nothing written, not even a temporary file


@pytest.mark.parametrize("name", ["chart.png", "chart.gpkg"])
def test_an_out_without_a_draught_is_refused(tmp_path: Path, name: str) -> None:
    result = _run("chart", str(ENC), "--out", str(tmp_path / name), "--quiet")
    _one_error_line(result, "--out", "--draught")
    assert result.exit_code == 2
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["trail.png/", "trail.gpkg/", "trail.png//"])
def test_an_out_ending_in_a_separator_names_a_directory(tmp_path: Path, name: str) -> None:
    """Path() would drop the separator and write trail.png: the option is read as typed."""
    result = _run("chart", str(ENC), "--draught", "5", "--out", f"{tmp_path}/{name}", "--quiet")
    _one_error_line(result, name, "--out ends in a path separator", "names a directory")
    assert result.exit_code == 2
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", ["plots", "plots.png"])
def test_an_out_that_is_a_directory_is_named_so(tmp_path: Path, name: str) -> None:
    (tmp_path / name).mkdir()
    result = _run("chart", str(ENC), "--draught", "5", "--out", str(tmp_path / name), "--quiet")
    _one_error_line(result, name, "--out is a directory")
    assert result.exit_code == 2
    assert list((tmp_path / name).iterdir()) == []


def test_an_out_under_a_file_is_refused(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    result = _run("chart", str(ENC), "--draught", "5", "--out", str(tmp_path / "file" / "c.gpkg"))
    _one_error_line(result, "c.gpkg", "which is a file")
    assert result.exit_code == 2


def test_the_chart_plot_outlines_the_coverage(tmp_path: Path) -> None:
    from colregs9_cli.charts.water import load_chart
    from colregs9_cli.report.chart_plot import draw_chart

    chart = load_chart([ENC])
    figure = Figure()
    ax = figure.subplots()
    draw_chart(ax, chart, 5.0, coverage=True)
    (edge,) = [c for c in ax.collections if c.get_gid() == "coverage"]
    assert edge.get_label().startswith("chart edge")
    (path,) = edge.get_paths()
    # the outline is the coverage's ring, the box of the cell's M_COVR
    extents = path.get_extents()
    np.testing.assert_allclose(
        [extents.x0, extents.y0, extents.x1, extents.y1], chart.coverage.bounds
    )
    figure.clear()
    ax = figure.add_subplot()
    draw_chart(ax, chart, 5.0)  # the replay's figures keep their legend as it was
    assert "coverage" not in {c.get_gid() for c in ax.collections}


@pytest.mark.parametrize("draught_m", [2.0, 5.0])
def test_the_depths_are_banded_around_the_draught(draught_m: float) -> None:
    """With a draught, each depth area's colour is its band's: warm where it is shallower
    than the draught, pale blue where it is deeper, with a band edge at the draught."""
    from matplotlib.colors import BoundaryNorm, to_hex

    from colregs9_cli.charts.water import load_chart
    from colregs9_cli.report.chart_plot import DEEP_COLOURS, SHALLOW_COLOURS, draw_chart

    chart = load_chart([ENC])
    figure = Figure()
    ax = figure.subplots()
    depths = draw_chart(ax, chart, draught_m)
    assert isinstance(depths.norm, BoundaryNorm)
    assert draught_m in list(depths.norm.boundaries)
    colours = [to_hex(c) for c in depths.to_rgba(depths.get_array())]
    values = np.asarray(depths.get_array())
    shallow = values < draught_m
    assert shallow.any() and (~shallow).any()
    assert {c for c, s in zip(colours, shallow, strict=True) if s} <= set(SHALLOW_COLOURS)
    assert {c for c, s in zip(colours, shallow, strict=True) if not s} <= set(DEEP_COLOURS)


def test_the_summary_lists_the_charted_channels() -> None:
    result = _run("chart", str(ENC))
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    start = lines.index(
        "Channels: 20 area(s), 4 line(s) (axis true; least depth; length × mean width)"
    )
    listed = lines[start + 1 : start + 25]
    assert (
        "  fairway           Annapolis Harbor Channel: centreline 063.6°, two-way, 1281 m × 31 m"
        in listed
    )
    assert (
        "  dredged-area      Spa Creek Channel: centreline 040.4°, 4.1 m deep, 536 m × 30 m"
        in listed
    )
    assert "  navigation-line   NAVLNE 022610C3897F15B3: line 090.0°, 2161 m" in listed
    assert sum(line.startswith("  fairway ") for line in listed) == 10


def test_a_chart_without_channels_says_so_in_one_line(tmp_path: Path) -> None:
    from colregs9_cli.charts.water import load_chart
    from colregs9_cli.jobs.chartinfo import format_chart_summary

    path = _geojson(tmp_path / "plain.geojson", OBJL="DEPARE", DRVAL1=5.0)
    result = _run("chart", str(path))
    assert result.exit_code == 0, result.output
    assert result.output == format_chart_summary(load_chart([path])) + "Channels: none charted\n"


def test_the_geopackage_has_the_channels_and_their_axes(tmp_path: Path) -> None:
    import pyogrio
    import shapely

    out = tmp_path / "annapolis.gpkg"
    result = _run("chart", str(ENC), "--draught", "2", "--out", str(out), "--quiet")
    assert result.exit_code == 0, result.output
    assert "navigable for 2 m along 100% of its axis, 30 m wide there" in result.output
    layers = dict(pyogrio.list_layers(out))
    assert layers["channels"] == "Unknown" and layers["channel_axes"] == "MultiLineString"
    meta, _, wkb, fields = pyogrio.raw.read(out, layer="channels")
    columns = dict(zip(meta["fields"], fields, strict=True))
    assert len(wkb) == 24 and meta["crs"] == "EPSG:4326"
    kinds = {str(shapely.from_wkb(w).geom_type) for w in wkb}
    assert kinds == {"MultiPolygon", "MultiLineString"}
    named = sorted(
        n for n, k in zip(columns["name"], columns["kind"], strict=True) if n and k == "fairway"
    )
    assert named == ["Annapolis Harbor Channel", "Back Creek Channel", "Spa Creek Channel"]
    assert pyogrio.read_info(out, layer="channel_axes")["features"] == 24


def test_a_channel_attribute_that_is_not_a_number(tmp_path: Path) -> None:
    path = tmp_path / "bad_orient.geojson"
    depth = {"type": "Feature", "properties": {"OBJL": "DEPARE", "DRVAL1": 5.0}}
    fairway = {"type": "Feature", "properties": {"OBJL": "FAIRWY", "ORIENT": "NE"}}
    ring = [[9.9, 57.0], [9.95, 57.0], [9.95, 57.05], [9.9, 57.0]]
    features = [
        {**f, "geometry": {"type": "Polygon", "coordinates": [ring]}} for f in (depth, fairway)
    ]
    path.write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    _one_error_line(_run("chart", str(path)), "bad_orient.geojson", "ORIENT is 'NE'")
