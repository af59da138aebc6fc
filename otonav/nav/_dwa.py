"""Dynamic Window Approach (Fox, Burgard, Thrun 1997), vectorised with numpy.

Frames and units: poses in odom (x, y m; yaw rad CCW, REP 103); commands are body
twists (v m/s forward, omega rad/s CCW).

One step:

1. **Window.** The (v, omega) reachable within one control period ``period`` under the
   acceleration limits, intersected with ``[0, max_v] x [-max_omega, max_omega]``; the
   top of the v range is also capped at ``sqrt(max_accel * goal_distance)`` (braking at
   half the limit stops at the goal) so the
   robot arrives instead of overshooting. ``v_samples x omega_samples`` samples,
   plus the braking command (the window's lowest v, omega toward 0). With the target
   more than ``rotate_threshold`` off the heading only the lowest v is sampled: the
   robot slows and turns toward it first.
2. **Rollouts.** Each sample held for ``horizon`` s, poses every ``dt`` s (exact arcs).
3. **Admissible.** With ``clearance(x, y)`` the distance from a point to the nearest
   return (the costmap's lower bound), the *free length* of a rollout is the arc
   length driven before the first pose whose clearance is under ``radius`` (or under
   the clearance at the start, when the robot already is closer than ``radius``: it
   may then only move away). A sample is admissible when it can stop within its free
   length: ``v * latency + v**2 / (2 * max_accel) <= free length``.
4. **Score** (higher is better), each term in [0, 1] or [-1, 1]:
   ``w_heading * (1 - |bearing error to the target| / pi)
   + w_progress * (distance to the target gained) / (v_top * horizon)
   + w_clearance * min(min clearance - radius, clearance_cap) / clearance_cap
   + w_speed * v / v_top``, with ``v_top`` the top of this step's window (at least
   1 mm/s), not ``max_v``: the progress and speed terms compare the samples the window
   offers, so raising ``max_v`` (the same window while the robot accelerates) does not
   shrink them under the clearance term (issue 42: a 2 m/s robot, whose terms were a
   fifth of a 0.4 m/s one's, crept at 0.017 m/s in the open; ADR 0078).
   The target is a point of the global path ahead of the robot (or the goal); heading
   and progress are taken at the rollout's closest approach to it, among its poses
   before the first one under the threshold (the heading at the last of those poses
   when the closest approach is the start: a rollout that never gets nearer).

The best admissible sample is the command. With none admissible the command is the
braking one and the reason says so.

**Fast path** (:func:`clear_arc`, ``fast_path``): where the way is open the sampling
is not needed. The one arc through the target at the top of the window (pure
pursuit: curvature ``2 y / L**2`` with the target at ``(x, y)``, ``L`` away in
base_link; the yaw rate clamped to the window) is rolled out over the horizon like a
sample; when every pose of it, the start included, has a clearance of at least
``radius + fast_margin + v * dt / 2``, it is the command (reason ``clear arc``). That
proves the whole arc keeps ``radius + fast_margin``, not only its poses: the
clearance is a lower bound on a 1-Lipschitz distance and the poses are ``v * dt``
apart, so no point of the arc is more than ``v * dt / 2`` from one. With no pose under
the radius the stop fits (what the full step calls admissible); the safety layer
still checks the command. Every other case (the target off by more than
``rotate_threshold``, a pose too near a return, no speed) runs the full step. The
arc is not the sample the full step would pick (that one also weighs clearance up to
``clearance_cap``), but it follows the global path, which keeps off obstacles by its
penalty. Measured on the acceptance course: 2/3 of the moving steps take it, at ~5 us
(its poses in plain Python, ADR 0034) instead of ~75 us; every built-in course passes
with the same times +-0.5 s.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from otonav.params import DwaParams

__all__ = ("ClearanceFn", "DwaParams", "DwaResult", "PointClearanceFn", "clear_arc", "dwa_step")

ClearanceFn = Callable[[NDArray[np.float64], NDArray[np.float64]], NDArray[np.float32]]
"""(x, y) arrays in odom -> distance to the nearest return, m (same shape)."""

PointClearanceFn = Callable[[float, float], float]
"""One point (x, y) in odom -> distance to the nearest return, m (as :data:`ClearanceFn`)."""


class DwaResult(NamedTuple):
    """Output of :func:`dwa_step` (a named tuple: immutable, and made in a third of
    a frozen dataclass's time, once per step).

    Attributes:
        v: forward speed command, m/s.
        omega: yaw-rate command, rad/s.
        admissible: how many samples could stop before breaking the clearance.
        samples: how many samples were rolled out.
        best_score: the chosen sample's score (-inf when none was admissible, NaN on
            the fast path: nothing was compared).
        clearance: the chosen rollout's smallest clearance, m.
        reason: why this command, in a few words.
    """

    v: float
    omega: float
    admissible: int
    samples: int
    best_score: float
    clearance: float
    reason: str


_MIN_V_TOP = 1e-3
"""m/s: the smallest speed the progress and speed terms are scaled by (a window that
reaches no faster, e.g. turning on the spot from rest, scores them as at 1 mm/s)."""


@lru_cache(maxsize=8)
def _times(dt: float, steps: int) -> NDArray[np.float64]:
    t = dt * np.arange(steps + 1, dtype=np.float64)
    t.flags.writeable = False
    return t


@lru_cache(maxsize=8)
def _fractions(n: int) -> NDArray[np.float64]:
    f = np.linspace(0.0, 1.0, n)
    f.flags.writeable = False
    return f


@lru_cache(maxsize=8)
def _columns(steps: int) -> NDArray[np.intp]:
    c = np.arange(steps + 1)
    c.flags.writeable = False
    return c


@lru_cache(maxsize=8)
def _tie_break(steps: int) -> NDArray[np.float64]:
    b = 1e-9 * np.arange(steps + 1, dtype=np.float64)
    b.flags.writeable = False
    return b


@lru_cache(maxsize=8)
def _rows(v_count: int, w_count: int) -> NDArray[np.intp]:
    """Per sample of the grid, its row among the distinct yaw rates: the ``w_count``
    rates for each of the ``v_count`` speeds, then the braking sample's (``w_count``)."""
    r = np.append(np.tile(np.arange(w_count), v_count), w_count)
    r.flags.writeable = False
    return r


