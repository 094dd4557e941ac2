"""The replay's reports on real data (San Diego Bay over the NOAA ENC US5CA72M): the figures'
legend, chart and view, the overview map, and the GeoPackage's field types."""

from __future__ import annotations

import dataclasses
import itertools
import re

import numpy as np
import pandas as pd
import pyogrio
import pytest
import shapely
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.text import Text

from colregs9_cli.charts.water import load_chart
from colregs9_cli.report.chart_plot import NOT_CHARTED_LABEL
from colregs9_cli.report.encounter_figure import DEFAULTED_NOTE, encounter_figure
from colregs9_cli.report.html_report import overview_figure, pair_numbers, place_labels

from fixture_files import SANDIEGO_ENC

# Own ship SAILEBRATE reports no dimension; the target ECHELON reports all but her draught.
DEFAULTED = "20220103T000009-338254678-368124990"
# South of the cell's coverage (M_COVR ends at about 32.65° N).
LEAVES_THE_CHART = "20220103T001317-366793760-368103590"


@pytest.fixture(scope="module")
def sandiego(sandiego_replay):
    return sandiego_replay, load_chart([SANDIEGO_ENC], sandiego_replay.frame)


def _outcome(result, encounter_id: str):
    (outcome,) = [o for o in result.encounters if o.summary.encounter_id == encounter_id]
    return outcome


def _collection(ax, gid: str):
    found = [c for c in ax.collections if c.get_gid() == gid]
    return found[0] if found else None


def _legend_texts(figure) -> list[str]:
    (legend,) = figure.legends
    return [text.get_text() for text in legend.get_texts()]


def test_the_legend_stars_exactly_the_defaulted_dimensions(sandiego) -> None:
    result, chart = sandiego
    outcome = _outcome(result, DEFAULTED)
    s = outcome.summary
    assert (s.own_dimensions_defaulted, s.target_dimensions_defaulted) == (
        "length;breadth;draught",
        "draught",
    )
    figure = encounter_figure(outcome, chart, ukc_m=0.0, frame=result.frame)
    ax = figure.axes[0]
    labels = {line.get_gid(): line.get_label() for line in ax.get_lines()}
    for gid, defaulted in (
        ("own-track", s.own_dimensions_defaulted),
        ("target-track", s.target_dimensions_defaulted),
    ):
        match = re.search(r", ([\d.]+)(\*?) × ([\d.]+)(\*?) m, T ([\d.]+)(\*?) m$", labels[gid])
        assert match, labels[gid]
        starred = {
            name
            for name, star in zip(
                ("length", "breadth", "draught"), match.groups()[1::2], strict=True
            )
            if star
        }
        assert starred == set(defaulted.split(";")), labels[gid]
    assert DEFAULTED_NOTE in _legend_texts(figure)


def test_the_figure_draws_only_the_chart_in_its_view(sandiego) -> None:
    result, chart = sandiego
    figure = encounter_figure(_outcome(result, DEFAULTED), chart, ukc_m=0.0, frame=result.frame)
    ax = figure.axes[0]
    (x_low, x_high), (y_low, y_high) = ax.get_xlim(), ax.get_ylim()
    view = (x_low, y_low, x_high, y_high)
    depths = _collection(ax, "depth-areas")
    clipped = shapely.clip_by_rect(chart.depth_areas, *view)
    in_view = shapely.area(clipped) > 0
    # Only the depth areas in the view, each with its own DRVAL1, cut to the view.
    assert 0 < in_view.sum() < len(chart.depth_areas) // 4
    np.testing.assert_array_equal(depths.get_array(), chart.drval1_m[in_view])
    for path in depths.get_paths():
        extents = path.get_extents()
        assert view[0] - 1e-6 <= extents.x0 and extents.x1 <= view[2] + 1e-6
        assert view[1] - 1e-6 <= extents.y0 and extents.y1 <= view[3] + 1e-6
    # This view lies inside the chart's coverage: nothing is hatched as not charted.
    assert _collection(ax, "not-charted") is None


def test_the_map_frames_the_passing_not_the_whole_run(sandiego) -> None:
    # SHELTER ISLAND and SAILEBRATE passed at 55 m at 00:01:34; SHELTER ISLAND's track runs
    # on for 8 km until 00:11. The map is drawn at the scale of the pass.
    result, chart = sandiego
    outcome = _outcome(result, "20220103T000012-338187796-338254678")
    figure = encounter_figure(outcome, chart, ukc_m=0.0, frame=result.frame)
    ax = figure.axes[0]
    (x_low, x_high), (y_low, y_high) = ax.get_xlim(), ax.get_ylim()
    assert x_high - x_low < 1000.0
    track = outcome.own_track.dropna(subset=["east_m"])
    assert np.ptp(track["east_m"]) > 5000.0  # drawn whole, cut by the view
    for part in (outcome.own_track, outcome.target_track):
        times = pd.to_datetime(part["timestamp"], utc=True)
        passing = part[
            (times >= outcome.series["timestamp"].min())
            & (times <= outcome.series["timestamp"].max())
        ]
        assert ((passing["east_m"] >= x_low) & (passing["east_m"] <= x_high)).all()
        assert ((passing["north_m"] >= y_low) & (passing["north_m"] <= y_high)).all()


