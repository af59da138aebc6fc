"""The bridge's odometry estimate as a pure step (``otonav.control.estimate_odometry``)."""

from __future__ import annotations

import math

import pytest

from otonav.control import OdometryEstimate, Pose2D, estimate_odometry

pytestmark = pytest.mark.unit

START = OdometryEstimate(Pose2D(0.0, 0.0, 0.0), 0.0, 10.0, -4.0, 1.0)


def test_straight_travel_is_the_wheels_mean_arc_length() -> None:
    # Both wheels turn 2 rad in 0.5 s on r = 0.05 m wheels: 0.1 m at 0.2 m/s.
    after = estimate_odometry(START, 12.0, -2.0, 0.0, 1.5, 0.05)
    assert after.v == pytest.approx(0.2)
    assert after.pose.x == pytest.approx(0.1)
    assert after.pose.y == pytest.approx(0.0)
    assert (after.left, after.right, after.time) == (12.0, -2.0, 1.5)


def test_heading_comes_from_the_gyro_not_the_wheels() -> None:
    # Wheels spinning in place (mean travel 0) while the gyro says a quarter turn.
    spin = estimate_odometry(START, 11.0, -5.0, math.pi / 2, 2.0, 0.05)
    assert spin.v == 0.0
    assert spin.pose.yaw == pytest.approx(math.pi / 2)
    assert (spin.pose.x, spin.pose.y) == (0.0, 0.0)


def test_an_arc_ends_where_the_circle_does() -> None:
    # v = 1 m/s and 1 rad/s for pi/2 s: a quarter circle of radius 1, to (1, 1, pi/2).
    dt = math.pi / 2
    travel = 1.0 * dt / 0.5  # rad per wheel on r = 0.5 m
    arc = estimate_odometry(START, 10.0 + travel, -4.0 + travel, 1.0, 1.0 + dt, 0.5)
    assert arc.v == pytest.approx(1.0)
    assert (arc.pose.x, arc.pose.y, arc.pose.yaw) == pytest.approx((1.0, 1.0, math.pi / 2))


@pytest.mark.parametrize("now", [1.0, 0.5])
def test_no_interval_keeps_the_last_estimate(now: float) -> None:
    moving = estimate_odometry(START, 12.0, -2.0, 0.3, 1.5, 0.05)
    again = estimate_odometry(moving, 99.0, 99.0, 5.0, now + 0.5, 0.05)
    assert again is moving  # same instant or earlier: same pose, same speed


def test_steps_compose_from_the_readings_they_were_given() -> None:
    one = estimate_odometry(START, 11.0, -3.0, 0.0, 1.25, 0.05)
    two = estimate_odometry(one, 12.0, -2.0, 0.0, 1.5, 0.05)
    assert two.pose.x == pytest.approx(0.1)  # the same 2 rad as in one step
    assert two.v == pytest.approx(0.2)


def test_an_error_model_sees_the_interval_and_its_answer_is_integrated() -> None:
    # world.odometry_error: the model gets the interval's distance and yaw rate and
    # what it returns is what the pose integrates (and what /odom's twist reports).
    seen: list[tuple[float, float]] = []

    def model(distance: float, yaw_rate: float) -> tuple[float, float]:
        seen.append((distance, yaw_rate))
        return distance * 1.5, yaw_rate + 0.2

    after = estimate_odometry(START, 12.0, -2.0, 0.0, 1.5, 0.05, error=model)
    assert seen == [pytest.approx((0.1, 0.0))]
    assert after.v == pytest.approx(0.3)
    assert after.yaw_rate == pytest.approx(0.2)
    assert after.pose.yaw == pytest.approx(0.1)
    # no interval (the same instant again): no new sample of the error model
    assert estimate_odometry(after, 12.0, -2.0, 0.0, 1.5, 0.05, error=model) is after
    assert len(seen) == 1