def _window(lo: float, hi: float, n: int) -> NDArray[np.float64]:
    # np.linspace costs ~10 us a call; the cached fractions make this one multiply-add.
    return lo + (hi - lo) * _fractions(n) if n > 1 and hi > lo else np.array([0.5 * (lo + hi)])


def clear_arc(
    pose: tuple[float, float, float],
    v0: float,
    omega0: float,
    target: tuple[float, float],
    goal_distance: float,
    clearance_at: PointClearanceFn,
    params: DwaParams,
) -> DwaResult | None:
    """The fast path (module docstring): the arc toward ``target`` at the top of the
    window when it is provably clear, else None (run :func:`dwa_step`). Same
    arguments as :func:`dwa_step`, but the clearance of one point at a time: the
    arc's nine poses in plain Python cost ~5 us, through numpy ~17 us (per-call
    overhead), and the first pose too near a return ends the test."""
    p = params
    x0, y0, th0 = pose
    v_cap = min(p.max_v, math.sqrt(p.max_accel * max(goal_distance, 0.0)))
    v = min(max(v0 + p.max_accel * p.period, 0.0), v_cap)
    w_lo = max(omega0 - p.max_alpha * p.period, -p.max_omega)
    w_hi = min(omega0 + p.max_alpha * p.period, p.max_omega)
    if v <= 0.0 or w_lo > w_hi:
        return None
    c, s = math.cos(th0), math.sin(th0)
    dx, dy = target[0] - x0, target[1] - y0
    bx, by = c * dx + s * dy, c * dy - s * dx  # the target in base_link
    span2 = bx * bx + by * by
    if span2 < 1e-12 or abs(math.atan2(by, bx)) > p.rotate_threshold:
        return None
    omega = min(max(v * 2.0 * by / span2, w_lo), w_hi)
    steps = max(1, round(p.horizon / p.dt))
    w_eff = omega if abs(omega) >= 1e-6 else math.copysign(1e-6, omega)
    r = v / w_eff
    need = p.radius + p.fast_margin + 0.5 * v * p.dt
    least = math.inf
    sin, cos = math.sin, math.cos
    for k in range(steps + 1):
        th = th0 + w_eff * (p.dt * k)  # the same floats as dwa_step's rollouts
        here = clearance_at(x0 + r * (sin(th) - s), y0 - r * (cos(th) - c))
        if here < need:
            return None
        if here < least:
            least = here
    return DwaResult(
        v=v,
        omega=omega,
        admissible=1,
        samples=1,
        best_score=math.nan,
        clearance=least,
        reason="clear arc",
    )


