"""The safety limit's documented stopping model, written as a plain loop (no numpy
integration, no horizon): the reference the safety unit tests compare
``otonav.nav._safety`` against."""

from __future__ import annotations

import math

import numpy as np

from otonav.nav._safety import SafetyParams


def speed_profile(start: float, target: float, tm: float, latency: float, limit: float) -> float:
    """The documented profile at mid-step time ``tm``: toward the target at the limit
    until the latency, then down to zero at the limit."""
    ramp = min(tm, latency)
    before = start + min(max(target - start, -limit * ramp), limit * ramp)
    if tm <= latency:
        return before
    return math.copysign(max(abs(before) - limit * (tm - latency), 0.0), before)


def stopping_path(v0: float, w0: float, v_t: float, w_t: float, p: SafetyParams) -> np.ndarray:
    """(K, 2) centre positions along the stopping path, every dt until stopped."""
    x = y = th = 0.0
    out = []
    k = 0
    while True:
        k += 1
        tm = k * p.dt - 0.5 * p.dt
        v = speed_profile(v0, v_t, tm, p.latency, p.max_accel)
        w = speed_profile(w0, w_t, tm, p.latency, p.max_alpha)
        th += w * p.dt
        x += v * math.cos(th - 0.5 * w * p.dt) * p.dt
        y += v * math.sin(th - 0.5 * w * p.dt) * p.dt
        out.append((x, y))
        if tm > p.latency and v == 0.0 and w == 0.0:
            return np.array(out)


def worst_gap(path: np.ndarray, pts: np.ndarray, p: SafetyParams) -> float:
    """Smallest (distance - allowed) between the path and the returns ``pts``."""
    d0 = np.hypot(pts[:, 0], pts[:, 1])
    allowed = np.minimum(p.radius, d0 - 1e-4)
    gap = np.hypot(pts[None, :, 0] - path[:, None, 0], pts[None, :, 1] - path[:, None, 1])
    return float((gap - allowed[None, :]).min())
