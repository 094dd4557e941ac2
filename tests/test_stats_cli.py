"""`colregs9 stats` end to end on the real fixtures, checked against independent readings.

The expected figures are never taken from colregs9's readers: the CSV fixtures are read again
here with plain pandas and the cleaning rules of docs/design.md §4 written out by hand, and the NMEA
fixture is decoded with pyais directly (see ``_nmea_vessels``).
"""

from __future__ import annotations

import gzip
import hashlib
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_hex
from matplotlib.patches import Rectangle
from pyais.stream import IterMessages
from typer.testing import CliRunner

from colregs9_cli.cli import app
from colregs9_cli.core.dimensions import GroupBy, Per
from colregs9_cli.jobs.stats import run_stats
from colregs9_cli.report.stats_report import histogram_figure

from fixture_files import DMA22, DMA26, MARINECADASTRE, NMEA, ROOT

LIMFJORDEN = ROOT / "queries" / "limfjorden.toml"
LIMFJORD_BOX = (56.5, 57.2, 8.2, 10.4)

DIMENSIONS = ["length_m", "breadth_m", "draught_m"]
CSV_HEADER = "dimension,count,mean,median,std,min,max"
REPORT_FILES = {
    "dimension_stats.csv",
    "dimension_stats.md",
    "dimension_histograms.png",
    "index.html",
    "run.json",
}


def _valid_mmsi(mmsi: pd.Series) -> pd.Series:
    # Nine digits with a maritime identification digit (MID) in 201-775.
    return mmsi.between(201_000_000, 775_999_999)


def _positive(values: pd.Series) -> pd.Series:
    # 0 is AIS "not available" for dimensions and draught.
    return values.where(values > 0)


def _has_position(lat: pd.Series, lon: pd.Series) -> pd.Series:
    return lat.between(-90, 90) & lon.between(-180, 180) & (lat != 91) & (lon != 181)


def _dma_reports(path: Path) -> pd.DataFrame:
    """Every usable row of a DMA CSV: vessels only, valid MMSI, exact duplicates once."""
    raw = pd.read_csv(path, dtype=str, keep_default_na=False).drop_duplicates()
    raw.columns = [name.lstrip("# ") for name in raw.columns]
    mmsi = pd.to_numeric(raw["MMSI"], errors="coerce")
    raw = raw[raw["Type of mobile"].isin(["Class A", "Class B"]) & _valid_mmsi(mmsi)]

    def number(column: str) -> pd.Series:
        return pd.to_numeric(raw[column].str.strip(), errors="coerce")

    lat, lon = number("Latitude"), number("Longitude")
    return pd.DataFrame(
        {
            "mmsi": number("MMSI").astype("int64"),
            "has_position": _has_position(lat, lon),
            "length_m": _positive(number("Length")),
            "breadth_m": _positive(number("Width")),
            "draught_m": _positive(number("Draught")),
        }
    )


def _marinecadastre_reports(path: Path) -> pd.DataFrame:
    raw = pd.read_csv(path).drop_duplicates()
    raw = raw[_valid_mmsi(raw["MMSI"])]
    return pd.DataFrame(
        {
            "mmsi": raw["MMSI"].astype("int64"),
            "has_position": _has_position(raw["LAT"], raw["LON"]),
            "length_m": _positive(raw["Length"]),
            "breadth_m": _positive(raw["Width"]),
            "draught_m": _positive(raw["Draft"]),
        }
    )


def _expected(reports: pd.DataFrame, per: str) -> pd.DataFrame:
    """The table computed with plain pandas: per vessel, each vessel's median report."""
    positions = reports[reports["has_position"]]
    if per == "vessel":
        values = reports.groupby("mmsi")[DIMENSIONS].median().reindex(positions["mmsi"].unique())
    else:
        values = positions[DIMENSIONS]
    return pd.DataFrame(
        {
            "count": values.count(),
            "mean": values.mean(),
            "median": values.median(),
            "std": values.std(ddof=1),
            "min": values.min(),
            "max": values.max(),
            "missing": values.isna().sum(),
        }
    )