def dwa_step(
    pose: tuple[float, float, float],
    v0: float,
    omega0: float,
    target: tuple[float, float],
    goal_distance: float,
    clearance: ClearanceFn,
    params: DwaParams,
) -> DwaResult:
    """Choose (v, omega) for the next period (module docstring): from ``pose`` (x, y,
    yaw in odom) at ``v0`` m/s, ``omega0`` rad/s, heading for ``target`` (odom, m), the
    speed capped for arriving ``goal_distance`` m away, ``clearance`` looked up in odom."""
    p = params
    x0, y0, th0 = pose
    # Arrive: braking at half the limit would stop at the goal (margin for the period).
    v_cap = min(p.max_v, math.sqrt(p.max_accel * max(goal_distance, 0.0)))
    v_lo = min(max(v0 - p.max_accel * p.period, 0.0), v_cap)
    v_hi = min(max(v0 + p.max_accel * p.period, 0.0), v_cap)
    w_lo = max(omega0 - p.max_alpha * p.period, -p.max_omega)
    w_hi = min(omega0 + p.max_alpha * p.period, p.max_omega)
    if w_lo > w_hi:  # omega0 outside the limits: the window is the nearest limit
        w_lo = w_hi = min(max(omega0, -p.max_omega), p.max_omega)
    tx, ty = target
    off = abs(math.remainder(math.atan2(ty - y0, tx - x0) - th0, math.tau))
    vs = _window(v_lo, v_lo if off > p.rotate_threshold else v_hi, p.v_samples)
    ws = _window(w_lo, w_hi, p.omega_samples)
    brake_w = min(max(0.0, w_lo), w_hi)
    # The grid: v = [vs repeated per omega..., v_lo], w = [ws tiled..., brake_w]. The
    # headings, sines and cosines depend on omega only: computed per distinct rate
    # (13 + 1 rows, not 66) and spread to the samples by one index (the same floats;
    # with the other trims below ~10 % of the step).
    nv, nw = vs.size, ws.size
    n = nv * nw + 1
    v = np.empty(n)
    v[:-1].reshape(nv, nw)[...] = vs[:, None]
    v[-1] = v_lo
    wu = np.empty(nw + 1)  # (np.append is a Python function: ~3 us more)
    wu[:nw] = ws
    wu[nw] = brake_w
    rows = _rows(nv, nw)
    w = wu[rows]
    steps = max(1, round(p.horizon / p.dt))
    t = _times(p.dt, steps)  # (K+1,): column 0 is the start pose
    columns = _columns(steps)
    # Exact arcs: x = x0 + v/w (sin(th) - sin(th0)), y = y0 - v/w (cos(th) - cos(th0)).
    # A straight line is the limit w -> 0; |w| >= 1e-6 rad/s keeps v/w finite and
    # errs by < 1e-6 m over the horizon (no branch, no extra numpy calls).
    wu_eff = np.where(np.abs(wu) < 1e-6, np.copysign(1e-6, wu), wu)
    thu = th0 + wu_eff[:, None] * t[None, :]  # (distinct rates, K+1) heading
    r = (v / wu_eff[rows])[:, None]
    xs = x0 + r * (np.sin(thu) - math.sin(th0))[rows]
    ys = y0 - r * (np.cos(thu) - math.cos(th0))[rows]
    clear = clearance(xs.ravel(), ys.ravel()).reshape(n, steps + 1)
    here = float(clear[0, 0])
    threshold = min(p.radius, here - 1e-3)
    # The first pose under the threshold, by argmax over the poses after the start and
    # a sentinel column (no hit: `steps`); the pose before it is the last free one.
    hit = np.empty((n, steps + 1), dtype=np.bool_)
    np.less(clear[:, 1:], threshold, out=hit[:, :steps])
    hit[:, steps] = True
    last = hit.argmax(axis=1)
    free = np.where(last < steps, v * t[last], np.inf)
    stop = v * p.latency + v * v / (2.0 * p.max_accel)
    admissible = stop <= free
    count = int(np.count_nonzero(admissible))
    if count == 0:
        return DwaResult(
            v=float(v_lo),
            omega=float(brake_w),
            admissible=0,
            samples=n,
            best_score=-math.inf,
            clearance=here,
            reason="no admissible trajectory: braking",
        )
    # A rollout that reaches a pose under the threshold is cut before it: it is scored
    # where it can get to, not through the obstacle.
    # Each rollout is judged at its closest approach to the target (up to its cut): a
    # fast arc that passes the goal within the horizon is not worse than a slow one
    # that stops short of it (judged at the end, the DWA crawls into every goal).
    to_target = np.hypot(tx - xs, ty - ys)
    # Ties (a turn on the spot stays at one point) go to the latest pose: its heading.
    late = to_target - _tie_break(steps)[None, :]
    np.putmask(late, columns[None, :] > last[:, None], np.inf)  # beyond the cut
    best_i = late.argmin(axis=1)
    flat = best_i + columns.size * _columns(n - 1)  # (row, best_i) in the raveled arrays
    closest = to_target.ravel()[flat]
    # A rollout that never gets nearer (the target behind a robot still rolling
    # forward) has its closest approach at the start, where every rollout has the same
    # heading: its bearing is judged at its last free pose instead. Otherwise all tie
    # and the first sample, the hardest right turn, won: the robot turned the long way
    # round to a target behind on its left (issue 24, a false recovery in a U trap).
    head_i = np.where(best_i == 0, last, best_i)
    flat_h = head_i + columns.size * _columns(n - 1)
    ex, ey = xs.ravel()[flat_h], ys.ravel()[flat_h]
    bearing = np.arctan2(ty - ey, tx - ex) - thu.ravel()[head_i + columns.size * rows]
    bearing = np.abs(np.remainder(bearing + math.pi, math.tau) - math.pi)
    np.putmask(bearing, closest < 0.05, 0.0)  # at the target: no bearing to keep
    d0 = math.hypot(tx - x0, ty - y0)
    v_top = max(v_hi, _MIN_V_TOP)  # the window's, not max_v (module docstring, ADR 0078)
    gain = (d0 - closest) / (v_top * p.horizon)
    min_clear = np.minimum.reduce(clear, axis=1)
    # np.minimum(np.maximum()) is np.clip's result without its ~4 us Python wrapper.
    room = np.minimum(np.maximum(min_clear - p.radius, 0.0), p.clearance_cap) / p.clearance_cap
    score = (
        p.w_heading * (1.0 - bearing / math.pi)
        + p.w_progress * gain
        + p.w_clearance * room
        + p.w_speed * v / v_top
    )
    np.putmask(score, ~admissible, -np.inf)
    best = int(score.argmax())
    reason = "toward target" if room[best] >= 1.0 else "avoiding"
    return DwaResult(
        v=float(v[best]),
        omega=float(w[best]),
        admissible=count,
        samples=n,
        best_score=float(score[best]),
        clearance=float(min_clear[best]),
        reason=reason,
    )
