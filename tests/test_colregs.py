"""COLREGs rules 13–15 (G_a): situation and roles at every sector boundary, both sides."""

from __future__ import annotations

import numpy as np
import pytest

from colregs9_cli.colregs import (
    ColregsParams,
    Kinematics,
    Role,
    Situation,
    classify,
    colregs_params_from_table,
    evaluate_colregs,
    relative_bearing_deg,
)
from colregs9_cli.errors import ParameterError, QueryError
from colregs9_cli.replay_params import CourseSource

PARAMS = ColregsParams()
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
    # overtaking sector 112.5°–247.5° (inclusive): own ship in the target's sector
    (0.0, 112.5, OVERTAKING, GW, SO, True),
    (0.0, 112.5 - EPS, CROSSING, SO, GW, False),
    (0.0, 247.5, OVERTAKING, GW, SO, True),
    (0.0, 247.5 + EPS, CROSSING, GW, SO, False),
    (0.0, 180.0, OVERTAKING, GW, SO, True),
    # ... the target in own ship's sector
    (112.5, 0.0, OVERTAKING, SO, GW, False),
    (112.5 - EPS, 0.0, CROSSING, GW, SO, False),
    (247.5, 0.0, OVERTAKING, SO, GW, False),
    (247.5 + EPS, 0.0, CROSSING, SO, GW, False),
    # each astern of the other: nobody comes up from astern, so it falls through to crossing
    (150.0, 200.0, CROSSING, GW, SO, False),
    # crossing around dead ahead (0°), target on own ship's port beam side 270°
    (EPS, 270.0, CROSSING, GW, SO, False),
    (0.0, 270.0, CROSSING, GW, SO, False),
    (360.0 - EPS, 270.0, CROSSING, SO, SO, False),  # port to port: both stand on
    # ... and own ship on the target's starboard side 90°
    (EPS, 90.0, CROSSING, GW, GW, False),  # starboard to starboard: both give way
    (0.0, 90.0, CROSSING, SO, GW, False),
    (360.0 - EPS, 90.0, CROSSING, SO, GW, False),
    # crossing around dead astern (180°), reachable only with both astern of each other
    (180.0 - EPS, 180.0, CROSSING, GW, SO, False),
    (180.0, 180.0, CROSSING, GW, GW, False),
    (180.0 + EPS, 180.0, CROSSING, SO, GW, False),
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
    result = classify(beta, beta_prime, True, PARAMS)
    assert result.situation[0] is situation
    assert result.own_role[0] is own_role
    assert result.target_role[0] is target_role
    assert bool(result.own_overtaking[0]) is own_overtaking


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
        overtaking_sector_min_deg=100.0,
        overtaking_sector_max_deg=260.0,
    )
    assert classify(8.0, 8.0, True, wide).situation[0] is HEAD_ON
    assert classify(8.0, 8.0, True, PARAMS).situation[0] is CROSSING
    assert classify(0.0, 105.0, True, wide).situation[0] is OVERTAKING
    assert classify(0.0, 105.0, True, PARAMS).situation[0] is CROSSING
    assert classify(0.0, 255.0, True, wide).situation[0] is OVERTAKING


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
    by_cog = evaluate_colregs(own, crabbing, PARAMS)
    by_heading = evaluate_colregs(own, crabbing, ColregsParams(course_source=CourseSource.HEADING))
    assert by_cog.situation[0] is HEAD_ON
    assert by_heading.beta_prime_deg[0] == pytest.approx(10.0)
    assert by_heading.situation[0] is CROSSING
    assert (by_heading.own_role[0], by_heading.target_role[0]) == (SO, GW)
    no_heading = ship(1000, 0, 180.0, 5.0)
    assert (
        evaluate_colregs(
            own, no_heading, ColregsParams(course_source=CourseSource.HEADING)
        ).situation[0]
        is HEAD_ON
    )


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


def test_role_inversion() -> None:
    assert Role.STAND_ON.inverted() is Role.GIVE_WAY
    assert Role.GIVE_WAY.inverted() is Role.STAND_ON
    assert Role.NONE.inverted() is Role.NONE


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
