"""Charted channels (``charts/channels.py``, ``channel_axis.py``, ``channel_facts.py``): axes
charted and derived, the channel a position is in, along or crossing, offsets to starboard,
widths for a draught, precedence between charts, and the real San Diego and Annapolis cells
checked against GDAL read directly."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

import numpy as np
import pyogrio
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from colregs9_cli.charts.channel_facts import ChannelParams, ChannelRelation, channel_facts
from colregs9_cli.charts.channels import (
    AxisSource,
    Channels,
    Traffic,
    load_channels,
    make_channel,
)
from colregs9_cli.charts.s57_classes import ChannelKind
from colregs9_cli.charts.water import load_chart
from colregs9_cli.errors import ChartError, ParameterError
from colregs9_cli.geo import LocalFrame

from fixture_files import FIXTURES, SANDIEGO_ENC
from geojson_charts import annulus_sector, feature, write_chart

ANNAPOLIS_ENC = FIXTURES / "charts" / "noaa_enc_US5MD1MC.000"
FRAME = LocalFrame(55.0, 10.0)
ALONG, CROSSING, OBLIQUE = ChannelRelation.ALONG, ChannelRelation.CROSSING, ChannelRelation.OBLIQUE


def _channels(*geometries: Any, orient_deg: float | None = None) -> Channels:
    items = [
        make_channel(
            FRAME, ChannelKind.FAIRWAY, g, record_id=f"F{i}", name=f"F{i}", orient_deg=orient_deg
        )
        for i, g in enumerate(geometries)
    ]
    assert all(c is not None for c in items)
    return Channels(FRAME, tuple(c for c in items if c is not None))


# A channel 200 m wide running north-south for 2 km, centred on the frame's origin.
STRAIGHT = shapely.box(-100.0, -1000.0, 100.0, 1000.0)


@pytest.mark.parametrize("orient_deg", [0.0, 180.0, None])
def test_a_straight_channel_along_both_ways_crossing_and_outside(orient_deg: float | None) -> None:
    channels = _channels(STRAIGHT, orient_deg=orient_deg)
    (channel,) = channels
    expected_source = AxisSource.CENTRELINE if orient_deg is None else AxisSource.ORIENT
    assert channel.axis_source is expected_source
    assert channel.length_m == pytest.approx(2000.0, abs=1.0)
    assert channel.width_m == pytest.approx(200.0, abs=0.2)
    assert channel.axis_deg % 180 == pytest.approx(0.0, abs=0.1) or channel.axis_deg % 180 > 179.9
    # The axis is the centre line x = 0 (east), from one end of the channel to the other.
    assert np.abs(shapely.get_coordinates(channel.axis)[:, 0]).max() < 1e-6
    north = np.array([0.0, 0.0, 0.0, 0.0, 300.0, 0.0, 0.0])
    east = np.array([50.0, 50.0, -60.0, -60.0, 0.0, 0.0, 150.0])
    course = np.array([0.0, 180.0, 0.0, 180.0, 90.0, 35.0, 0.0])
    facts = channel_facts(channels, north, east, course)
    assert facts.channel.tolist() == [0, 0, 0, 0, 0, 0, -1]
    assert list(facts.relation) == [ALONG, ALONG, ALONG, ALONG, CROSSING, OBLIQUE, "outside"]
    # Northbound, starboard is east; southbound, starboard is west.
    np.testing.assert_allclose(facts.offset_m[:5], [50.0, -50.0, -60.0, 60.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(facts.half_width_m[:6], 100.0, atol=1e-6)
    np.testing.assert_allclose(facts.offset_fraction[:4], [0.5, -0.5, -0.6, 0.6], atol=1e-8)
    # To the starboard-hand limit: 50 m (northbound at +50), 150 m (southbound at +50) …
    np.testing.assert_allclose(facts.starboard_limit_m[:4], [50.0, 150.0, 160.0, 40.0], atol=1e-6)
    np.testing.assert_allclose(facts.angle_to_axis_deg[:6], [0, 0, 0, 0, 90, 35], atol=1e-6)
    np.testing.assert_allclose(facts.axis_grid_deg[:4], [0.0, 180.0, 0.0, 180.0], atol=1e-6)
    assert np.isnan(facts.offset_m[6]) and np.isnan(facts.half_width_m[6])
    assert not facts.against_traffic.any()  # two-way: no traffic direction charted


def test_no_course_is_unknown_and_the_tolerances_are_parameters() -> None:
    channels = _channels(STRAIGHT)
    facts = channel_facts(channels, [0.0, 0.0], [0.0, 0.0], [np.nan, 35.0])
    assert list(facts.relation) == [ChannelRelation.UNKNOWN, OBLIQUE]
    assert np.isnan(facts.offset_m[0])
    wide = channel_facts(channels, [0.0], [0.0], [35.0], ChannelParams(40.0, 60.0))
    assert list(wide.relation) == [ALONG]
    with pytest.raises(ParameterError, match="along_within_deg 50"):
        ChannelParams(along_within_deg=50.0, crossing_from_deg=45.0)


def test_an_l_shaped_channel_gives_each_leg_its_direction() -> None:
    # Up the west leg (x 0..100) northwards to y = 1000, then east along y 900..1000.
    corner = shapely.Polygon(
        [(0, -1000), (100, -1000), (100, 900), (2000, 900), (2000, 1000), (0, 1000)]
    )
    channels = _channels(corner)
    axis = channels.axis_at([0.0, 950.0], [50.0, 1200.0], [0, 0])
    leg_deg = [axis.direction_grid_deg[0] % 180, axis.direction_grid_deg[1] % 180]
    assert leg_deg == pytest.approx([0.0, 90.0], abs=1.0)
    # Westbound on the east leg at 980 m north: north is her starboard side, 30 m off.
    # Eastbound there: 30 m to port. Northbound in the west leg at x 80: 30 m to starboard.
    facts = channel_facts(channels, [980.0, 980.0, 0.0], [1200.0, 1200.0, 80.0], [270, 90, 0])
    assert list(facts.relation) == [ALONG, ALONG, ALONG]
    np.testing.assert_allclose(facts.offset_m, [30.0, -30.0, 30.0], atol=0.5)
    np.testing.assert_allclose(facts.half_width_m, 50.0, atol=0.5)
    # Crossing the east leg southwards: 90° to its local axis, not "along" the west leg's.
    across = channel_facts(channels, [950.0], [1500.0], [180.0])
    assert list(across.relation) == [CROSSING]


def test_an_arc_channel_follows_its_bend() -> None:
    channels = _channels(annulus_sector(900.0, 1100.0, 120.0))
    at_deg = np.array([30.0, 45.0, 60.0, 90.0])
    radius = np.full(4, 1000.0)
    east, north = radius * np.sin(np.radians(at_deg)), radius * np.cos(np.radians(at_deg))
    axis = channels.axis_at(north, east, 0)
    # The tangent to the circle: the bearing from the centre plus 90°.
    off_tangent = (axis.direction_grid_deg - (at_deg + 90.0) + 90.0) % 180.0 - 90.0
    np.testing.assert_allclose(off_tangent, 0.0, atol=2.0)
    np.testing.assert_allclose(np.abs(axis.across_m), 0.0, atol=3.0)
    # On the outer side (r 1050) at 45°: clockwise round the bend (course 135°) the centre is
    # to starboard, so she is 50 m to port; anticlockwise (315°) 50 m to starboard.
    point_n, point_e = 1050 * math.cos(math.pi / 4), 1050 * math.sin(math.pi / 4)
    facts = channel_facts(channels, [point_n] * 2, [point_e] * 2, [135.0, 315.0])
    assert list(facts.relation) == [ALONG, ALONG]
    np.testing.assert_allclose(facts.offset_m, [-50.0, 50.0], atol=3.0)
    np.testing.assert_allclose(facts.half_width_m, 100.0, atol=3.0)


def test_precedence_between_overlapping_areas_is_by_kind_then_size() -> None:
    fairway = make_channel(FRAME, ChannelKind.FAIRWAY, STRAIGHT, record_id="FW")
    quarter = make_channel(
        FRAME, ChannelKind.DREDGED_AREA, shapely.box(0, -1000, 50, 1000), record_id="DQ"
    )
    berth = make_channel(FRAME, ChannelKind.FAIRWAY, shapely.box(50, -50, 100, 50), record_id="B")
    assert fairway is not None and quarter is not None and berth is not None
    channels = Channels(FRAME, (quarter, fairway, berth))
    index = channels.channel_at([0.0, 0.0, 0.0, np.nan], [25.0, 75.0, -50.0, 0.0])
    # In the dredged quarter the fairway decides; in the berth, the smaller of two fairways.
    assert channels.labels(index) == ["FAIRWY FW", "FAIRWY B", "FAIRWY FW", None]


@settings(max_examples=60)
@given(
    theta=st.floats(0.0, 180.0),
    width=st.floats(40.0, 400.0),
    centre=st.tuples(st.floats(-5000.0, 5000.0), st.floats(-5000.0, 5000.0)),
    along=st.floats(-600.0, 600.0),
    across_frac=st.floats(-0.9, 0.9),
    course=st.floats(0.0, 360.0, exclude_max=True),
    shift=st.tuples(st.floats(-3000.0, 3000.0), st.floats(-3000.0, 3000.0)),
)
def test_offsets_of_a_rotated_channel(
    theta: float,
    width: float,
    centre: tuple[float, float],
    along: float,
    across_frac: float,
    course: float,
    shift: tuple[float, float],
) -> None:
    """A straight channel 2 km long at any direction: the derived axis is its centre line,
    the offset is the distance across it with the sign of her starboard side, it flips when
    her course is reversed, and translating everything changes nothing."""
    u = np.array([math.sin(math.radians(theta)), math.cos(math.radians(theta))])
    right = np.array([u[1], -u[0]])
    c = np.asarray(centre)
    corners = [
        c + s * 1000.0 * u + t * width / 2 * right for s, t in ((-1, -1), (1, -1), (1, 1), (-1, 1))
    ]
    across = across_frac * width / 2
    east, north = c + along * u + across * right
    turn = abs((course - theta + 180.0) % 360.0 - 180.0)  # 0–180 from the axis direction
    # Not on the edge of a relation (30°, 45°) or square across, where rounding decides.
    assume(abs(turn - 90.0) > 0.5 and min(abs(min(turn, 180 - turn) - t) for t in (30, 45)) > 0.01)

    def facts(dx: float, dy: float, heading: float) -> Any:
        polygon = shapely.affinity.translate(shapely.Polygon(corners), dx, dy)
        return channel_facts(_channels(polygon), [north + dy], [east + dx], [heading])

    here = facts(0.0, 0.0, course)
    assert here.channel[0] == 0
    expected = across if turn < 90.0 else -across
    assert here.offset_m[0] == pytest.approx(expected, abs=0.5)
    assert here.half_width_m[0] == pytest.approx(width / 2, abs=0.5)
    assert here.angle_to_axis_deg[0] == pytest.approx(min(turn, 180 - turn), abs=0.5)
    back = facts(0.0, 0.0, (course + 180.0) % 360.0)
    assert back.offset_m[0] == pytest.approx(-here.offset_m[0], abs=1e-6)
    assert back.relation[0] == here.relation[0]
    moved = facts(*shift, course)
    assert moved.offset_m[0] == pytest.approx(here.offset_m[0], abs=1e-6)
    assert moved.half_width_m[0] == pytest.approx(here.half_width_m[0], abs=1e-6)
    assert moved.relation[0] == here.relation[0]


# -- charts written as GeoJSON in FRAME's metres ---------------------------------------------


def _chart(
    path: Path, *features: tuple[dict[str, Any], Any], box_m: float = 3000.0, **detail: Any
) -> Path:
    return write_chart(path, FRAME, *features, box_m=box_m, **detail)


def _load(*paths: Path) -> Channels:
    return load_channels(load_chart(list(paths), frame=FRAME))


def test_a_traffic_separation_scheme_from_geojson(tmp_path: Path) -> None:
    """Two lanes running north and south with a separation zone between, a separation line
    and the scheme's boundaries; one lane's class given by its numeric S-57 code."""
    path = _chart(
        tmp_path / "tss.geojson",
        ({"OBJL": "TSSLPT", "ORIENT": 0.0}, shapely.box(200, -2000, 1200, 2000)),
        ({"OBJL": 148, "ORIENT": 180.0}, shapely.box(-1200, -2000, -200, 2000)),
        ({"OBJL": "TSEZNE"}, shapely.box(-200, -2000, 200, 2000)),
        ({"OBJL": "TSELNE"}, shapely.LineString([(0, 2000), (0, 2800)])),
        ({"OBJL": "TSSBND"}, shapely.LineString([(1200, -2000), (1200, 2000)])),
        ({"OBJL": "TSSBND"}, shapely.LineString([(-1200, -2000), (-1200, 2000)])),
    )
    channels = _load(path)
    kinds = [c.kind for c in channels]
    assert kinds == [
        ChannelKind.TSS_LANE,
        ChannelKind.TSS_LANE,
        ChannelKind.TSS_ZONE,
        ChannelKind.TSS_LINE,
        ChannelKind.TSS_BOUNDARY,
        ChannelKind.TSS_BOUNDARY,
    ]
    north_lane, zone = channels[0], channels[2]
    assert north_lane.label == "TSSLPT tss#2" and north_lane.name is None
    assert north_lane.one_way and north_lane.axis_source is AxisSource.ORIENT
    assert zone.axis_source is AxisSource.CENTRELINE and not zone.one_way
    np.testing.assert_allclose(shapely.get_coordinates(north_lane.axis)[:, 0], 700.0, atol=0.5)
    index = channels.channel_at([0.0, 0.0, 0.0, 0.0], [700.0, -700.0, 0.0, 1500.0])
    assert index.tolist() == [0, 1, 2, -1]
    facts = channel_facts(channels, [0.0] * 4, [900.0, 900.0, 700.0, 700.0], [0, 180, 90, 60])
    assert list(facts.relation) == [ALONG, ALONG, CROSSING, CROSSING]
    assert facts.against_traffic.tolist() == [False, True, False, False]
    np.testing.assert_allclose(facts.offset_m[:2], [200.0, -200.0], atol=0.5)
    np.testing.assert_allclose(facts.angle_to_axis_deg[2:], [90.0, 60.0], atol=0.1)


def test_the_width_navigable_for_a_draught(tmp_path: Path) -> None:
    """A fairway 200 m wide over a 10 m deep west half and a 3 m east half of the chart, the
    depth boundary at x = 20 m: 120 m of it is navigable for 5 m, all 200 m for 2 m."""
    path = _chart(
        tmp_path / "halves.geojson",
        ({"OBJL": "DEPARE", "DRVAL1": 10.0}, shapely.box(-3000, -3000, 20, 3000)),
        ({"OBJL": "DEPARE", "DRVAL1": 3.0}, shapely.box(20, -3000, 3000, 3000)),
        ({"OBJL": "FAIRWY", "OBJNAM": "Halves", "TRAFIC": 4}, STRAIGHT),
    )
    channels = _load(path)
    (fairway,) = channels
    assert fairway.name == "Halves" and fairway.traffic is Traffic.TWO_WAY
    points = ([0.0, 0.0, 500.0], [-50.0, 60.0, 0.0])
    np.testing.assert_allclose(channels.width_m_at(*points, 0), 200.0, atol=0.5)
    np.testing.assert_allclose(channels.width_m_at(*points, 0, draught_m=2.0), 200.0, atol=0.5)
    five = channels.width_m_at(*points, 0, draught_m=5.0)
    np.testing.assert_allclose(five[[0, 2]], 120.0, atol=0.5)
    assert np.isnan(five[1])  # over the shallow half
    facts = channel_facts(channels, *points, [0.0] * 3, draught_m=4.5, ukc_m=0.5)
    np.testing.assert_allclose(facts.navigable_width_m[[0, 2]], 120.0, atol=0.5)


def test_where_charts_overlap_the_more_detailed_decides(tmp_path: Path) -> None:
    coarse = _chart(
        tmp_path / "coarse.geojson",
        ({"OBJL": "FAIRWY", "OBJNAM": "Coarse"}, shapely.box(-100, -2500, 100, 2500)),
        INTU=3,
    )
    harbour = tmp_path / "harbour.geojson"
    half = shapely.box(-3000, 0, 3000, 3000)
    harbour.write_text(
        json.dumps(
            {
                "type": "FeatureCollection",
                "features": [
                    feature(FRAME, {"OBJL": "M_COVR", "CATCOV": 1, "INTU": 5}, half),
                    feature(FRAME, {"OBJL": "DEPARE", "DRVAL1": 12.0}, half),
                    feature(
                        FRAME,
                        {"OBJL": "FAIRWY", "OBJNAM": "Harbour"},
                        shapely.box(-100, 0, 100, 2500),
                    ),
                ],
            }
        )
    )
    channels = _load(coarse, harbour)
    assert [(c.label, c.chart) for c in channels] == [
        ("Harbour", "harbour.geojson"),
        ("Coarse", "coarse.geojson"),
    ]
    assert shapely.bounds(channels[1].geometry)[3] == pytest.approx(0.0, abs=1e-6)
    index = channels.channel_at([1000.0, -1000.0], [0.0, 0.0])
    assert channels.labels(index) == ["Harbour", "Coarse"]


def test_a_chart_without_channels_and_a_bad_attribute(tmp_path: Path) -> None:
    plain = _load(_chart(tmp_path / "plain.geojson"))
    assert len(plain) == 0
    assert plain.channel_at([0.0], [0.0]).tolist() == [-1]
    assert list(channel_facts(plain, [0.0], [0.0], [0.0]).relation) == ["outside"]
    bad = _chart(tmp_path / "bad.geojson", ({"OBJL": "FAIRWY", "ORIENT": "north"}, STRAIGHT))
    with pytest.raises(
        ChartError, match=r"bad\.geojson: layer bad, feature \d+: ORIENT is 'north'"
    ):
        _load(bad)


# -- the real cells, checked against GDAL read directly ----------------------------------------


def _gdal_layer(path: Path, layer: str) -> dict[str, Any]:
    meta, _, _, fields = pyogrio.raw.read(path, layer=layer, UPDATES="APPLY")
    return dict(zip(meta["fields"], fields, strict=True))


@pytest.fixture(scope="module")
def sandiego() -> Channels:
    started = time.perf_counter()
    chart = load_chart([SANDIEGO_ENC])
    loaded = time.perf_counter()
    channels = load_channels(chart)
    # Measured at 0.9 s for the chart and 0.35 s for its channels; generous for a loaded CI.
    assert time.perf_counter() - loaded < 10.0 and loaded - started < 20.0
    return channels


def test_san_diego_channels_are_the_cells(sandiego: Channels) -> None:
    counts: dict[str, int] = {}
    for channel in sandiego:
        counts[channel.object_class] = counts.get(channel.object_class, 0) + 1
    assert counts == {"FAIRWY": 14, "DRGARE": 27, "RECTRC": 2, "NAVLNE": 5}
    for layer in counts:
        gdal = _gdal_layer(SANDIEGO_ENC, layer)
        ours = [c for c in sandiego if c.object_class == layer]
        assert sorted(c.record_id for c in ours) == sorted(gdal["LNAM"])
        names = {c.record_id: c.name for c in ours}
        for lnam, name in zip(gdal["LNAM"], gdal.get("OBJNAM", [None] * len(ours)), strict=True):
            assert names[lnam] == (name or None)
        if "ORIENT" in gdal:
            orient = {c.record_id: c.orient_deg for c in ours}
            for lnam, value in zip(gdal["LNAM"], gdal["ORIENT"], strict=True):
                assert orient[lnam] == (None if np.isnan(value) else value)
    tracks = [c for c in sandiego if c.kind is ChannelKind.RECOMMENDED_TRACK]
    assert sorted(c.orient_deg for c in tracks) == [232.0, 353.0]
    assert all(c.one_way for c in tracks)  # TRAFIC 3, as charted


def test_san_diego_main_channel_is_found_with_its_axis_along_the_bay(sandiego: Channels) -> None:
    (main,) = [c for c in sandiego if c.name == "San Diego Harbor Channel"]
    index = sandiego.items.index(main)
    assert main.kind is ChannelKind.FAIRWAY and main.axis_source is AxisSource.CENTRELINE
    assert main.length_m == pytest.approx(21_200, rel=0.02)
    (entrance_track,) = [
        c for c in sandiego if c.kind is ChannelKind.RECOMMENDED_TRACK and c.orient_deg == 353.0
    ]
    assert entrance_track.record_id in main.tracks
    # Halfway along the entrance track (353°): in the main channel, whose axis runs 353/173°.
    mid = shapely.line_interpolate_point(entrance_track.axis, 0.5, normalized=True)
    east, north = mid.x, mid.y
    assert sandiego.channel_at([north], [east]).tolist() == [index]
    direction = sandiego.axis_at([north], [east], index).direction_grid_deg
    lat, lon = sandiego.frame.to_geodetic(north, east)
    true_deg = sandiego.frame.grid_to_true_deg(direction, lat, lon)
    assert float(true_deg[0]) % 180 == pytest.approx(173.0, abs=2.0)
    # The bay's northern reach runs east-west at lat 32.718 (lon -117.204 to -117.194).
    north_m, east_m = sandiego.frame.to_local(32.7183, -117.1987)
    assert sandiego.channel_at(north_m, east_m).tolist() == [index]
    direction = sandiego.axis_at(north_m, east_m, index).direction_grid_deg
    assert float(direction[0]) % 180 == pytest.approx(90.0, abs=5.0)
    # An inbound ship up the entrance, 40 m east of the axis: along it, to starboard.
    facts = channel_facts(sandiego, [north], [east + 40.0], [353.0])
    assert list(facts.relation) == [ALONG]
    assert 0.0 < facts.offset_m[0] < facts.half_width_m[0]


def test_annapolis_fairways_with_their_names() -> None:
    channels = load_channels(load_chart([ANNAPOLIS_ENC]))
    gdal = _gdal_layer(ANNAPOLIS_ENC, "FAIRWY")
    fairways = [c for c in channels if c.kind is ChannelKind.FAIRWAY]
    assert len(fairways) == 10 == len(gdal["LNAM"])
    assert sorted(c.name for c in fairways if c.name) == [
        "Annapolis Harbor Channel",
        "Back Creek Channel",
        "Spa Creek Channel",
    ]
    assert sorted(c.label for c in fairways if not c.name) == sorted(
        f"FAIRWY {lnam}"
        for lnam, name in zip(gdal["LNAM"], gdal["OBJNAM"], strict=True)
        if not name
    )
    assert sum(c.kind is ChannelKind.DREDGED_AREA for c in channels) == 10
    assert all(c.axis_source is AxisSource.CENTRELINE for c in fairways)
    # Each dredged channel lies under the fairway of the same shape: the fairway is found.
    (harbour,) = [c for c in fairways if c.name == "Annapolis Harbor Channel"]
    point = shapely.line_interpolate_point(harbour.axis, 0.5, normalized=True)
    assert channels.labels(channels.channel_at([point.y], [point.x])) == [
        "Annapolis Harbor Channel"
    ]
    assert channels[channels.channel_at([point.y], [point.x])[0]].kind is ChannelKind.FAIRWAY
