"""The safety limit: can the robot still stop before its centre comes too close?

A pure function in the spirit of Nav2's collision monitor, trusting nothing the planner
says. Frames and units: the returns are points in the *current* base_link (m; the
caller moves the last scan into it with odometry); commands are body twists (m/s,
rad/s).

Model of what a command does (the base controller's behaviour, conservatively): for
``latency`` s (the safety period + the base period + the drive's lag) the velocity
ramps from the current one toward the command at the base's limits ``max_accel`` /
``max_alpha``; then both ramp to zero at the same limits. The centre (base_link, the
judged point, on the wheel axle) follows that unicycle path, integrated every ``dt``
s: forward, reverse, and the arc of a turning robot alike. A turn on the spot does not
move the centre.

A command is *safe* when along that path the centre never comes closer than ``radius``
to a return, except that a return already closer may not get closer than it is (so a
robot inside the radius can still back away). The output is the command with its
forward speed scaled down by the largest of ``1, 0.8, ..., 0`` that is safe (the
turn rate kept); if even the stop with the turn is unsafe, it is (0, 0): braking is
the best there is. Returns farther than the longest stopping path plus ``radius``
cannot matter and are skipped (the common case costs one distance per return).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from otonav.params import SafetyParams

__all__ = ("MAX_STEPS", "SafetyParams", "SafetyResult", "safe_command", "stopping_reach")


@dataclass(frozen=True, slots=True)
class SafetyResult:
    """Output of :func:`safe_command`.

    Attributes:
        v: limited forward speed, m/s.
        omega: limited yaw rate, rad/s.
        scale: the forward-speed scale applied (1: untouched).
        nearest: distance from the centre to the nearest return, m (inf if none).
        reason: ``clear`` (nothing in reach), ``safe`` (checked, untouched),
            ``limited`` (slowed) or ``stopped``.
    """

    v: float
    omega: float
    scale: float
    nearest: float
    reason: str


MAX_STEPS = 500
"""The most steps of ``dt`` a stopping path is integrated over (10 s at the default
``dt``); a longer one (a base with a tiny ``max_accel``) is bounded past it instead:
the grid, and the cost of a call, grew as v^2 / max_accel without it."""


def stopping_reach(speed: float, params: SafetyParams) -> float:
    """How far the centre may travel before the robot stops from ``speed`` (m/s, >= 0),
    m: ``latency`` s at that speed, braking at ``max_accel``, plus ``2 dt`` s of it
    (the stopping path is integrated every ``dt`` s, mid-step; the slack covers the
    sum's error) and 1 um (a return exactly at the edge is checked, not skipped).

    A return farther than ``radius`` + this from the centre cannot make
    :func:`safe_command` change a command at that speed or below (it returns
    ``clear``): the safety layer and the bare benchmark skip the check on that bound
    (one formula for all three, issue 31)."""
    p = params
    return speed * p.latency + speed * speed / (2.0 * p.max_accel) + 2.0 * p.dt * speed + 1e-6


def _profile(
    start: float, target: NDArray[np.float64], t: NDArray[np.float64], latency: float, limit: float
) -> NDArray[np.float64]:
    """Velocity at times ``t`` (mid-step) for each target: ramp from ``start`` toward
    the target at ``limit`` until ``latency``, then ramp to zero at ``limit``."""
    tm = t - 0.5 * (t[1] - t[0] if t.size > 1 else 0.0)
    ramp = np.minimum(tm, latency)[None, :]
    before = start + np.clip(target[:, None] - start, -limit * ramp, limit * ramp)
    after = np.maximum(tm - latency, 0.0)[None, :]
    return np.sign(before) * np.maximum(np.abs(before) - limit * after, 0.0)


def safe_command(
    v_cmd: float,
    omega_cmd: float,
    v0: float,
    omega0: float,
    points: NDArray[np.float64],
    params: SafetyParams,
) -> SafetyResult:
    """The command (``v_cmd`` m/s, ``omega_cmd`` rad/s) limited so the robot, now at
    ``v0``, ``omega0``, can always stop in time before ``points``, the ``(N, 2)`` returns
    in the current base_link, m (module docstring)."""
    p = params
    d0 = np.hypot(points[:, 0], points[:, 1]) if points.shape[0] else np.empty(0)
    nearest = float(d0.min()) if d0.size else math.inf
    fastest = max(abs(v_cmd), abs(v0))
    near = d0 < p.radius + stopping_reach(fastest, p)
    if not near.any():
        return SafetyResult(v_cmd, omega_cmd, 1.0, nearest, "clear")
    pts, dn = points[near], d0[near]
    allowed = np.minimum(p.radius, dn - 1e-4)  # inside the radius: no closer than now
    scales = np.linspace(1.0, 0.0, p.scales)
    v_t = scales * v_cmd
    w_t = np.full(p.scales, omega_cmd)
    # The fastest each profile gets (the ramp moves at most limit * latency from the
    # current speed, never past the target), then the time to brake from it.
    top_v = np.maximum(abs(v0), np.minimum(np.abs(v_t), abs(v0) + p.max_accel * p.latency))
    top_w = max(abs(omega0), min(abs(omega_cmd), abs(omega0) + p.max_alpha * p.latency))
    duration = p.latency + max(float(top_v.max()) / p.max_accel, top_w / p.max_alpha)
    steps = math.ceil(duration / p.dt) + 1
    t = p.dt * np.arange(1, min(steps, MAX_STEPS) + 1, dtype=np.float64)  # (K,)
    v = _profile(v0, v_t, t, p.latency, p.max_accel)  # (n, K)
    w = _profile(omega0, w_t, t, p.latency, p.max_alpha)
    th = np.cumsum(w, axis=1) * p.dt
    x = np.cumsum(v * np.cos(th - 0.5 * w * p.dt), axis=1) * p.dt
    y = np.cumsum(v * np.sin(th - 0.5 * w * p.dt), axis=1) * p.dt
    gap = np.hypot(pts[None, None, :, 0] - x[:, :, None], pts[None, None, :, 1] - y[:, :, None])
    worst = (gap - allowed).min(axis=(1, 2))
    if steps > MAX_STEPS:
        # The rest of a path too long to integrate (a tiny max_accel): it stays within
        # the distance it can still travel of where the grid ends, the speed then (or
        # the top speed, still ramping) for the time left. Conservative, never optimistic.
        end = float(t[-1])
        speed = np.abs(v[:, -1]) if end >= p.latency else top_v
        tail = speed * (duration - end + p.dt)
        worst = np.minimum(worst, (gap[:, -1, :] - allowed).min(axis=1) - tail)
    ok = worst >= 0.0
    for i in range(p.scales):
        if ok[i]:
            if i == 0:
                return SafetyResult(v_cmd, omega_cmd, 1.0, nearest, "safe")
            why = "limited" if scales[i] > 0.0 else "stopped"
            return SafetyResult(float(v_t[i]), omega_cmd, float(scales[i]), nearest, why)
    return SafetyResult(0.0, 0.0, 0.0, nearest, "stopped")
