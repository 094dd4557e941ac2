"""COLREGs rules 13–15 (G_a): situation and roles at every sector boundary, both sides."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from colregs9_cli.core.colregs import (
    ColregsParams,
    Kinematics,
    Role,
    Situation,
    SituationBasis,
    classify,
    colregs_params_from_table,
    evaluate_colregs,
    relative_bearing_deg,
)
from colregs9_cli.core.tracks import CourseSource
from colregs9_cli.errors import ParameterError, QueryError

PARAMS = ColregsParams()
# The sectors alone: no bearing moved by a margin, so no reading in doubt (rules 13(c), 14(c)).
SECTORS = ColregsParams(ambiguity_margin_deg=0.0)
EPS = 1e-6
GW, SO, NO = Role.GIVE_WAY, Role.STAND_ON, Role.NONE
HEAD_ON, CROSSING, OVERTAKING, NONE = (
    Situation.HEAD_ON,
    Situation.CROSSING,
    Situation.OVERTAKING,
    Situation.NONE,
)

# (β target from own, β' own from target, situation, own role, target role, own overtaking)
BOUNDARY_CASES = [
    # head-on half-angle 6°, on own ship's bow: inside (inclusive) and just outside
    (6.0, 6.0, HEAD_ON, GW, GW, False),
    (6.0 + EPS, 0.0, CROSSING, GW, SO, False),
    (354.0, 354.0, HEAD_ON, GW, GW, False),
    (354.0 - EPS, 0.0, CROSSING, SO, GW, False),
    (0.0, 0.0, HEAD_ON, GW, GW, False),
    # ... and on the target's bow
    (0.0, 6.0, HEAD_ON, GW, GW, False),
    (0.0, 6.0 + EPS, CROSSING, SO, GW, False),
    (0.0, 354.0, HEAD_ON, GW, GW, False),
    (0.0, 354.0 - EPS, CROSSING, GW, SO, False),
    # rule 14(c), in doubt: both on the same bow within 22.5°, and just outside
    (20.0, 10.0, HEAD_ON, GW, GW, False),
    (350.0, 340.0, HEAD_ON, GW, GW, False),
    (22.5 + EPS, 10.0, CROSSING, GW, SO, False),
    # ... red to red: courses within 22.5° of reciprocal, one of them within 22.5° of her bow
    # (San Diego's SAILEBRATE and SHELTER ISLAND: 352.9°, 335.2°), and just outside each
    (352.9, 335.2, HEAD_ON, GW, GW, False),
    (350.0, 327.5, HEAD_ON, GW, GW, False),
    (350.0, 327.5 - EPS, CROSSING, GW, SO, False),
    (337.5 - EPS, 320.0, CROSSING, GW, SO, False),
    # ... green to green the doubt stays narrow: both within 22.5° of the bow
    (10.0, 32.5, CROSSING, SO, GW, False),
    # overtaking: strictly more than 22.5° abaft the beam, (112.5°, 247.5°)
    (0.0, 112.5 + EPS, OVERTAKING, GW, SO, True),
    (0.0, 112.5, CROSSING, SO, GW, False),
    (0.0, 247.5 - EPS, OVERTAKING, GW, SO, True),
    (0.0, 247.5, CROSSING, GW, SO, False),
    (0.0, 180.0, OVERTAKING, GW, SO, True),
    # ... the target in own ship's sector
    (112.5 + EPS, 0.0, OVERTAKING, SO, GW, False),
    (112.5, 0.0, CROSSING, GW, SO, False),
    (247.5 - EPS, 0.0, OVERTAKING, SO, GW, False),
    (247.5, 0.0, CROSSING, SO, GW, False),
    # each astern of the other: nobody comes up from astern, so it falls through to crossing
    (150.0, 200.0, CROSSING, GW, SO, False),
    # crossing around dead ahead (0°), target on own ship's port beam side 270°
    (EPS, 270.0, CROSSING, GW, SO, False),
    (0.0, 270.0, CROSSING, GW, SO, False),
    # both on the port side: the target's bearing (90° off her fore-and-aft line) decides
    (360.0 - EPS, 270.0, CROSSING, GW, SO, False),
    # ... and own ship on the target's starboard side 90°
    (EPS, 90.0, CROSSING, SO, GW, False),
    (0.0, 90.0, CROSSING, SO, GW, False),
    (360.0 - EPS, 90.0, CROSSING, SO, GW, False),
    # the same-side crossings of the DMA sample (issue 13): one give-way vessel each
    (31.4, 10.0, CROSSING, GW, SO, False),
    (10.0, 31.4, CROSSING, SO, GW, False),
    (100.0, 45.0, CROSSING, GW, SO, False),
    # ... and its port-to-port pair near reciprocal courses: head-on in doubt
    (353.9, 352.5, HEAD_ON, GW, GW, False),
    # crossing around dead astern (180°), reachable only with both astern of each other
    (180.0 - EPS, 180.0, CROSSING, GW, SO, False),
    (180.0 + EPS, 180.0, CROSSING, SO, GW, False),
    # an exact tie on one side is reciprocal courses: head-on
    (60.0, 60.0, HEAD_ON, GW, GW, False),
    # ordinary crossings
    (45.0, 315.0, CROSSING, GW, SO, False),
    (315.0, 45.0, CROSSING, SO, GW, False),
]


@pytest.mark.parametrize(
    ("beta", "beta_prime", "situation", "own_role", "target_role", "own_overtaking"),
    BOUNDARY_CASES,
)
def test_boundaries_while_closing(
    beta: float,
    beta_prime: float,
    situation: Situation,
    own_role: Role,
    target_role: Role,
    own_overtaking: bool,
) -> None:
    result = classify(beta, beta_prime, True, SECTORS)
    assert result.situation[0] is situation
    assert result.own_role[0] is own_role
    assert result.target_role[0] is target_role
    assert bool(result.own_overtaking[0]) is own_overtaking
    # the other seat: the same situation, the roles swapped
    other = classify(beta_prime, beta, True, SECTORS)
    assert other.situation[0] is situation
    assert (other.own_role[0], other.target_role[0]) == (target_role, own_role)
    assert other.ambiguous[0] == result.ambiguous[0]


# Read in doubt (rules 14(c) and 13(c)): a crossing that a 3 deg move of the bearings makes
# head-on, or an overtaking by one vessel, is that (β, β', situation, own, target, basis).
IN_DOUBT_CASES = [
    # San Diego, TRADITION and CHAMPAGNE: 6.06 deg off one bow, 2.7 deg off the other
    (353.94, 2.72, HEAD_ON, GW, GW, SituationBasis.HEAD_ON_IN_DOUBT),
    (6.0 + EPS, 0.0, HEAD_ON, GW, GW, SituationBasis.HEAD_ON_IN_DOUBT),
    # a move into the same-bow doubt is no move into the head-on sectors: no stacked doubt
    (22.5 + EPS, 10.0, CROSSING, GW, SO, None),
    (357.9, 19.0, CROSSING, SO, GW, None),  # San Diego: LETO 2.1 deg to port, 19 deg off hers
    # beyond the margin: a crossing
    (9.5, 350.5, CROSSING, GW, SO, None),
    (0.0, 112.5, OVERTAKING, GW, SO, SituationBasis.OVERTAKING_IN_DOUBT),
    (247.5, 0.0, OVERTAKING, SO, GW, SituationBasis.OVERTAKING_IN_DOUBT),
    (0.0, 109.5 - EPS, CROSSING, SO, GW, None),
]


@pytest.mark.parametrize(
    ("beta", "beta_prime", "situation", "own_role", "target_role", "basis"), IN_DOUBT_CASES
)
def test_a_vessel_in_doubt_assumes_head_on_or_overtaking(
    beta: float,
    beta_prime: float,
    situation: Situation,
    own_role: Role,
    target_role: Role,
    basis: SituationBasis | None,
) -> None:
    for seat, (b, b_prime), roles in (
        ("a", (beta, beta_prime), (own_role, target_role)),
        ("b", (beta_prime, beta), (target_role, own_role)),
    ):
        result = classify(b, b_prime, True, PARAMS)
        assert result.situation[0] is situation, seat
        assert (result.own_role[0], result.target_role[0]) == roles, seat
        if basis is not None:
            assert result.basis[0] is basis and result.ambiguous[0], seat
    # the sectors alone keep the crossing
    assert classify(beta, beta_prime, True, SECTORS).situation[0] is CROSSING


@pytest.mark.parametrize(("beta", "beta_prime"), [(c[0], c[1]) for c in BOUNDARY_CASES])
def test_not_closing_is_no_situation(beta: float, beta_prime: float) -> None:
    result = classify(beta, beta_prime, False, PARAMS)
    assert result.situation[0] is NONE
    assert result.own_role[0] is NO and result.target_role[0] is NO
    assert not result.own_overtaking[0]


def test_classification_is_symmetric_in_the_two_vessels() -> None:
    rng = np.random.default_rng(4)
    beta = rng.uniform(0, 360, 2000)
    beta_prime = rng.uniform(0, 360, 2000)
    closing = rng.random(2000) < 0.8
    forward = classify(beta, beta_prime, closing, PARAMS)
    swapped = classify(beta_prime, beta, closing, PARAMS)
    assert (forward.situation == swapped.situation).all()
    assert (forward.own_role == swapped.target_role).all()
    assert (forward.target_role == swapped.own_role).all()


def test_configured_angles_move_the_boundaries() -> None:
    wide = ColregsParams(
        head_on_half_angle_deg=10.0,
        head_on_doubt_deg=10.0,
        overtaking_sector_min_deg=100.0,
        overtaking_sector_max_deg=260.0,
        ambiguity_margin_deg=0.0,
    )
    no_doubt = ColregsParams(head_on_doubt_deg=6.0, ambiguity_margin_deg=0.0)
    assert classify(8.0, 8.0, True, wide).situation[0] is HEAD_ON
    assert classify(8.0, 3.0, True, no_doubt).situation[0] is CROSSING
    assert classify(8.0, 3.0, True, PARAMS).situation[0] is HEAD_ON  # in doubt
    assert classify(0.0, 105.0, True, wide).situation[0] is OVERTAKING
    assert classify(0.0, 105.0, True, PARAMS).situation[0] is CROSSING
    assert classify(0.0, 255.0, True, wide).situation[0] is OVERTAKING


def test_ambiguous_near_a_boundary_only() -> None:
    # 1° inside the head-on sector (and the doubt region does not reach 5°/357°)
    near_head_on = classify(5.0, 357.0, True, PARAMS)
    assert near_head_on.situation[0] is HEAD_ON and near_head_on.ambiguous[0]
    # 2° short of the overtaking sector
    assert classify(0.0, 110.5, True, PARAMS).ambiguous[0]
    assert not classify(0.0, 100.0, True, PARAMS).ambiguous[0]
    # an ordinary crossing, far from every boundary
    assert not classify(45.0, 315.0, True, PARAMS).ambiguous[0]
    # a same-side crossing where the two bearings are nearly equally far from the line
    assert classify(60.0, 62.0, True, PARAMS).ambiguous[0]
    # the margin is a parameter; 0 turns the flag off
    assert not classify(0.0, 110.5, True, ColregsParams(ambiguity_margin_deg=0.0)).ambiguous[0]
    assert classify(0.0, 100.0, True, ColregsParams(ambiguity_margin_deg=15.0)).ambiguous[0]


def test_basis_records_the_reading() -> None:
    assert classify(45.0, 315.0, True, PARAMS).basis[0] is SituationBasis.SECTORS
    assert classify(20.0, 10.0, True, PARAMS).basis[0] is SituationBasis.HEAD_ON_IN_DOUBT
    assert classify(31.4, 10.0, True, PARAMS).basis[0] is SituationBasis.SAME_SIDE
    assert classify(31.4, 10.0, False, PARAMS).basis[0] is SituationBasis.NONE


def _scene(own_course, target_course, bearing, own_speed, target_speed, range_m=1000.0):
    """Own ship at the origin; the target at ``bearing`` (true) and ``range_m``."""
    bearing_rad = np.radians(bearing)
    own = Kinematics(
        north_m=np.zeros_like(bearing),
        east_m=np.zeros_like(bearing),
        cog_deg=own_course,
        heading_deg=np.full_like(bearing, np.nan),
        speed_mps=own_speed,
    )
    target = Kinematics(
        north_m=range_m * np.cos(bearing_rad),
        east_m=range_m * np.sin(bearing_rad),
        cog_deg=target_course,
        heading_deg=np.full_like(bearing, np.nan),
        speed_mps=target_speed,
    )
    return own, target


@pytest.mark.parametrize(("own_speed", "target_speed"), [(5.0, 5.0), (2.0, 7.0), (8.0, 1.0)])
def test_grid_sweep_seats_agree_and_a_crossing_has_one_give_way_vessel(
    own_speed: float, target_speed: float
) -> None:
    step = 3.0  # degrees: 120³ ≈ 1.7 M geometries per speed pair
    grid = np.arange(0.0, 360.0, step)
    own_course, target_course, bearing = (a.ravel() for a in np.meshgrid(grid, grid, grid))
    own, target = _scene(
        own_course,
        target_course,
        bearing,
        np.full_like(bearing, own_speed),
        np.full_like(bearing, target_speed),
    )
    forward = evaluate_colregs(own, target, PARAMS)
    backward = evaluate_colregs(target, own, PARAMS)
    assert (forward.situation == backward.situation).all()
    assert (forward.own_role == backward.target_role).all()
    assert (forward.target_role == backward.own_role).all()
    assert (forward.ambiguous == backward.ambiguous).all()
    give_way = (forward.own_role == GW).astype(int) + (forward.target_role == GW).astype(int)
    situation = forward.situation
    assert (give_way[situation == CROSSING] == 1).all()
    assert (give_way[situation == OVERTAKING] == 1).all()
    assert (give_way[situation == HEAD_ON] == 2).all()
    assert (give_way[situation == NONE] == 0).all()
    assert (forward.own_role[situation == NONE] == NO).all()
    # every situation occurs, and closing is what separates "none" from the rest
    assert {CROSSING, HEAD_ON, OVERTAKING, NONE} <= set(situation)
    assert ((situation == NONE) == ~forward.closing).all()


@given(
    st.floats(0, 360, exclude_max=True),
    st.floats(0, 360, exclude_max=True),
    st.floats(0, 360, exclude_max=True),
    st.floats(0, 360, exclude_max=True),
    st.floats(-5e4, 5e4),
    st.floats(-5e4, 5e4),
)
def test_rotating_and_moving_the_scene_changes_nothing(
    own_course: float, target_course: float, bearing: float, turn: float, dn: float, de: float
) -> None:
    own, target = _scene(
        np.array([own_course]), np.array([target_course]), np.array([bearing]), 4.0, 6.0
    )
    turned_own, turned_target = _scene(
        np.array([own_course + turn]),
        np.array([target_course + turn]),
        np.array([bearing + turn]),
        4.0,
        6.0,
    )
    moved = Kinematics(
        north_m=np.asarray(turned_own.north_m) + dn,
        east_m=np.asarray(turned_own.east_m) + de,
        cog_deg=turned_own.cog_deg,
        heading_deg=turned_own.heading_deg,
        speed_mps=turned_own.speed_mps,
    )
    moved_target = Kinematics(
        north_m=np.asarray(turned_target.north_m) + dn,
        east_m=np.asarray(turned_target.east_m) + de,
        cog_deg=turned_target.cog_deg,
        heading_deg=turned_target.heading_deg,
        speed_mps=turned_target.speed_mps,
    )
    before = evaluate_colregs(own, target, PARAMS)
    after = evaluate_colregs(moved, moved_target, PARAMS)
    # Bearings agree to rounding; away from a boundary the situation and roles do too.
    np.testing.assert_allclose(np.cos(np.radians(before.beta_deg - after.beta_deg)), 1.0, atol=1e-9)
    if not before.ambiguous[0]:
        assert before.situation[0] is after.situation[0]
        assert before.own_role[0] is after.own_role[0]
        assert before.target_role[0] is after.target_role[0]


def test_relative_bearing() -> None:
    # Target 1 km east of own ship heading north: 90°; own ship heading east: 0°.
    assert relative_bearing_deg(0, 0, 0.0, 0, 1000) == pytest.approx(90.0)
    assert relative_bearing_deg(0, 0, 90.0, 0, 1000) == pytest.approx(0.0)
    assert relative_bearing_deg(0, 0, 100.0, 0, 1000) == pytest.approx(350.0)
    assert relative_bearing_deg(0, 0, 0.0, -1000, -1000) == pytest.approx(225.0)


def ship(
    north: float, east: float, cog: float, speed: float, heading: float = np.nan
) -> Kinematics:
    return Kinematics(
        north_m=np.array([north]),
        east_m=np.array([east]),
        cog_deg=np.array([cog]),
        heading_deg=np.array([heading]),
        speed_mps=np.array([speed]),
    )


@pytest.mark.parametrize(
    ("own", "target", "situation", "own_role", "target_role"),
    [
        # reciprocal courses on one line
        (ship(0, 0, 0.0, 5.0), ship(1000, 0, 180.0, 5.0), HEAD_ON, GW, GW),
        # target from starboard heading west: own ship gives way (rule 15)
        (ship(0, 0, 0.0, 5.0), ship(1000, 1000, 270.0, 5.0), CROSSING, GW, SO),
        # own ship faster, same course, target 500 m ahead: own ship overtakes (rule 13)
        (ship(0, 0, 0.0, 8.0), ship(500, 0, 0.0, 3.0), OVERTAKING, GW, SO),
        # the paper's case: own ship southbound, the target crosses from her port side
        (ship(0, 0, 180.0, 1.03), ship(-500, 800, 270.0, 3.6), CROSSING, SO, GW),
        # the same target already past and opening
        (ship(0, 0, 180.0, 1.03), ship(-500, -800, 270.0, 3.6), NONE, NO, NO),
        # same course and speed: the range is steady, not closing
        (ship(0, 0, 30.0, 4.0), ship(100, 0, 30.0, 4.0), NONE, NO, NO),
    ],
)
def test_geometric_situations(
    own: Kinematics, target: Kinematics, situation: Situation, own_role: Role, target_role: Role
) -> None:
    result = evaluate_colregs(own, target, PARAMS)
    assert result.situation[0] is situation
    assert result.own_role[0] is own_role
    assert result.target_role[0] is target_role


def test_course_source_heading_changes_the_bearings() -> None:
    own = ship(0, 0, 0.0, 5.0)
    crabbing = ship(1000, 0, 180.0, 5.0, heading=170.0)  # moves south, bow 10° to port of it
    by_cog = evaluate_colregs(own, crabbing, SECTORS)
    heading = ColregsParams(course_source=CourseSource.HEADING, ambiguity_margin_deg=0.0)
    by_heading = evaluate_colregs(own, crabbing, heading)
    assert by_cog.situation[0] is HEAD_ON
    assert by_heading.beta_prime_deg[0] == pytest.approx(10.0)
    assert by_heading.situation[0] is CROSSING
    assert (by_heading.own_role[0], by_heading.target_role[0]) == (SO, GW)
    no_heading = ship(1000, 0, 180.0, 5.0)
    assert evaluate_colregs(own, no_heading, heading).situation[0] is HEAD_ON


def test_vectorised_over_steps() -> None:
    own = Kinematics(
        north_m=np.zeros(3),
        east_m=np.zeros(3),
        cog_deg=np.zeros(3),
        heading_deg=np.full(3, np.nan),
        speed_mps=np.full(3, 5.0),
    )
    target = Kinematics(
        north_m=np.array([1000.0, 1000.0, -1000.0]),
        east_m=np.array([0.0, 1000.0, 0.0]),
        cog_deg=np.array([180.0, 270.0, 0.0]),
        heading_deg=np.full(3, np.nan),
        speed_mps=np.array([5.0, 5.0, 2.0]),
    )
    result = evaluate_colregs(own, target, PARAMS)
    assert list(result.situation) == [HEAD_ON, CROSSING, NONE]
    assert list(result.own_role) == [GW, GW, NO]
    assert result.closing.tolist() == [True, True, False]


def test_string_values() -> None:
    assert [s.value for s in Situation] == ["head-on", "crossing", "overtaking", "none"]
    assert [r.value for r in Role] == ["give-way", "stand-on", "none"]


@pytest.mark.parametrize(
    "kwargs",
    [
        {"head_on_half_angle_deg": -1.0},
        {"head_on_half_angle_deg": 90.0},
        {"head_on_half_angle_deg": float("nan")},
        {"overtaking_sector_min_deg": 90.0},
        {"overtaking_sector_max_deg": 180.0},
        {"overtaking_sector_max_deg": 270.0},
        {"head_on_doubt_deg": 5.0},
        {"head_on_doubt_deg": 90.0},
        {"ambiguity_margin_deg": -1.0},
        {"ambiguity_margin_deg": float("inf")},
    ],
)
def test_parameters_out_of_range(kwargs: dict[str, float]) -> None:
    with pytest.raises(ParameterError, match=r"\[colregs\]"):
        ColregsParams(**kwargs)


def test_parameters_from_a_toml_table() -> None:
    params = colregs_params_from_table(
        {"head_on_half_angle_deg": 8, "course_source": "heading"}, "q.toml [colregs]"
    )
    assert params == ColregsParams(head_on_half_angle_deg=8.0, course_source=CourseSource.HEADING)
    assert params.course_source is CourseSource.HEADING
    with pytest.raises(QueryError, match=r"q.toml \[colregs\]: unknown key 'head_on'"):
        colregs_params_from_table({"head_on": 8}, "q.toml [colregs]")
    with pytest.raises(QueryError, match="course_source"):
        colregs_params_from_table({"course_source": "gyro"}, "q.toml [colregs]")


def test_a_slow_vessels_cog_makes_the_situation_ambiguous() -> None:
    # a clear crossing (target 45° on the starboard bow heading west), far from any sector
    # boundary; speeds in m/s
    own, target = ship(0, 0, 0.0, 5.0), ship(1000, 1000, 270.0, 5.0)
    assert not evaluate_colregs(own, target, PARAMS, course_judged_above_kn=2.0).ambiguous[0]
    slow_target = ship(1000, 1000, 270.0, 0.9)  # 1.75 kn: her COG is noise
    slow = evaluate_colregs(own, slow_target, PARAMS, course_judged_above_kn=2.0)
    assert slow.situation[0] is CROSSING and slow.ambiguous[0]
    assert evaluate_colregs(slow_target, own, PARAMS, course_judged_above_kn=2.0).ambiguous[0]
    # her heading is no noise: with course_source = heading and a heading, not ambiguous
    by_heading = ColregsParams(course_source=CourseSource.HEADING)
    steered = ship(1000, 1000, 270.0, 0.9, heading=270.0)
    assert not evaluate_colregs(own, steered, by_heading, course_judged_above_kn=2.0).ambiguous[0]
    assert evaluate_colregs(own, slow_target, by_heading, course_judged_above_kn=2.0).ambiguous[0]


def test_an_unknown_bearing_is_no_situation_and_no_warning() -> None:
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = classify([np.nan, 10.0], [200.0, np.nan], [True, True], ColregsParams())
    assert list(result.situation) == [Situation.NONE, Situation.NONE]
