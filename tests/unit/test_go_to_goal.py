"""Unit tests for otonav.nav.go_to_goal and otonav.nav._geometry."""

from __future__ import annotations

import math
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from otonav.control import Pose2D
from otonav.nav import GoToGoalParams, go_to_goal, wrap_angle

pytestmark = pytest.mark.unit

PARAMS = GoToGoalParams()  # kp_lin 0.8, kp_ang 2.0, max_v 0.5, max_omega 1.5, tol 0.1, 0.6 rad
ORIGIN = Pose2D(0.0, 0.0, 0.0)


def finite(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(allow_nan=False, allow_infinity=False, min_value=lo, max_value=hi)


def test_forward_when_facing_goal() -> None:
    cmd = go_to_goal(ORIGIN, 0.3, 0.0, PARAMS)
    assert not cmd.reached
    assert cmd.distance == pytest.approx(0.3)
    assert cmd.heading_error == pytest.approx(0.0)
    assert cmd.v == pytest.approx(0.8 * 0.3)
    assert cmd.omega == pytest.approx(0.0)


def test_turn_left_for_goal_on_left() -> None:
    # Goal 90 deg to the left: beyond the turn-in-place threshold, so rotate CCW only.
    cmd = go_to_goal(ORIGIN, 0.0, 2.0, PARAMS)
    assert cmd.heading_error == pytest.approx(math.pi / 2)
    assert cmd.v == 0.0
    assert cmd.omega == pytest.approx(1.5)
    # Slightly to the left (atan(0.1) rad): drive and turn CCW proportionally.
    cmd = go_to_goal(ORIGIN, 2.0, 0.2, PARAMS)
    err = math.atan(0.1)
    assert cmd.heading_error == pytest.approx(err)
    assert cmd.omega == pytest.approx(2.0 * err)
    assert cmd.v == pytest.approx(0.5 * math.cos(err))


def test_turn_right_for_goal_on_right_when_rotated() -> None:
    # Facing +y at (1, 1); the goal at (1.4, 2) is ahead and to the right (negative error).
    cmd = go_to_goal(Pose2D(1.0, 1.0, math.pi / 2), 1.4, 2.0, PARAMS)
    err = math.atan2(1.0, 0.4) - math.pi / 2
    assert err < 0
    assert cmd.heading_error == pytest.approx(err)
    assert cmd.omega == pytest.approx(2.0 * err)
    assert cmd.v == pytest.approx(min(0.8 * math.hypot(0.4, 1.0), 0.5) * math.cos(err))


def test_reached_within_tolerance() -> None:
    cmd = go_to_goal(Pose2D(1.0, 1.0, 2.0), 1.05, 0.95, PARAMS)
    assert cmd.reached
    assert cmd.distance == pytest.approx(math.hypot(0.05, 0.05))
    assert cmd.v == 0.0
    assert cmd.omega == 0.0
    assert not go_to_goal(Pose2D(1.0, 1.0, 2.0), 1.2, 1.0, PARAMS).reached


def test_no_forward_motion_when_facing_away() -> None:
    cmd = go_to_goal(ORIGIN, -2.0, 0.0, PARAMS)
    assert abs(cmd.heading_error) == pytest.approx(math.pi)
    assert cmd.v == 0.0
    assert abs(cmd.omega) == pytest.approx(1.5)
    # Even with turn-in-place disabled, a goal behind never makes the robot reverse.
    no_tip = GoToGoalParams(turn_in_place_threshold=math.pi)
    cmd = go_to_goal(ORIGIN, -2.0, 0.5, no_tip)
    assert cmd.v == 0.0


def test_clamps_to_limits() -> None:
    far = go_to_goal(ORIGIN, 100.0, 0.0, PARAMS)
    assert far.v == pytest.approx(0.5)
    strong = GoToGoalParams(kp_ang=50.0)
    right = go_to_goal(ORIGIN, 100.0, -20.0, strong)
    assert right.omega == pytest.approx(-1.5)
    left = go_to_goal(ORIGIN, 100.0, 20.0, strong)
    assert left.omega == pytest.approx(1.5)


def test_zero_linear_gain_never_moves_forward() -> None:
    cmd = go_to_goal(ORIGIN, 3.0, 0.0, GoToGoalParams(kp_lin=0.0))
    assert cmd.v == 0.0
    assert not cmd.reached


@pytest.mark.parametrize(
    ("pose", "goal", "field"),
    [
        (Pose2D(math.nan, 0.0, 0.0), (1.0, 1.0), "pose.x"),
        (Pose2D(0.0, math.nan, 0.0), (1.0, 1.0), "pose.y"),
        (Pose2D(0.0, 0.0, math.nan), (1.0, 1.0), "pose.yaw"),
        (ORIGIN, (math.nan, 1.0), "goal_x"),
        (ORIGIN, (1.0, math.nan), "goal_y"),
    ],
)
def test_nan_input_names_field(pose: Pose2D, goal: tuple[float, float], field: str) -> None:
    with pytest.raises(ValueError, match=re.escape(field)):
        go_to_goal(pose, goal[0], goal[1], PARAMS)


def test_params_reject_negative() -> None:
    with pytest.raises(ValueError, match="max_v"):
        GoToGoalParams(max_v=-1.0)
    with pytest.raises(ValueError, match="tolerance"):
        GoToGoalParams(tolerance=math.nan)


@settings(max_examples=100)
@given(
    x=finite(-50.0, 50.0),
    y=finite(-50.0, 50.0),
    yaw=finite(-20.0, 20.0),
    gx=finite(-50.0, 50.0),
    gy=finite(-50.0, 50.0),
    kp_lin=finite(0.0, 10.0),
    kp_ang=finite(0.0, 10.0),
    max_v=finite(0.0, 3.0),
    max_omega=finite(0.0, 5.0),
    threshold=finite(0.0, math.pi),
)
def test_output_within_limits(
    x: float,
    y: float,
    yaw: float,
    gx: float,
    gy: float,
    kp_lin: float,
    kp_ang: float,
    max_v: float,
    max_omega: float,
    threshold: float,
) -> None:
    params = GoToGoalParams(
        kp_lin=kp_lin,
        kp_ang=kp_ang,
        max_v=max_v,
        max_omega=max_omega,
        turn_in_place_threshold=threshold,
    )
    cmd = go_to_goal(Pose2D(x, y, yaw), gx, gy, params)
    assert 0.0 <= cmd.v <= max_v
    assert abs(cmd.omega) <= max_omega
    assert -math.pi <= cmd.heading_error <= math.pi
    assert cmd.distance == pytest.approx(math.hypot(gx - x, gy - y))
    assert cmd.reached == (cmd.distance <= params.tolerance)
    if abs(cmd.heading_error) > threshold:
        assert cmd.v == 0.0


# --- wrap_angle -------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("angle", "expected"),
    [
        (0.0, 0.0),
        (1.0, 1.0),
        (-1.0, -1.0),
        (3 * math.pi / 2, -math.pi / 2),
        (-3 * math.pi / 2, math.pi / 2),
        (7.0, 7.0 - 2 * math.pi),
        (-7.0, -7.0 + 2 * math.pi),
        (10 * math.pi + 0.25, 0.25),
    ],
)
def test_wrap_angle_in_range(angle: float, expected: float) -> None:
    wrapped = wrap_angle(angle)
    assert -math.pi <= wrapped <= math.pi
    assert wrapped == pytest.approx(expected, abs=1e-12)


def test_wrap_angle_keeps_pi_boundary() -> None:
    assert abs(wrap_angle(math.pi)) == pytest.approx(math.pi)
    assert abs(wrap_angle(-math.pi)) == pytest.approx(math.pi)
    assert math.isnan(wrap_angle(math.nan))


@settings(max_examples=100)
@given(angle=finite(-1e6, 1e6))
def test_wrap_angle_properties(angle: float) -> None:
    wrapped = wrap_angle(angle)
    assert -math.pi <= wrapped <= math.pi
    assert wrap_angle(wrapped) == wrapped
    turns = (angle - wrapped) / (2 * math.pi)
    assert turns == pytest.approx(round(turns), abs=1e-6)
    assert math.cos(wrapped) == pytest.approx(math.cos(angle), abs=1e-6)
    assert math.sin(wrapped) == pytest.approx(math.sin(angle), abs=1e-6)