def _nmea_vessels() -> tuple[int, pd.DataFrame]:
    """The Limfjord vessels of the NMEA fixture and their median reports, via pyais alone.

    Cross-check: only the ``!`` sentence lines are kept (the ``\\si:`` tag-block lines and the
    ``$PGHP`` timestamp lines carry no positions or dimensions), pyais reassembles and decodes
    them, positions are message types 1, 2, 3, 18, 19 and 27 with a valid MMSI and a lat/lon in
    the box, dimensions come from types 5, 19 and 24 part B (A+B and C+D only when both parts
    are > 0, draught from type 5 when > 0). This gives 2,159 positions from 126 vessels in the
    box: fixtures/SOURCES.md counts 2,160 positions from 127 MMSIs, one of which (11388, a
    single type 1 report) has no valid MMSI.
    """
    with gzip.open(NMEA, "rt", encoding="ascii") as handle:
        sentences = [line.strip().encode() for line in handle if line.startswith("!")]
    positions, statics = [], []
    for message in IterMessages(sentences):
        decoded = message.decode()
        kind = decoded.msg_type
        if kind in (1, 2, 3, 18, 19, 27):
            positions.append((int(decoded.mmsi), float(decoded.lat), float(decoded.lon)))
        if kind in (5, 19) or (kind == 24 and decoded.partno == 1):
            length = decoded.to_bow + decoded.to_stern
            breadth = decoded.to_port + decoded.to_starboard
            statics.append(
                (
                    int(decoded.mmsi),
                    length if decoded.to_bow > 0 and decoded.to_stern > 0 else math.nan,
                    breadth if decoded.to_port > 0 and decoded.to_starboard > 0 else math.nan,
                    float(decoded.draught) if kind == 5 and decoded.draught > 0 else math.nan,
                )
            )
    frame = pd.DataFrame(positions, columns=["mmsi", "lat", "lon"])
    lat_min, lat_max, lon_min, lon_max = LIMFJORD_BOX
    in_box = (
        _valid_mmsi(frame["mmsi"])
        & frame["lat"].between(lat_min, lat_max)
        & frame["lon"].between(lon_min, lon_max)
    )
    vessels = frame.loc[in_box, "mmsi"].unique()
    reports = pd.DataFrame(statics, columns=["mmsi", *DIMENSIONS])
    values = reports.groupby("mmsi")[DIMENSIONS].median().reindex(vessels)
    return int(in_box.sum()), values


def _stats(args: list[str]):  # type: ignore[no-untyped-def]
    result = CliRunner().invoke(app, ["stats", *args])
    assert "Traceback" not in result.output
    return result


def _assert_table(csv_path: Path, expected: pd.DataFrame) -> None:
    table = pd.read_csv(csv_path).set_index("dimension")
    assert list(table.index) == DIMENSIONS
    for dimension in DIMENSIONS:
        for column in ("count", "mean", "median", "std", "min", "max"):
            want = expected.loc[dimension, column]
            got = table.loc[dimension, column]
            if pd.isna(want):
                assert pd.isna(got), (dimension, column, got)
            else:
                assert got == pytest.approx(want, rel=1e-9), (dimension, column)


def _assert_manifest(out: Path, source: Path, expected: pd.DataFrame, units: int) -> dict:
    manifest = json.loads((out / "run.json").read_text())
    for key in ("version", "query", "inputs", "rows_read", "rows_in_query", "ledger", "per"):
        assert key in manifest
    assert manifest["tool"] == "colregs9"
    (item,) = manifest["inputs"]
    assert item["sha256"] == hashlib.sha256(source.read_bytes()).hexdigest()
    ledger = manifest["ledger"]
    assert ledger["rows_read"] == manifest["rows_read"] == item["rows_read"]
    assert ledger["rows_read"] == (
        ledger["rows_used"] + ledger["rows_outside_query"] + ledger["rows_rejected"]
    )
    assert sum(ledger["rejects_by_reason"].values()) == ledger["rows_rejected"]
    rows = {row["dimension"]: row for row in manifest["table"]["rows"]}
    assert manifest["table"]["units"] == units
    for dimension in DIMENSIONS:
        assert rows[dimension]["missing"] == expected.loc[dimension, "missing"]
        assert rows[dimension]["count"] == expected.loc[dimension, "count"]
    return manifest


