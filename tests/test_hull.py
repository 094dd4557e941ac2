"""Hull outlines and the least distance between two hulls: hand-worked rectangles, an
independent oracle (separating axes and vertex-to-edge distances, no shapely), invariances,
NaN propagation, the offsets from AIS A/B/C/D, and the geodetic form."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from pyproj import Geod

from colregs9_cli.core.hull import (
    DEFAULT_ANTENNA_FROM_BOW_FRAC,
    UNKNOWN_OFFSETS,
    HullOffsets,
    centred_offsets,
    hull_outlines,
    least_hull_distance_geodetic_m,
    least_hull_distance_m,
    offsets_from_ais,
)
from colregs9_cli.errors import ParameterError
from colregs9_cli.geo import sail, true_bearing_deg

SHIP = centred_offsets(100.0, 10.0)  # 50 m to bow and stern, 5 m each side


def distance(
    a: tuple[float, float, float],
    a_offsets: HullOffsets,
    b: tuple[float, float, float],
    b_offsets: HullOffsets,
) -> float:
    """One step: a and b are (north_m, east_m, heading_deg)."""
    return float(least_hull_distance_m(*a, a_offsets, *b, b_offsets)[0])


# -- hand-worked rectangles ------------------------------------------------------------------


def test_parallel_side_by_side_is_the_separation_less_the_half_breadths() -> None:
    assert distance((0.0, 0.0, 0.0), SHIP, (0.0, 30.0, 0.0), SHIP) == pytest.approx(20.0)
    # Heading east, b 30 m to the south (a's starboard side).
    assert distance((0.0, 0.0, 90.0), SHIP, (-30.0, 0.0, 90.0), SHIP) == pytest.approx(20.0)


def test_side_by_side_uses_the_facing_sides_offsets() -> None:
    # a's starboard side is 8 m out; b (to starboard of a, same heading) has her port 3 m out.
    a = HullOffsets(60.0, 40.0, 2.0, 8.0)
    b = HullOffsets(30.0, 30.0, 3.0, 7.0)
    assert distance((0.0, 0.0, 0.0), a, (0.0, 30.0, 0.0), b) == pytest.approx(30.0 - 8.0 - 3.0)
    # Swapping sides: b to port of a faces a's port side (2 m) and b's starboard side (7 m).
    assert distance((0.0, 0.0, 0.0), a, (0.0, -30.0, 0.0), b) == pytest.approx(30.0 - 2.0 - 7.0)


def test_crossing_at_right_angles_bow_to_side() -> None:
    # a heads north, her bow 60 m ahead of her antenna. b heads west 100 m ahead of a: her
    # port side (4 m) faces south, and her hull spans east -30 … +70, across a's bow.
    a = HullOffsets(60.0, 40.0, 5.0, 5.0)
    b = HullOffsets(30.0, 70.0, 4.0, 6.0)
    assert distance((0.0, 0.0, 0.0), a, (100.0, 0.0, 270.0), b) == pytest.approx(100 - 60 - 4)
    # Heading east instead, b shows her starboard side (6 m) to the south.
    assert distance((0.0, 0.0, 0.0), a, (100.0, 0.0, 90.0), b) == pytest.approx(100 - 60 - 6)


def test_bow_to_bow_head_on() -> None:
    a = HullOffsets(60.0, 40.0, 5.0, 5.0)
    b = HullOffsets(30.0, 20.0, 3.0, 3.0)
    # b heads south 200 m north of a: bows at north 60 and 170.
    assert distance((0.0, 0.0, 0.0), a, (200.0, 0.0, 180.0), b) == pytest.approx(110.0)
    # Offset 4 m to the east the bows still overlap across (a spans ±5 m): same distance.
    assert distance((0.0, 0.0, 0.0), a, (200.0, 4.0, 180.0), b) == pytest.approx(110.0)


def test_corner_to_corner() -> None:
    # a spans north -50 … 50, east -5 … 5; b north 100 … 200, east 15 … 25.
    expected = math.hypot(100.0 - 50.0, 15.0 - 5.0)
    assert distance((0.0, 0.0, 0.0), SHIP, (150.0, 20.0, 0.0), SHIP) == pytest.approx(expected)


@pytest.mark.parametrize("east_m", [0.0, 4.0, 9.999, 10.0])
def test_overlapping_or_touching_hulls_are_zero(east_m: float) -> None:
    # Alongside: half-breadths 5 + 5 = 10 m, so up to 10 m the hulls touch or overlap.
    assert distance((0.0, 0.0, 0.0), SHIP, (20.0, east_m, 180.0), SHIP) == 0.0


def test_crossed_hulls_overlap_though_no_corner_is_inside_the_other() -> None:
    # A cross: each long thin hull passes through the other's middle.
    assert distance((0.0, 0.0, 0.0), SHIP, (0.0, 0.0, 90.0), SHIP) == 0.0


def test_just_apart_is_just_above_zero() -> None:
    assert distance((0.0, 0.0, 0.0), SHIP, (0.0, 10.001, 0.0), SHIP) == pytest.approx(0.001)


def test_the_outline_is_the_ais_rectangle_around_the_antenna() -> None:
    offsets = HullOffsets(60.0, 40.0, 4.0, 6.0)
    (hull,) = hull_outlines(0.0, 0.0, 90.0, offsets)  # heading east: port is north
    assert hull.area == pytest.approx(100.0 * 10.0)
    assert shapely.bounds(hull) == pytest.approx([-40.0, -6.0, 60.0, 4.0])
    (north_up,) = hull_outlines(100.0, 200.0, 0.0, offsets)  # heading north: port is west
    assert shapely.bounds(north_up) == pytest.approx([196.0, 60.0, 206.0, 160.0])


# -- an independent oracle for two rectangles ---------------------------------------------------


def _corners(north: float, east: float, heading: float, o: HullOffsets) -> np.ndarray:
    h = math.radians(heading)
    along = np.array([math.sin(h), math.cos(h)])  # (east, north) of the bow direction
    across = np.array([math.cos(h), -math.sin(h)])  # starboard
    centre = np.array([east, north])
    return np.array(
        [
            centre + fwd * along + stbd * across
            for fwd, stbd in (
                (o.to_bow_m, -o.to_port_m),
                (o.to_bow_m, o.to_starboard_m),
                (-o.to_stern_m, o.to_starboard_m),
                (-o.to_stern_m, -o.to_port_m),
            )
        ]
    )


def _point_to_segment(p: np.ndarray, s0: np.ndarray, s1: np.ndarray) -> float:
    edge = s1 - s0
    t = float(np.clip(np.dot(p - s0, edge) / np.dot(edge, edge), 0.0, 1.0))
    return float(np.linalg.norm(p - (s0 + t * edge)))


def oracle_distance(p: np.ndarray, q: np.ndarray) -> float:
    """Two convex quadrilaterals: 0 unless an edge normal separates them (separating axis
    theorem); then the least vertex-to-edge distance either way."""
    separated = False
    for poly in (p, q):
        for i in range(4):
            edge = poly[(i + 1) % 4] - poly[i]
            axis = np.array([-edge[1], edge[0]])
            pp, qq = p @ axis, q @ axis
            if pp.max() < qq.min() or qq.max() < pp.min():
                separated = True
    if not separated:
        return 0.0
    return min(
        _point_to_segment(v, poly[i], poly[(i + 1) % 4])
        for vs, poly in ((p, q), (q, p))
        for v in vs
        for i in range(4)
    )


offsets_st = st.builds(
    HullOffsets,
    st.floats(0.5, 200.0),
    st.floats(0.5, 200.0),
    st.floats(0.2, 30.0),
    st.floats(0.2, 30.0),
)
place_st = st.tuples(st.floats(-500.0, 500.0), st.floats(-500.0, 500.0), st.floats(0.0, 360.0))


@settings(max_examples=300)
@given(a=place_st, a_offsets=offsets_st, b=place_st, b_offsets=offsets_st)
def test_agrees_with_an_independent_oracle(
    a: tuple[float, float, float],
    a_offsets: HullOffsets,
    b: tuple[float, float, float],
    b_offsets: HullOffsets,
) -> None:
    expected = oracle_distance(_corners(*a, a_offsets), _corners(*b, b_offsets))
    assert distance(a, a_offsets, b, b_offsets) == pytest.approx(expected, abs=1e-6)


# -- properties ----------------------------------------------------------------------------------


@settings(max_examples=200)
@given(
    a=place_st,
    a_offsets=offsets_st,
    b=place_st,
    b_offsets=offsets_st,
    turn_deg=st.floats(0.0, 360.0),
    pivot=st.tuples(st.floats(-1e4, 1e4), st.floats(-1e4, 1e4)),
    shift=st.tuples(st.floats(-1e5, 1e5), st.floats(-1e5, 1e5)),
)
def test_invariant_under_rotation_translation_and_swapping(
    a: tuple[float, float, float],
    a_offsets: HullOffsets,
    b: tuple[float, float, float],
    b_offsets: HullOffsets,
    turn_deg: float,
    pivot: tuple[float, float],
    shift: tuple[float, float],
) -> None:
    def moved(place: tuple[float, float, float]) -> tuple[float, float, float]:
        # Turn clockwise by turn_deg about the pivot (as a heading turns), then shift.
        north, east = place[0] - pivot[0], place[1] - pivot[1]
        t = math.radians(turn_deg)
        return (
            pivot[0] + north * math.cos(t) - east * math.sin(t) + shift[0],
            pivot[1] + north * math.sin(t) + east * math.cos(t) + shift[1],
            (place[2] + turn_deg) % 360.0,
        )

    reference = distance(a, a_offsets, b, b_offsets)
    assert distance(b, b_offsets, a, a_offsets) == reference
    assert distance(moved(a), a_offsets, moved(b), b_offsets) == pytest.approx(reference, abs=1e-6)


@given(a=place_st, a_offsets=offsets_st, b=place_st, b_offsets=offsets_st)
def test_bounded_by_the_antenna_range(
    a: tuple[float, float, float],
    a_offsets: HullOffsets,
    b: tuple[float, float, float],
    b_offsets: HullOffsets,
) -> None:
    """The antennas are on the hulls, and no hull point is farther from its antenna than
    the farthest corner."""
    antenna_range = math.hypot(a[0] - b[0], a[1] - b[1])
    reach_a = math.hypot(
        max(a_offsets.to_bow_m, a_offsets.to_stern_m),
        max(a_offsets.to_port_m, a_offsets.to_starboard_m),
    )
    reach_b = math.hypot(
        max(b_offsets.to_bow_m, b_offsets.to_stern_m),
        max(b_offsets.to_port_m, b_offsets.to_starboard_m),
    )
    d = distance(a, a_offsets, b, b_offsets)
    assert d <= antenna_range + 1e-9
    assert d >= antenna_range - reach_a - reach_b - 1e-9


def test_vectorised_over_steps_matches_one_step_at_a_time() -> None:
    rng = np.random.default_rng(9)
    n = 200
    a = rng.uniform(-300, 300, n), rng.uniform(-300, 300, n), rng.uniform(0, 360, n)
    b = rng.uniform(-300, 300, n), rng.uniform(-300, 300, n), rng.uniform(0, 360, n)
    a_offsets, b_offsets = HullOffsets(80.0, 20.0, 6.0, 9.0), HullOffsets(10.0, 3.0, 1.0, 2.0)
    together = least_hull_distance_m(*a, a_offsets, *b, b_offsets)
    one_by_one = [
        distance((a[0][i], a[1][i], a[2][i]), a_offsets, (b[0][i], b[1][i], b[2][i]), b_offsets)
        for i in range(n)
    ]
    assert together.shape == (n,)
    np.testing.assert_array_equal(together, one_by_one)
    # A stationary vessel (scalars) broadcasts against the other's track.
    np.testing.assert_array_equal(
        least_hull_distance_m(0.0, 0.0, 0.0, a_offsets, *b, b_offsets),
        least_hull_distance_m(np.zeros(n), np.zeros(n), np.zeros(n), a_offsets, *b, b_offsets),
    )


# -- NaN -----------------------------------------------------------------------------------------


@pytest.mark.parametrize("which", range(6))
def test_a_nan_input_gives_nan_at_that_step_only(which: int) -> None:
    columns = [np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.full(3, 30.0), np.zeros(3)]
    columns[which][1] = np.nan
    a_north, a_east, a_heading, b_north, b_east, b_heading = columns
    d = least_hull_distance_m(a_north, a_east, a_heading, SHIP, b_north, b_east, b_heading, SHIP)
    assert d[0] == d[2] == pytest.approx(20.0)
    assert math.isnan(d[1])


def test_unknown_offsets_give_nan_everywhere() -> None:
    partly = HullOffsets(50.0, 50.0, math.nan, 5.0)
    assert not partly.known
    for a_offsets, b_offsets in ((UNKNOWN_OFFSETS, SHIP), (SHIP, partly)):
        d = least_hull_distance_m([0.0, 0.0], 0.0, 0.0, a_offsets, 0.0, 30.0, 0.0, b_offsets)
        assert np.isnan(d).all()
    assert list(hull_outlines([0.0, 1.0], 0.0, 0.0, UNKNOWN_OFFSETS)) == [None, None]


def test_infinite_positions_give_nan() -> None:
    d = least_hull_distance_m([0.0, np.inf], 0.0, 0.0, SHIP, 0.0, 30.0, [0.0, 0.0], SHIP)
    assert d[0] == pytest.approx(20.0) and math.isnan(d[1])


# -- offsets -------------------------------------------------------------------------------------


def test_centred_offsets_put_the_antenna_amidships_on_the_centre_line() -> None:
    assert DEFAULT_ANTENNA_FROM_BOW_FRAC == 0.5
    assert centred_offsets(100.0, 10.0) == HullOffsets(50.0, 50.0, 5.0, 5.0, defaulted=True)
    aft = centred_offsets(100.0, 10.0, antenna_from_bow_frac=0.8)
    assert (aft.to_bow_m, aft.to_stern_m) == pytest.approx((80.0, 20.0))
    assert aft.defaulted
    assert centred_offsets(math.nan, 10.0) == UNKNOWN_OFFSETS
    assert centred_offsets(100.0, 0.0) == UNKNOWN_OFFSETS
    with pytest.raises(ParameterError, match="antenna_from_bow_frac"):
        centred_offsets(100.0, 10.0, antenna_from_bow_frac=1.5)


def test_offsets_from_ais_all_four_reported() -> None:
    offsets = offsets_from_ais(223, 65, 25, 24, length_m=288.0, breadth_m=49.0)
    assert offsets == HullOffsets(223.0, 65.0, 25.0, 24.0, defaulted=False)
    assert (offsets.length_m, offsets.breadth_m) == (288.0, 49.0)


def test_offsets_from_ais_reference_point_not_available() -> None:
    # ITU-R M.1371: A = C = 0 with B, D > 0 gives the dimensions but not the antenna.
    assert offsets_from_ais(0, 120, 0, 18) == centred_offsets(120.0, 18.0)
    assert offsets_from_ais(0, 120, 0, 18, length_m=60.0, breadth_m=9.0) == centred_offsets(
        120.0, 18.0
    )
    # Beyond what ships have: the length and breadth given instead, else unknown.
    assert offsets_from_ais(0, 600, 0, 18, length_m=60.0, breadth_m=9.0) == centred_offsets(
        60.0, 9.0
    )
    assert offsets_from_ais(0, 600, 0, 18) == UNKNOWN_OFFSETS


def test_offsets_from_ais_fills_a_missing_side_from_the_breadth() -> None:
    # D not available (0): A and B are kept, the breadth is centred.
    assert offsets_from_ais(20, 20, 11, 0, length_m=40.0, breadth_m=8.0) == HullOffsets(
        20.0, 20.0, 4.0, 4.0, defaulted=True
    )
    assert offsets_from_ais(0, 13, 6, 4, length_m=20.0, breadth_m=10.0) == HullOffsets(
        10.0, 10.0, 6.0, 4.0, defaulted=True
    )
    # Without a breadth to fall back on, the hull is unknown.
    assert offsets_from_ais(20, 20, 11, 0) == UNKNOWN_OFFSETS


@pytest.mark.parametrize(
    ("parts", "expected"),
    [
        ((None, None, None, None), (50.0, 50.0, 5.0, 5.0)),
        ((0, 0, 0, 0), (50.0, 50.0, 5.0, 5.0)),
        ((math.nan, 10, 2, 2), (50.0, 50.0, 2.0, 2.0)),  # C and D kept
        ((400, 200, 3, 7), (50.0, 50.0, 3.0, 7.0)),  # A + B beyond 500 m
        ((30, 70, 50, 40), (30.0, 70.0, 5.0, 5.0)),  # C + D beyond 80 m
    ],
)
def test_offsets_from_ais_not_available_or_implausible_fall_back(
    parts: tuple[float | None, ...], expected: tuple[float, float, float, float]
) -> None:
    a, b, c, d = parts
    bow, stern, port, starboard = expected
    assert offsets_from_ais(a, b, c, d, length_m=100.0, breadth_m=10.0) == HullOffsets(
        bow, stern, port, starboard, defaulted=True
    )
    assert offsets_from_ais(a, b, c, d) == UNKNOWN_OFFSETS


@pytest.mark.parametrize(
    "parts", [(-1.0, 10.0, 2.0, 2.0), (math.inf, 10.0, 2.0, 2.0), (0.0, 0.0, 2.0, 2.0)]
)
def test_offsets_that_draw_no_hull_are_refused(parts: tuple[float, float, float, float]) -> None:
    with pytest.raises(ParameterError, match="offsets"):
        HullOffsets(*parts)


# -- the geodetic form ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("lat", "lon"), [(55.7, 12.6), (32.7, -117.2), (-33.9, 151.2), (78.2, 15.6), (0.0, 179.9999)]
)
def test_geodetic_side_by_side(lat: float, lon: float) -> None:
    # b 30 m due east of a, both heading true north: 20 m between the hulls, to within the
    # convergence of the meridians over 30 m (sub-millimetre).
    b_lat, b_lon = sail(lat, lon, 90.0, 30.0)
    d = least_hull_distance_geodetic_m(lat, lon, 0.0, SHIP, b_lat, b_lon, 0.0, SHIP)
    assert d[0] == pytest.approx(20.0, abs=2e-3)
    swapped = least_hull_distance_geodetic_m(b_lat, b_lon, 0.0, SHIP, lat, lon, 0.0, SHIP)
    assert swapped[0] == pytest.approx(d[0], abs=1e-9)


def test_geodetic_head_on_across_the_antimeridian_agrees_with_the_plane() -> None:
    # b 500 m from a on a true bearing, each heading at the other: bows 500 - 60 - 30 apart.
    a_lat, a_lon = -16.5, 179.9995
    b_lat, b_lon = sail(a_lat, a_lon, 80.0, 500.0)
    a_offsets, b_offsets = HullOffsets(60.0, 40.0, 5.0, 5.0), HullOffsets(30.0, 20.0, 3.0, 3.0)
    towards_b = true_bearing_deg(a_lat, a_lon, b_lat, b_lon)
    towards_a = true_bearing_deg(b_lat, b_lon, a_lat, a_lon)
    d = least_hull_distance_geodetic_m(
        a_lat, a_lon, towards_b, a_offsets, b_lat, b_lon, towards_a, b_offsets
    )
    assert b_lon[()] < 0.0  # across 180°
    assert d[0] == pytest.approx(500.0 - 60.0 - 30.0, abs=1e-2)


def test_geodetic_nan_propagates() -> None:
    d = least_hull_distance_geodetic_m(
        [55.0, np.nan], 12.0, [0.0, 0.0], SHIP, 55.0, 12.001, [0.0, 0.0], SHIP
    )
    assert np.isfinite(d[0]) and math.isnan(d[1])
    d = least_hull_distance_geodetic_m(55.0, 12.0, np.nan, SHIP, 55.0, 12.001, 0.0, SHIP)
    assert math.isnan(d[0])


def test_geodetic_headings_follow_the_converging_meridians() -> None:
    """Two 300 m ships 2 nm apart abeam at 78° N, both heading true north: the meridians
    converge by 0.16° between them, so their bows are about 0.4 m closer than their sterns.
    The least distance is between the inner bow corners, placed here by sailing geodesics."""
    lat, lon = 78.0, 15.0
    offsets = HullOffsets(150.0, 150.0, 20.0, 20.0)
    b_lat, b_lon = sail(lat, lon, 90.0, 2.0 * 1852.0)
    a_bow_lat, a_bow_lon = sail(*sail(lat, lon, 0.0, 150.0), 90.0, 20.0)
    b_bow_lat, b_bow_lon = sail(*sail(b_lat, b_lon, 0.0, 150.0), 270.0, 20.0)
    _, _, expected = Geod(ellps="WGS84").inv(a_bow_lon, a_bow_lat, b_bow_lon, b_bow_lat)
    d = least_hull_distance_geodetic_m(lat, lon, 0.0, offsets, b_lat, b_lon, 0.0, offsets)
    assert 2.0 * 1852.0 - 40.0 - d[0] > 0.3  # closer than the hulls' stated abeam distance
    assert d[0] == pytest.approx(expected, abs=0.01)
