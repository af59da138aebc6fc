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


def _require(finite: dict[str, float], non_negative: dict[str, float] | None = None) -> None:
    """Raise ValueError naming the first value not finite (or negative, of ``non_negative``)."""
    for name, value in {**finite, **(non_negative or {})}.items():
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite, got {value!r}")
    for name, value in (non_negative or {}).items():
        if value < 0.0:
            raise ValueError(f"{name} must be >= 0, got {value!r}")


@dataclass(frozen=True, slots=True)
class DiffDriveGeometry:
    """Geometry of a differential-drive base: ``wheel_radius`` and ``wheel_separation``
    (the track width: between the two wheel contact points along body y), m, > 0."""

    wheel_radius: float
    wheel_separation: float

    def __post_init__(self) -> None:
        for name in ("wheel_radius", "wheel_separation"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ValueError(f"DiffDriveGeometry.{name} must be finite and > 0, got {value!r}")


@dataclass(frozen=True, slots=True)
class Pose2D:
    """Planar pose of ``base_link`` in the ``odom`` frame: ``x``, ``y`` in m, ``yaw`` in
    rad counter-clockwise from odom x."""

    x: float
    y: float
    yaw: float


def twist_to_wheels(v: float, omega: float, geom: DiffDriveGeometry) -> tuple[float, float]:
    """Inverse kinematics: the body twist (``v`` m/s along body x, ``omega`` rad/s CCW)
    as ``(left, right)`` wheel angular speeds, rad/s; positive rolls the robot forward."""
    half_track = 0.5 * omega * geom.wheel_separation
    return (v - half_track) / geom.wheel_radius, (v + half_track) / geom.wheel_radius


def wheels_to_twist(left: float, right: float, geom: DiffDriveGeometry) -> tuple[float, float]:
    """Forward kinematics: wheel angular speeds (rad/s, positive rolls forward) as the
    body twist ``(v, omega)``: m/s along body x, rad/s CCW."""
    r = geom.wheel_radius
    return 0.5 * r * (left + right), r * (right - left) / geom.wheel_separation


def _sinc(x: float) -> float:
    """sin(x)/x, continuous at 0."""
    if abs(x) < 1e-4:
        # Taylor series; the next term (x**4/120) is below 1e-18 here.
        return 1.0 - x * x / 6.0
    return math.sin(x) / x


def integrate_odometry(pose: Pose2D, v: float, omega: float, dt: float) -> Pose2D:
    """``pose`` (odom frame) after the body twist ``(v, omega)`` (m/s, rad/s CCW) held
    for ``dt`` s (>= 0), its yaw wrapped to [-pi, pi]; ValueError if an input is not
    finite or ``dt`` is negative.

    Exact for constant ``(v, omega)``: the robot moves on a circular arc, whose chord
    has length ``v*dt*sinc(omega*dt/2)`` and points along the mid-arc heading
    ``yaw + omega*dt/2``. The chord form has no division by ``omega`` and reduces to a
    straight line as ``omega -> 0``."""
    _require(
        {"pose.x": pose.x, "pose.y": pose.y, "pose.yaw": pose.yaw, "v": v, "omega": omega},
        {"dt": dt},
    )
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
    """The twist ``(v, omega)`` (m/s, rad/s) clamped to the velocity limits ``max_v``,
    ``max_omega``, then to within ``max_accel*dt`` (resp. ``max_alpha*dt``) of the
    previous command ``(prev_v, prev_omega)`` sent ``dt`` s ago. If the previous command
    was within the velocity limits, the result is within both bounds. ValueError if an
    input is not finite or a limit or ``dt`` is negative."""
    _require(
        {"v": v, "omega": omega, "prev_v": prev_v, "prev_omega": prev_omega},
        {
            "dt": dt,
            "max_v": max_v,
            "max_omega": max_omega,
            "max_accel": max_accel,
            "max_alpha": max_alpha,
        },
    )
    v = _clamp(v, -max_v, max_v)
    omega = _clamp(omega, -max_omega, max_omega)
    dv = max_accel * dt
    dw = max_alpha * dt
    return (
        _clamp(v, prev_v - dv, prev_v + dv),
        _clamp(omega, prev_omega - dw, prev_omega + dw),
    )