@pytest.mark.parametrize(
    ("source", "reader", "rows_read"),
    [
        (DMA26, _dma_reports, 20),
        (DMA22, _dma_reports, 138),
        (MARINECADASTRE, _marinecadastre_reports, 1000),
    ],
    ids=["dma26", "dma22", "marinecadastre"],
)
@pytest.mark.parametrize("per", ["vessel", "message"])
def test_csv_fixtures_match_a_plain_pandas_reading(
    tmp_path: Path, source: Path, reader, rows_read: int, per: str
) -> None:  # type: ignore[no-untyped-def]
    reports = reader(source)
    expected = _expected(reports, per)
    positions = reports[reports["has_position"]]
    units = positions["mmsi"].nunique() if per == "vessel" else len(positions)

    out = tmp_path / "out"
    result = _stats([str(source), "--per", per, "--out", str(out), "--quiet"])
    assert result.exit_code == 0, result.output

    assert {p.name for p in out.iterdir()} == REPORT_FILES
    assert (out / "dimension_stats.csv").read_text().splitlines()[0] == CSV_HEADER
    _assert_table(out / "dimension_stats.csv", expected)
    manifest = _assert_manifest(out, source, expected, units)
    assert manifest["rows_read"] == rows_read
    assert manifest["rows_in_query"] == len(positions)
    assert manifest["vessels"] == positions["mmsi"].nunique()
    assert manifest["per"] == per
    assert manifest["query"]["name"] == "all"

    # The printed table: one line per dimension with its count and missing figures.
    lines = {line.split()[0]: line.split() for line in result.stdout.splitlines() if line}
    for dimension in DIMENSIONS:
        assert lines[dimension][1] == str(expected.loc[dimension, "count"])
        assert lines[dimension][-1] == str(expected.loc[dimension, "missing"])
    markdown = (out / "dimension_stats.md").read_text()
    assert "| Dimension | mean | median | std | min | max | count | missing |" in markdown
    for label in ("Length (m)", "Breadth (m)", "Draught (m)"):
        assert f"| {label} |" in markdown


def test_dma26_figures_by_hand(tmp_path: Path) -> None:
    # The 20 rows of the 2024 sample: one exact duplicate (HUMBRIA SEAWAYS), one AtoN, and
    # three lat 91 rows leave 15 vessels with one position each; 13 report a length, e.g.
    # ARCTIC PRINCESS 288 m (A 223 + B 65) is the longest, KYST-FRB14 9 m the shortest.
    result = _stats([str(DMA26), "--out", str(tmp_path), "--quiet"])
    assert result.exit_code == 0, result.output
    table = pd.read_csv(tmp_path / "dimension_stats.csv").set_index("dimension")
    assert table.loc["length_m", ["count", "min", "max"]].tolist() == [13, 9.0, 288.0]
    assert table.loc["draught_m", ["count", "min", "max"]].tolist() == [11, 1.5, 13.1]


def test_nmea_limfjorden_matches_pyais_decoded_directly(tmp_path: Path) -> None:
    positions_in_box, values = _nmea_vessels()
    assert (positions_in_box, len(values)) == (2159, 126)
    result = _stats([str(NMEA), "--query", str(LIMFJORDEN), "--out", str(tmp_path), "--quiet"])
    assert result.exit_code == 0, result.output

    manifest = json.loads((tmp_path / "run.json").read_text())
    assert manifest["vessels"] == 126
    assert manifest["query"]["name"] == "limfjorden"
    assert manifest["inputs"][0]["layout"] == "nmea"
    ledger = manifest["ledger"]
    assert ledger["rows_read"] == (
        ledger["rows_used"] + ledger["rows_outside_query"] + ledger["rows_rejected"]
    )
    expected = pd.DataFrame(
        {
            "count": values.count(),
            "mean": values.mean(),
            "median": values.median(),
            "std": values.std(ddof=1),
            "min": values.min(),
            "max": values.max(),
            "missing": values.isna().sum(),
        }
    )
    # 13 lengths (6-82 m), 12 breadths, 7 draughts among the 126 vessels.
    assert expected["count"].tolist() == [13, 12, 7]
    _assert_table(tmp_path / "dimension_stats.csv", expected)
    rows = {row["dimension"]: row for row in manifest["table"]["rows"]}
    assert [rows[d]["missing"] for d in DIMENSIONS] == [113, 114, 119]


def test_histograms_plot_the_counted_values(tmp_path: Path) -> None:
    run = run_stats([MARINECADASTRE], per=Per.VESSEL, out_dir=tmp_path)
    png = tmp_path / "dimension_histograms.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = __import__("matplotlib.image", fromlist=["imread"]).imread(png)
    assert image.shape[0] > 200 and image.shape[1] > 600
    assert np.ptp(image) > 0  # not a blank canvas
    figure = histogram_figure(run.result, "all")
    table = pd.read_csv(tmp_path / "dimension_stats.csv").set_index("dimension")
    for axis, dimension in zip(figure.axes, DIMENSIONS, strict=True):
        bars = [p for p in axis.patches if isinstance(p, Rectangle)]
        assert sum(bar.get_height() for bar in bars) == table.loc[dimension, "count"]
        right = max(bar.get_x() + bar.get_width() for bar in bars)
        assert right == pytest.approx(table.loc[dimension, "max"])


