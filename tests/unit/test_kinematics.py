"""Unit tests for otonav.control._kinematics (diff-drive IK/FK, odometry, limits)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from otonav.control import (
    DiffDriveGeometry,
    Pose2D,
    integrate_odometry,
    limit_twist,
    twist_to_wheels,
    wheels_to_twist,
)

pytestmark = pytest.mark.unit

GEOM = DiffDriveGeometry(wheel_radius=0.05, wheel_separation=0.3)


def finite(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(allow_nan=False, allow_infinity=False, min_value=lo, max_value=hi)


# --- kinematics -------------------------------------------------------------------------


def test_fk_ik_round_trip() -> None:
    # left = (0.4 - 0.7*0.15)/0.05 = 5.9, right = (0.4 + 0.7*0.15)/0.05 = 10.1
    left, right = twist_to_wheels(0.4, 0.7, GEOM)
    assert left == pytest.approx(5.9)
    assert right == pytest.approx(10.1)
    v, omega = wheels_to_twist(left, right, GEOM)
    assert v == pytest.approx(0.4)
    assert omega == pytest.approx(0.7)


def test_pure_rotation_wheels_oppose() -> None:
    # CCW turn: the right wheel rolls forward, the left backward, at omega*sep/2/r = 3.
    left, right = twist_to_wheels(0.0, 1.0, GEOM)
    assert left == pytest.approx(-3.0)
    assert right == pytest.approx(3.0)
    assert wheels_to_twist(-3.0, 3.0, GEOM) == pytest.approx((0.0, 1.0))


def test_pure_translation_wheels_equal() -> None:
    left, right = twist_to_wheels(0.5, 0.0, GEOM)
    assert left == pytest.approx(10.0)
    assert right == pytest.approx(10.0)
    assert wheels_to_twist(10.0, 10.0, GEOM) == pytest.approx((0.5, 0.0))


@settings(max_examples=100)
@given(
    v=finite(-5.0, 5.0),
    omega=finite(-10.0, 10.0),
    radius=finite(0.01, 1.0),
    separation=finite(0.05, 2.0),
)
def test_ik_fk_round_trip_property(
    v: float, omega: float, radius: float, separation: float
) -> None:
    geom = DiffDriveGeometry(wheel_radius=radius, wheel_separation=separation)
    left, right = twist_to_wheels(v, omega, geom)
    # Wheel rim speeds differ by exactly omega * separation.
    assert (right - left) * radius == pytest.approx(omega * separation, abs=1e-9)
    v2, omega2 = wheels_to_twist(left, right, geom)
    assert v2 == pytest.approx(v, abs=1e-9)
    assert omega2 == pytest.approx(omega, abs=1e-9)


@pytest.mark.parametrize(
    ("radius", "separation", "field"),
    [
        (0.0, 0.3, "wheel_radius"),
        (-0.05, 0.3, "wheel_radius"),
        (math.nan, 0.3, "wheel_radius"),
        (0.05, 0.0, "wheel_separation"),
        (0.05, math.inf, "wheel_separation"),
    ],
)
def test_geometry_rejects_non_positive(radius: float, separation: float, field: str) -> None:
    with pytest.raises(ValueError, match=field):
        DiffDriveGeometry(wheel_radius=radius, wheel_separation=separation)


# --- odometry ---------------------------------------------------------------------------


def test_quarter_circle_lands_on_arc() -> None:
    # Radius v/omega = 1 m, CCW from the origin facing +x: a quarter turn ends at (1, 1).
    end = integrate_odometry(Pose2D(0.0, 0.0, 0.0), v=1.0, omega=1.0, dt=math.pi / 2)
    assert end.x == pytest.approx(1.0)
    assert end.y == pytest.approx(1.0)
    assert end.yaw == pytest.approx(math.pi / 2)


def test_odometry_yaw_is_wrapped() -> None:
    end = integrate_odometry(Pose2D(0.0, 0.0, 3.0), v=0.0, omega=1.0, dt=1.0)
    assert end.yaw == pytest.approx(4.0 - 2 * math.pi)


def test_odometry_rejects_bad_input() -> None:
    with pytest.raises(ValueError, match="dt"):
        integrate_odometry(Pose2D(0.0, 0.0, 0.0), v=1.0, omega=0.0, dt=-0.1)
    with pytest.raises(ValueError, match=r"pose\.yaw"):
        integrate_odometry(Pose2D(0.0, 0.0, math.nan), v=1.0, omega=0.0, dt=0.1)


@settings(max_examples=100)
@given(
    x=finite(-100.0, 100.0),
    y=finite(-100.0, 100.0),
    yaw=finite(-math.pi, math.pi),
    v=finite(-5.0, 5.0),
    dt=finite(0.0, 10.0),
)
def test_straight_line_moves_v_dt_along_heading(
    x: float, y: float, yaw: float, v: float, dt: float
) -> None:
    end = integrate_odometry(Pose2D(x, y, yaw), v=v, omega=0.0, dt=dt)
    assert end.x == pytest.approx(x + v * dt * math.cos(yaw), abs=1e-9)
    assert end.y == pytest.approx(y + v * dt * math.sin(yaw), abs=1e-9)
    assert math.hypot(end.x - x, end.y - y) == pytest.approx(abs(v) * dt, abs=1e-9)
    assert end.yaw == pytest.approx(yaw, abs=1e-12)


@settings(max_examples=100)
@given(
    x=finite(-10.0, 10.0),
    y=finite(-10.0, 10.0),
    yaw=finite(-math.pi, math.pi),
    v=finite(-2.0, 2.0),
    omega=st.one_of(finite(-3.0, -0.1), finite(0.1, 3.0)),
    steps=st.integers(min_value=1, max_value=50),
)
def test_full_circle_returns_to_start(
    x: float, y: float, yaw: float, v: float, omega: float, steps: int
) -> None:
    dt = 2 * math.pi / abs(omega) / steps
    pose = Pose2D(x, y, yaw)
    for _ in range(steps):
        pose = integrate_odometry(pose, v=v, omega=omega, dt=dt)
        assert -math.pi <= pose.yaw <= math.pi
    assert pose.x == pytest.approx(x, abs=1e-9)
    assert pose.y == pytest.approx(y, abs=1e-9)
    # Compare headings on the circle so that +pi and -pi count as equal.
    assert math.cos(pose.yaw) == pytest.approx(math.cos(yaw), abs=1e-9)
    assert math.sin(pose.yaw) == pytest.approx(math.sin(yaw), abs=1e-9)


# --- command limits ---------------------------------------------------------------------

LIMITS = {"max_v": 0.5, "max_omega": 1.5, "max_accel": 1.0, "max_alpha": 2.0}


def test_limit_twist_clamps_velocity() -> None:
    # Previous command already at the limit, so acceleration does not bind.
    assert limit_twist(2.0, -9.0, prev_v=0.5, prev_omega=-1.5, dt=0.1, **LIMITS) == (0.5, -1.5)


def test_limit_twist_clamps_acceleration() -> None:
    # From rest, 0.1 s allows 0.1 m/s and 0.2 rad/s of change.
    v, omega = limit_twist(0.5, -1.5, prev_v=0.0, prev_omega=0.0, dt=0.1, **LIMITS)
    assert v == pytest.approx(0.1)
    assert omega == pytest.approx(-0.2)


def test_limit_twist_passes_reachable_command() -> None:
    assert limit_twist(0.25, 0.5, prev_v=0.2, prev_omega=0.4, dt=0.1, **LIMITS) == (0.25, 0.5)


def test_limit_twist_rejects_negative_limit() -> None:
    with pytest.raises(ValueError, match="max_accel"):
        limit_twist(
            0.0, 0.0, prev_v=0.0, prev_omega=0.0, dt=0.1,
            max_v=1.0, max_omega=1.0, max_accel=-1.0, max_alpha=1.0,
        )  # fmt: skip


@settings(max_examples=100)
@given(
    data=st.data(),
    v=finite(-10.0, 10.0),
    omega=finite(-10.0, 10.0),
    dt=finite(0.0, 1.0),
    max_v=finite(0.0, 3.0),
    max_omega=finite(0.0, 5.0),
    max_accel=finite(0.0, 5.0),
    max_alpha=finite(0.0, 10.0),
)
def test_limit_twist_respects_both_bounds(
    data: st.DataObject,
    v: float,
    omega: float,
    dt: float,
    max_v: float,
    max_omega: float,
    max_accel: float,
    max_alpha: float,
) -> None:
    prev_v = data.draw(finite(-max_v, max_v), label="prev_v")
    prev_omega = data.draw(finite(-max_omega, max_omega), label="prev_omega")
    out_v, out_omega = limit_twist(
        v, omega, prev_v=prev_v, prev_omega=prev_omega, dt=dt,
        max_v=max_v, max_omega=max_omega, max_accel=max_accel, max_alpha=max_alpha,
    )  # fmt: skip
    eps = 1e-12
    assert abs(out_v) <= max_v + eps
    assert abs(out_omega) <= max_omega + eps
    assert abs(out_v - prev_v) <= max_accel * dt + eps
    assert abs(out_omega - prev_omega) <= max_alpha * dt + eps
    # Never overshoots the request: the output lies between prev and the clamped request.
    target_v = min(max(v, -max_v), max_v)
    assert min(prev_v, target_v) - eps <= out_v <= max(prev_v, target_v) + eps
