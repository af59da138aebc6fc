"""Wheel-and-gyro odometry: the estimate the bridge publishes on /odom, as a pure step.

Forward speed comes from the wheel encoders (the mean of both wheels' travel since the
last estimate over the time between them); the yaw rate from the IMU's gyro, which does
not slip as wheels do on a turn; the pose is the exact arc for that twist held over the
interval (:func:`~otonav.control._kinematics.integrate_odometry`). No I/O, no clock: the
caller passes the readings and their sim time.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

from otonav.control._kinematics import Pose2D, integrate_odometry

__all__ = ("OdometryEstimate", "estimate_odometry")


class OdometryEstimate(NamedTuple):
    """The odometry after one step, and what the next step measures from."""

    pose: Pose2D
    """``base_link`` in ``odom``."""
    v: float
    """m/s, forward speed over the last interval."""
    left: float
    """rad, the left wheel's position at ``time``."""
    right: float
    """rad, the right wheel's position at ``time``."""
    time: float
    """s, sim time of the readings this estimate used."""
    yaw_rate: float = 0.0
    """rad/s, the yaw rate the last interval was integrated with."""


OdometryErrorModel = Callable[[float, float], tuple[float, float]]
"""``(distance m, yaw rate rad/s) -> (distance, yaw rate)`` as a mis-calibrated
odometry sees them (simulation only: ``world.odometry_error``)."""


def estimate_odometry(
    last: OdometryEstimate,
    left: float,
    right: float,
    yaw_rate: float,
    now: float,
    wheel_radius: float,
    error: OdometryErrorModel | None = None,
) -> OdometryEstimate:
    """One odometry step from wheel positions ``left``/``right`` (rad) and the gyro's
    ``yaw_rate`` (rad/s) read at sim time ``now`` (s), for wheels of ``wheel_radius`` m.

    When ``now`` is not after ``last.time`` (the same instant read again, or a real-time
    world that ran past two instants at once) there is no interval to measure: ``last``
    is returned unchanged, its speed the same estimate. ``error``, when given, turns the
    interval's distance and yaw rate into what a mis-calibrated odometry reports.
    """
    dt = now - last.time
    if not dt > 0:
        return last
    distance = wheel_radius * ((left - last.left) + (right - last.right)) / 2
    if error is not None:
        distance, yaw_rate = error(distance, yaw_rate)
    v = distance / dt
    pose = integrate_odometry(last.pose, v, yaw_rate, dt)
    return OdometryEstimate(pose, v, left, right, now, yaw_rate)