def test_by_ship_type(tmp_path: Path) -> None:
    result = _stats([str(MARINECADASTRE), "--by", "ship_type", "--out", str(tmp_path), "--quiet"])
    assert result.exit_code == 0, result.output
    header = (tmp_path / "dimension_stats.csv").read_text().splitlines()[0]
    assert header == "ship_type," + CSV_HEADER
    table = pd.read_csv(tmp_path / "dimension_stats.csv")
    manifest = json.loads((tmp_path / "run.json").read_text())
    assert manifest["by"] == "ship_type"
    overall = {row["dimension"]: row for row in manifest["table"]["rows"]}
    # Every vessel lands in exactly one ship type.
    assert sum(group["units"] for group in manifest["groups"]) == manifest["vessels"] == 998
    everything = table[table["ship_type"] == "(all)"].set_index("dimension")
    table = table[table["ship_type"] != "(all)"]
    for dimension in DIMENSIONS:
        part = table[table["dimension"] == dimension]
        assert part["count"].sum() == overall[dimension]["count"]
        assert everything.loc[dimension, "count"] == overall[dimension]["count"]
        assert part["max"].max() == pytest.approx(overall[dimension]["max"])
    assert table["ship_type"].nunique() == len(manifest["groups"]) > 1
    markdown = (tmp_path / "dimension_stats.md").read_text()
    assert markdown.count("## Ship type: ") == len(manifest["groups"])


