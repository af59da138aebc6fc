"""Differential-drive kinematics, odometry integration and command limiting.

Frames and units follow ROS REP 103 / REP 105: body frame ``base_link`` with x forward,
y left, z up; yaw is counter-clockwise about +z. Linear speeds are m/s, angular speeds
rad/s, lengths m, angles rad, time s. Pure functions: no I/O, no state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = (
    "DiffDriveGeometry",
    "Pose2D",
    "integrate_odometry",
    "limit_twist",
    "twist_to_wheels",
    "wheels_to_twist",
)


def _require(values: dict[str, float], *, non_negative: bool = False) -> None:
    """Each value finite (and >= 0), checked in order: a ValueError names the first not."""
    for name, value in values.items():
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite, got {value!r}")
        if non_negative and value < 0.0:
            raise ValueError(f"{name} must be >= 0, got {value!r}")


@dataclass(frozen=True, slots=True)
class DiffDriveGeometry:
    """Geometry of a differential-drive base.

    Attributes:
        wheel_radius: wheel radius, m (> 0).
        wheel_separation: distance between the two wheel contact points along the
            body y axis (track width), m (> 0).
    """

    wheel_radius: float
    wheel_separation: float

    def __post_init__(self) -> None:
        for name in ("wheel_radius", "wheel_separation"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"DiffDriveGeometry.{name} must be finite and > 0, got {value!r}")


@dataclass(frozen=True, slots=True)
class Pose2D:
    """Planar pose of ``base_link`` in the ``odom`` frame.

    Attributes:
        x: position along odom x, m.
        y: position along odom y, m.
        yaw: heading, rad, counter-clockwise from odom x.
    """

    x: float
    y: float
    yaw: float


def twist_to_wheels(v: float, omega: float, geom: DiffDriveGeometry) -> tuple[float, float]:
    """Inverse kinematics: body twist to wheel angular speeds.

    Args:
        v: forward speed along body x, m/s.
        omega: yaw rate about body z, rad/s (CCW positive).
        geom: base geometry.

    Returns:
        ``(left, right)`` wheel angular speeds, rad/s; positive rolls the robot forward.
    """
    half_track = 0.5 * omega * geom.wheel_separation
    return (v - half_track) / geom.wheel_radius, (v + half_track) / geom.wheel_radius


def wheels_to_twist(left: float, right: float, geom: DiffDriveGeometry) -> tuple[float, float]:
    """Forward kinematics: wheel angular speeds to body twist.

    Args:
        left: left wheel angular speed, rad/s (positive rolls forward).
        right: right wheel angular speed, rad/s (positive rolls forward).
        geom: base geometry.

    Returns:
        ``(v, omega)``: forward speed along body x in m/s and yaw rate in rad/s (CCW).
    """
    r = geom.wheel_radius
    return 0.5 * r * (left + right), r * (right - left) / geom.wheel_separation


def _sinc(x: float) -> float:
    """sin(x)/x, continuous at 0."""
    if abs(x) < 1e-4:
        # Taylor series; the next term (x**4/120) is below 1e-18 here.
        return 1.0 - x * x / 6.0
    return math.sin(x) / x


def integrate_odometry(pose: Pose2D, v: float, omega: float, dt: float) -> Pose2D:
    """Advance a pose by a constant body twist held for ``dt``.

    Exact for constant ``(v, omega)``: the robot moves on a circular arc, whose chord
    has length ``v*dt*sinc(omega*dt/2)`` and points along the mid-arc heading
    ``yaw + omega*dt/2``. The chord form has no division by ``omega`` and reduces to a
    straight line as ``omega -> 0``.

    Args:
        pose: start pose in the odom frame.
        v: forward speed along body x, m/s.
        omega: yaw rate, rad/s (CCW).
        dt: duration, s (>= 0).

    Returns:
        The pose after ``dt``, yaw wrapped to [-pi, pi].

    Raises:
        ValueError: if any input is not finite or ``dt`` is negative.
    """
    _require({"pose.x": pose.x, "pose.y": pose.y, "pose.yaw": pose.yaw, "v": v, "omega": omega})
    _require({"dt": dt}, non_negative=True)
    dtheta = omega * dt
    half = 0.5 * dtheta
    chord = v * dt * _sinc(half)
    mid_heading = pose.yaw + half
    return Pose2D(
        x=pose.x + chord * math.cos(mid_heading),
        y=pose.y + chord * math.sin(mid_heading),
        # IEEE remainder is exact and lands in [-pi, pi] (same as otonav.nav.wrap_angle).
        yaw=math.remainder(pose.yaw + dtheta, math.tau),
    )


def _clamp(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)


def limit_twist(
    v: float,
    omega: float,
    *,
    prev_v: float,
    prev_omega: float,
    dt: float,
    max_v: float,
    max_omega: float,
    max_accel: float,
    max_alpha: float,
) -> tuple[float, float]:
    """Clamp a twist command to velocity limits, then to acceleration limits.

    First ``v`` is clamped to ``[-max_v, max_v]`` and ``omega`` to
    ``[-max_omega, max_omega]``; then each is clamped to within ``max_accel*dt``
    (resp. ``max_alpha*dt``) of the previous command. If the previous command was
    within the velocity limits, the result is within both bounds.

    Args:
        v: requested forward speed, m/s.
        omega: requested yaw rate, rad/s.
        prev_v: previously sent forward speed, m/s.
        prev_omega: previously sent yaw rate, rad/s.
        dt: time since the previous command, s (>= 0).
        max_v: speed limit, m/s (>= 0).
        max_omega: yaw-rate limit, rad/s (>= 0).
        max_accel: linear acceleration limit, m/s^2 (>= 0).
        max_alpha: angular acceleration limit, rad/s^2 (>= 0).

    Returns:
        ``(v, omega)`` limited, m/s and rad/s.

    Raises:
        ValueError: if an input is not finite or a limit or ``dt`` is negative.
    """
    _require({"v": v, "omega": omega, "prev_v": prev_v, "prev_omega": prev_omega})
    _require({"dt": dt, "max_v": max_v, "max_omega": max_omega}, non_negative=True)
    _require({"max_accel": max_accel, "max_alpha": max_alpha}, non_negative=True)
    v = _clamp(v, -max_v, max_v)
    omega = _clamp(omega, -max_omega, max_omega)
    dv = max_accel * dt
    dw = max_alpha * dt
    return (
        _clamp(v, prev_v - dv, prev_v + dv),
        _clamp(omega, prev_omega - dw, prev_omega + dw),
    )