def test_water_beyond_the_chart_is_marked_not_charted(sandiego) -> None:
    result, chart = sandiego
    outcome = _outcome(result, LEAVES_THE_CHART)
    figure = encounter_figure(outcome, chart, ukc_m=0.0, frame=result.frame)
    ax = figure.axes[0]
    (x_low, x_high), (y_low, y_high) = ax.get_xlim(), ax.get_ylim()
    outside = shapely.difference(shapely.box(x_low, y_low, x_high, y_high), chart.coverage)
    not_charted = _collection(ax, "not-charted")
    drawn = shapely.union_all(
        [shapely.Polygon(ring) for path in not_charted.get_paths() for ring in path.to_polygons()]
    )
    assert shapely.area(outside) > 0.2 * (x_high - x_low) * (y_high - y_low)
    assert shapely.area(shapely.symmetric_difference(drawn, outside)) < 1e-6 * shapely.area(outside)
    assert not_charted.get_hatch() and NOT_CHARTED_LABEL in _legend_texts(figure)
    # The tracks leave the chart: the hatched part holds the end of the target's track.
    end = outcome.target_track.dropna().iloc[-1]
    assert shapely.contains_xy(outside, end["east_m"], end["north_m"])


def test_the_map_numbers_the_pairs_as_the_table_and_reads_in_degrees(sandiego) -> None:
    result, chart = sandiego
    figure = overview_figure(result, chart)
    ax = figure.axes[0]
    FigureCanvasAgg(figure).draw()
    numbers = pair_numbers(result)
    labels = {text.get_text(): text for text in ax.texts}
    assert set(labels) == {str(n) for n in numbers.values()} == {str(n) for n in range(1, 20)}
    for pair in result.pairs:
        label = labels[str(numbers[pair.summary.pair_id])]
        assert label.get_url() == f"#pair-{numbers[pair.summary.pair_id]}"
        north, east = result.frame.to_local(
            pair.summary.lat_deg_at_trigger_a, pair.summary.lon_deg_at_trigger_a
        )
        np.testing.assert_allclose(label.xy, (east, north))
    # San Diego is west of Greenwich: longitudes read °W, latitudes °N, no metres.
    longitudes = [t.get_text() for t in ax.get_xticklabels() if t.get_text()]
    latitudes = [t.get_text() for t in ax.get_yticklabels() if t.get_text()]
    assert longitudes and all(re.fullmatch(r"117\.\d{4}°W", t) for t in longitudes)
    assert latitudes and all(re.fullmatch(r"32\.\d{4}°N", t) for t in latitudes)
    assert "(m)" not in ax.get_xlabel() + ax.get_ylabel()
    # The numbers of the pairs crowded at Shelter Island do not cover one another (their
    # text, without the leader lines).
    renderer = figure.canvas.get_renderer()
    boxes = [Text.get_window_extent(text, renderer) for text in ax.texts]
    for i, box in enumerate(boxes):
        assert not any(box.overlaps(other) for other in boxes[i + 1 :])


def test_place_labels_keeps_a_cluster_apart() -> None:
    anchors = np.zeros((12, 2)) + np.arange(12)[:, None] * 0.5
    offsets = place_labels(anchors, [10.0] * 12, anchors)
    centres = anchors + offsets
    for i in range(12):
        for j in range(i + 1, 12):
            dx, dy = np.abs(centres[i] - centres[j])
            assert dx >= 10.0 or dy >= 8.0