def test_default_out_dir_is_named_after_the_query(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    result = _stats([str(NMEA), "--query", str(LIMFJORDEN), "--quiet", "--format", "nmea"])
    assert result.exit_code == 0, result.output
    assert {p.name for p in (tmp_path / "reports" / "stats-limfjorden").iterdir()} == (REPORT_FILES)


def _query(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "q.toml"
    path.write_text(text, encoding="utf-8")
    return path


BOX = "[region]\nlat_min = 56.5\nlat_max = 57.2\nlon_min = 8.2\nlon_max = 10.4\n"


@pytest.mark.parametrize(
    ("case", "exit_code", "needle"),
    [
        ("missing file", 2, "nope.csv"),
        ("empty file", 2, "empty.csv"),
        ("unknown layout", 2, "layout.csv"),
        ("unknown --format", 2, "bogus"),
        ("unknown --per", 2, "bogus"),
        ("truncated gzip", 2, "truncated.txt.gz"),
        ("non-UTF-8 byte", 2, "latin1.csv"),
        ("TOML syntax error", 2, "q.toml"),
        ("unknown query key", 2, "colour"),
        ("lat_min > lat_max", 2, "lat_min"),
        ("query selects no rows", 3, "q.toml"),
    ],
)
def test_bad_input_gives_one_error_line(
    tmp_path: Path, case: str, exit_code: int, needle: str
) -> None:
    ais = DMA26
    args: list[str] = []
    if case == "missing file":
        ais = tmp_path / "nope.csv"
    elif case == "empty file":
        ais = tmp_path / "empty.csv"
        ais.write_bytes(b"")
    elif case == "unknown layout":
        ais = tmp_path / "layout.csv"
        ais.write_text("when,where,who\n1,2,3\n")
    elif case == "unknown --format":
        args = ["--format", "bogus"]
    elif case == "unknown --per":
        args = ["--per", "bogus"]
    elif case == "truncated gzip":
        ais = tmp_path / "truncated.txt.gz"
        data = NMEA.read_bytes()
        ais.write_bytes(data[: len(data) // 2])
    elif case == "non-UTF-8 byte":
        ais = tmp_path / "latin1.csv"
        ais.write_bytes(DMA26.read_bytes().replace(b"HANNE", b"H\xc5NNE"))
    elif case == "TOML syntax error":
        args = ["--query", str(_query(tmp_path, 'name = "broken\n' + BOX))]
    elif case == "unknown query key":
        args = ["--query", str(_query(tmp_path, 'name = "x"\ncolour = "red"\n' + BOX))]
    elif case == "lat_min > lat_max":
        text = 'name = "x"\n' + BOX.replace("lat_min = 56.5", "lat_min = 57.5")
        args = ["--query", str(_query(tmp_path, text))]
    elif case == "query selects no rows":
        text = 'name = "x"\n[region]\nlat_min = 0.0\nlat_max = 1.0\nlon_min = 0.0\nlon_max = 1.0\n'
        args = ["--query", str(_query(tmp_path, text))]
    out = tmp_path / "out"
    result = _stats([str(ais), *args, "--out", str(out), "--quiet"])
    assert result.exit_code == exit_code, (case, result.output)
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: "), result.output
    assert needle in lines[0]
    assert not out.exists()  # nothing half-written


def test_per_and_by_enums_match_the_cli_choices() -> None:
    help_text = CliRunner().invoke(app, ["stats", "--help"]).output
    for value in (*Per, *GroupBy):
        assert value.value in help_text


def test_an_error_about_a_file_with_a_newline_in_its_name_is_one_line(tmp_path: Path) -> None:
    path = tmp_path / "new\nline.csv"
    path.write_text("a\nb\n")
    result = CliRunner().invoke(app, ["stats", str(path), "--quiet", "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    lines = result.output.splitlines()
    assert len(lines) == 1 and lines[0].startswith("Error: ")
    assert "new\\nline.csv" in lines[0]


def test_histograms_by_ship_type_are_stacked_by_type(tmp_path: Path) -> None:
    run = run_stats([MARINECADASTRE], per=Per.VESSEL, by=GroupBy.SHIP_TYPE, out_dir=tmp_path)
    figure = histogram_figure(run.result, "all")
    groups = {table.group: table for table in run.result.groups}
    (legend,) = figure.legends
    assert {text.get_text() for text in legend.get_texts()} <= set(groups)
    for axis, dimension in zip(figure.axes, DIMENSIONS, strict=True):
        bars = [p for p in axis.patches if isinstance(p, Rectangle)]
        # every counted vessel once, in the colour of her type
        assert sum(bar.get_height() for bar in bars) == run.result.overall.row(dimension).count
        by_colour: dict[tuple[float, ...], float] = {}
        for bar in bars:
            colour = tuple(bar.get_facecolor())
            by_colour[colour] = by_colour.get(colour, 0) + bar.get_height()
        counts = sorted(g.row(dimension).count for g in groups.values() if g.row(dimension).count)
        assert sorted(by_colour.values()) == counts


def test_histograms_by_ship_type_plot_each_type_in_one_colour(tmp_path: Path) -> None:
    # In this sample the SAR vessels report a length but no draught.
    run = run_stats([DMA26], per=Per.VESSEL, by=GroupBy.SHIP_TYPE, out_dir=tmp_path)
    table = pd.read_csv(tmp_path / "dimension_stats.csv", dtype={"ship_type": str})
    table = table[table["ship_type"] != "(all)"]
    figure = histogram_figure(run.result, "all")
    (legend,) = figure.legends
    colours = {
        text.get_text(): to_hex(handle.get_facecolor())
        for text, handle in zip(legend.get_texts(), legend.legend_handles, strict=True)
    }
    # One legend for every type of the CSV, whichever panels a type has values in.
    assert set(colours) == set(table["ship_type"])
    assert len(set(colours.values())) == len(colours)
    panels: dict[str, set[str]] = {}
    for axis, dimension in zip(figure.axes, DIMENSIONS, strict=True):
        rows = table[(table["dimension"] == dimension) & (table["count"] > 0)]
        expected = dict(zip(rows["ship_type"], rows["count"], strict=True))
        # Each stack is one type's vessels, in that type's legend colour.
        plotted = {}
        for stack in axis.containers:
            plotted[stack.get_label()] = sum(bar.get_height() for bar in stack)
            assert {to_hex(bar.get_facecolor()) for bar in stack} == {colours[stack.get_label()]}
        assert plotted == expected, dimension
        panels[dimension] = set(plotted)
    # The case that shifted the colours: a type with a length but no draught.
    assert panels["length_m"] - panels["draught_m"] == {"SAR"}


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ("[replay]\nfoo = 1\n", "[replay]: unknown key 'foo'"),
        ("[replay]\nchannel_narrow_within_lengths = -5\n", "channel_narrow_within_lengths"),
        ("[manoeuvrability]\nalpha = 2.0\n", "alpha 2.0 is outside [0, 1]"),
    ],
)
@pytest.mark.parametrize("command", ["stats", "ingest"])
def test_a_query_stats_accepts_replay_accepts(
    tmp_path: Path, command: str, table: str, message: str
) -> None:
    """stats and ingest do not use the replay's tables, but check them, so that a query
    they accept is one replay accepts."""
    query = tmp_path / "q.toml"
    query.write_text(table)
    out = tmp_path / "out"
    result = CliRunner().invoke(
        app, [command, str(DMA26), "--query", str(query), "--out", str(out), "--quiet"]
    )
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("Error: ") and message in lines[0]
    assert not out.exists()
