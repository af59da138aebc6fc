"""The DWA's documented sampling (otonav.nav._dwa's module docstring), written as a plain
per-sample loop: the reference the DWA unit tests compare ``dwa_step`` against."""

from __future__ import annotations

import math

import numpy as np

from otonav.nav._dwa import ClearanceFn, DwaParams, DwaResult

Pose = tuple[float, float, float]


def window(lo: float, hi: float, n: int) -> list[float]:
    """n samples across [lo, hi]; one sample, or an empty span: its middle."""
    if n > 1 and hi > lo:
        return [float(v) for v in np.linspace(lo, hi, n)]
    return [0.5 * (lo + hi)]


def dwa_reference(
    pose: Pose,
    v0: float,
    w0: float,
    target: tuple[float, float],
    goal: float,
    field: ClearanceFn,
    p: DwaParams,
) -> DwaResult:
    """``dwa_step(pose, v0, w0, target, goal, field, p)`` as its docstring says it, one
    sample at a time: every field of the result."""
    x0, y0, th0 = pose
    cap = min(p.max_v, math.sqrt(p.max_accel * max(goal, 0.0)))
    v_lo = min(max(v0 - p.max_accel * p.period, 0.0), cap)
    v_hi = min(max(v0 + p.max_accel * p.period, 0.0), cap)
    w_lo = max(w0 - p.max_alpha * p.period, -p.max_omega)
    w_hi = min(w0 + p.max_alpha * p.period, p.max_omega)
    if w_lo > w_hi:  # beyond the limit: the nearest limit
        w_lo = w_hi = min(max(w0, -p.max_omega), p.max_omega)
    off = abs(math.remainder(math.atan2(target[1] - y0, target[0] - x0) - th0, math.tau))
    vs = window(v_lo, v_lo if off > p.rotate_threshold else v_hi, p.v_samples)
    ws = window(w_lo, w_hi, p.omega_samples)
    brake = (v_lo, min(max(0.0, w_lo), w_hi))
    samples = [(v, w) for v in vs for w in ws] + [brake]
    steps = max(1, round(p.horizon / p.dt))
    t = p.dt * np.arange(steps + 1, dtype=np.float64)
    here = float(field(np.array([x0]), np.array([y0]))[0])
    best: tuple[float, float, float, float] | None = None
    count = 0
    for v, w in samples:
        we = w if abs(w) >= 1e-6 else math.copysign(1e-6, w)
        th = th0 + we * t
        xs = x0 + v / we * (np.sin(th) - math.sin(th0))
        ys = y0 - v / we * (np.cos(th) - math.cos(th0))
        clear = field(xs, ys)
        under = [k for k in range(1, steps + 1) if clear[k] < min(p.radius, here - 1e-3)]
        last = under[0] - 1 if under else steps  # the last free pose
        free = v * t[last] if under else math.inf
        if v * p.latency + v * v / (2.0 * p.max_accel) > free:
            continue
        count += 1
        d = np.hypot(target[0] - xs[: last + 1], target[1] - ys[: last + 1])
        i = int(np.argmin(d - 1e-9 * np.arange(last + 1)))  # ties: the latest
        h = i if i > 0 else last
        bearing = abs(
            math.remainder(math.atan2(target[1] - ys[h], target[0] - xs[h]) - th[h], math.tau)
        )
        if d[i] < 0.05:
            bearing = 0.0
        top = max(v_hi, 1e-3)  # the window's top speed, not max_v (issue 42)
        gain = (math.hypot(target[0] - x0, target[1] - y0) - d[i]) / (top * p.horizon)
        least = float(clear.min())
        room = min(max(least - p.radius, 0.0), p.clearance_cap) / p.clearance_cap
        score = (
            p.w_heading * (1 - bearing / math.pi)
            + p.w_progress * gain
            + p.w_clearance * room
            + p.w_speed * v / top
        )
        if best is None or score > best[2]:
            best = (v, w, score, least)
    n = len(samples)
    if best is None:
        reason = "no admissible trajectory: braking"
        return DwaResult(brake[0], brake[1], 0, n, -math.inf, here, reason)
    room = min(max(best[3] - p.radius, 0.0), p.clearance_cap) / p.clearance_cap
    reason = "toward target" if room >= 1.0 else "avoiding"
    return DwaResult(best[0], best[1], count, n, best[2], best[3], reason)