def test_geopackage_fields_are_typed_as_their_values(sandiego) -> None:
    result, _ = sandiego
    path = result.out_dir / "report.gpkg"
    info = pyogrio.read_info(path, layer="encounters")
    types = dict(zip(info["fields"], info["ogr_types"], strict=True))
    subtypes = dict(zip(info["fields"], info["ogr_subtypes"], strict=True))
    for name in ("own_mmsi", "target_mmsi", "own_nav_status", "target_nav_status"):
        assert types[name] == "OFTInteger64", name
    for name in ("situation_ambiguous", "rule9_applied", "data_covers_cpa", "both_restricted"):
        assert subtypes[name] == "OFSTBoolean", name
    for name in ("start_utc", "trigger_utc", "end_utc", "actual_min_separation_utc"):
        assert types[name] == "OFTDateTime", name
    for name in ("cpa_m", "tcpa_s", "actual_min_separation_m", "action_before_cpa_s"):
        assert types[name] == "OFTReal", name
    # Three-valued facts stay text.
    for name in ("give_way_vessel_acted", "target_estimated_restricted"):
        assert types[name] == "OFTString", name
    for layer, name in (("domains", "step"), ("tracks", "mmsi"), ("cpa", "mmsi")):
        layer_info = pyogrio.read_info(path, layer=layer)
        assert dict(zip(layer_info["fields"], layer_info["ogr_types"], strict=True))[name] == (
            "OFTInteger64"
        ), layer

    meta, _, _, fields = pyogrio.raw.read(path, layer="encounters", datetime_as_string=True)
    columns = dict(zip(meta["fields"], fields, strict=True))
    table = pd.read_csv(result.out_dir / "encounters.csv", dtype=str, keep_default_na=False).loc[
        lambda t: t.index.repeat(2)
    ]
    own = np.asarray(columns["vessel"]) == "own"
    # Times in UTC, as encounters.csv has them.
    np.testing.assert_array_equal(
        pd.to_datetime(columns["trigger_utc"]), pd.to_datetime(table["trigger_utc"])
    )
    # A status where the vessel sent one, null (not 0) where she did not.
    sent = (table["own_nav_status"] != "").to_numpy()
    assert 0 < sent.sum() < len(table)
    assert np.isnan(columns["own_nav_status"][~sent]).all()
    np.testing.assert_array_equal(
        columns["own_nav_status"][sent], table["own_nav_status"][sent].astype(float)
    )
    np.testing.assert_array_equal(columns["own_mmsi"], table["own_mmsi"].astype(np.int64))
    # Each point's action time is its own vessel's, from the give-way vessels' list.
    for i, row in enumerate(table.itertuples()):
        mmsi = row.own_mmsi if own[i] else row.target_mmsi
        given = dict(
            zip(row.give_way_vessels.split(";"), row.action_before_cpa_s.split(";"), strict=True)
        )
        expected = float(given[mmsi]) if given.get(mmsi) else np.nan
        np.testing.assert_equal(columns["action_before_cpa_s"][i], expected)
    assert np.isfinite(columns["action_before_cpa_s"]).sum() > 0


class _InChunks:
    """``EncounterParts`` of consecutive chunks of the encounters, as slabs on workers give
    them: uneven, some holding a single seat."""

    def __init__(self, encounters, cuts: list[int]) -> None:
        bounds = [0, *cuts, len(encounters)]
        self.parts = [encounters[a:b] for a, b in itertools.pairwise(bounds)]

    def map(self, function):
        results = [function(part) for part in self.parts]
        return [lambda result=result: result for result in results]


def _layers(path):
    layers = {}
    for layer in pyogrio.list_layers(path)[:, 0]:
        meta, _, wkb, fields = pyogrio.raw.read(path, layer=layer, datetime_as_string=True)
        if wkb is None:  # the QGIS styles, stamped with the time they were written
            continue
        layers[layer] = (
            list(meta["fields"]),
            list(meta["dtypes"]),
            list(wkb),
            pd.DataFrame(dict(zip(meta["fields"], fields, strict=True))),
        )
    return layers


def test_reports_made_in_parts_are_the_reports_made_whole(sandiego, tmp_path) -> None:
    """The series CSVs and the GeoPackage's layers made part by part (each slab's on the
    worker that holds it) are those made from all the encounters at once."""
    from colregs9_cli.progress import progress_bar
    from colregs9_cli.report.replay_geopackage import encounter_layers, join_layers
    from colregs9_cli.report.replay_report import write_replay_reports

    result, chart = sandiego
    encounters = result.encounters
    cuts = [1, 2, 9, len(encounters) - 1]
    whole = encounter_layers(encounters, result.frame)
    joined = join_layers(
        [encounter_layers(part, result.frame) for part in _InChunks(encounters, cuts).parts]
    )
    assert joined.keys() == whole.keys()
    for name, (wkb, table) in whole.items():
        assert list(joined[name][0]) == list(wkb), name
        pd.testing.assert_frame_equal(joined[name][1], table, check_dtype=True)

    written = {}
    for label, parts in (("whole", None), ("parts", _InChunks(encounters, cuts))):
        out = tmp_path / label
        with progress_bar("Reports", None, enabled=False) as bar:
            write_replay_reports(
                dataclasses.replace(result, out_dir=out), chart, False, bar, parts=parts
            )
        written[label] = out
    series = sorted((written["whole"] / "encounters").iterdir())
    assert len(series) == len(encounters)
    for path in series:
        assert (written["parts"] / "encounters" / path.name).read_bytes() == path.read_bytes()
    whole_layers = _layers(written["whole"] / "report.gpkg")
    parts_layers = _layers(written["parts"] / "report.gpkg")
    assert (
        whole_layers.keys() == parts_layers.keys() >= {"encounters", "domains", "navigable_water"}
    )
    for name, (fields, dtypes, wkb, table) in whole_layers.items():
        assert parts_layers[name][:3] == (fields, dtypes, wkb), name
        pd.testing.assert_frame_equal(parts_layers[name][3], table)
