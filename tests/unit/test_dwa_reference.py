"""The DWA (otonav.nav._dwa) against its module docstring written as plain per-sample
loops, on random settings as well as the defaults (issue 24, test rigor): acceleration
and yaw limits other than 1, one-sample windows, a robot already inside its radius, a
yaw rate beyond the limit, goals nearer than 1 m, targets within reach of a rollout,
no latency, a horizon of one step. Every field of the result is compared, and the
fast path (:func:`clear_arc`) likewise.

The clearance is exact (the distance to a set of points, float64), so the step and
the reference see the same numbers."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from dwa_model import Pose
from dwa_model import dwa_reference as _reference

from otonav.nav._dwa import ClearanceFn, DwaParams, DwaResult, PointClearanceFn, clear_arc, dwa_step

pytestmark = pytest.mark.unit


def _clearance(pts: np.ndarray) -> tuple[ClearanceFn, PointClearanceFn]:
    def field(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        if pts.shape[0] == 0:
            return np.full(np.shape(x), 5.0)
        d = np.hypot(np.subtract.outer(x, pts[:, 0]), np.subtract.outer(y, pts[:, 1]))
        out: np.ndarray = np.minimum(d.min(axis=-1), 5.0)
        return out

    def at(x: float, y: float) -> float:
        return float(field(np.array([x]), np.array([y]))[0])

    return field, at


def _arc_reference(
    pose: Pose,
    v0: float,
    w0: float,
    target: tuple[float, float],
    goal: float,
    at: PointClearanceFn,
    p: DwaParams,
) -> DwaResult | None:
    x0, y0, th0 = pose
    cap = min(p.max_v, math.sqrt(p.max_accel * max(goal, 0.0)))
    v = min(max(v0 + p.max_accel * p.period, 0.0), cap)
    w_lo = max(w0 - p.max_alpha * p.period, -p.max_omega)
    w_hi = min(w0 + p.max_alpha * p.period, p.max_omega)
    if v <= 0.0 or w_lo > w_hi:
        return None
    c, s = math.cos(th0), math.sin(th0)
    dx, dy = target[0] - x0, target[1] - y0
    bx, by = c * dx + s * dy, c * dy - s * dx
    span2 = bx * bx + by * by
    if span2 < 1e-12 or abs(math.atan2(by, bx)) > p.rotate_threshold:
        return None
    omega = min(max(v * 2.0 * by / span2, w_lo), w_hi)
    we = omega if abs(omega) >= 1e-6 else math.copysign(1e-6, omega)
    least = math.inf
    for k in range(max(1, round(p.horizon / p.dt)) + 1):
        th = th0 + we * (p.dt * k)
        here = at(x0 + v / we * (math.sin(th) - s), y0 - v / we * (math.cos(th) - c))
        if here < p.radius + p.fast_margin + 0.5 * v * p.dt:
            return None
        least = min(least, here)
    return DwaResult(v, omega, 1, 1, math.nan, least, "clear arc")


def _params(rng: np.random.Generator) -> DwaParams:
    horizon = float(rng.choice([0.25, 0.8, 1.6, 2.2]))
    return DwaParams(
        max_v=float(rng.uniform(0.2, 1.0)),
        max_omega=float(rng.uniform(0.5, 2.5)),
        max_accel=float(rng.uniform(0.4, 3.0)),
        max_alpha=float(rng.uniform(1.0, 5.0)),
        period=float(rng.uniform(0.03, 0.2)),
        horizon=horizon,
        dt=float(rng.choice([horizon, horizon / 2, horizon / 5, 0.2]))
        if horizon >= 0.2
        else horizon,
        v_samples=int(rng.integers(1, 6)),
        omega_samples=int(rng.integers(1, 14)),
        radius=float(rng.choice([0.0, rng.uniform(0.15, 0.4)])),
        latency=float(rng.choice([0.0, rng.uniform(0.02, 0.3)])),
        clearance_cap=float(rng.uniform(0.1, 0.6)),
        w_heading=float(rng.uniform(0, 2)),
        w_progress=float(rng.uniform(0, 3)),
        w_clearance=float(rng.uniform(0, 1.5)),
        w_speed=float(rng.uniform(0, 1)),
        rotate_threshold=float(rng.choice([0.0, rng.uniform(0.2, 1.5)])),
        fast_margin=float(rng.uniform(0.0, 0.3)),
    )


Case = tuple[Pose, float, float, tuple[float, float], float, np.ndarray]


def _case(rng: np.random.Generator, p: DwaParams) -> Case:
    pose = (float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(-3, 3)))
    kind = int(rng.integers(0, 4))
    if kind == 0:  # open space
        pts = np.empty((0, 2))
    elif kind == 1:  # a robot already inside its radius
        a = float(rng.uniform(-math.pi, math.pi))
        d = float(rng.uniform(0.5, 0.95)) * max(p.radius, 0.05)
        pts = np.array([[pose[0] + d * math.cos(a), pose[1] + d * math.sin(a)]])
        pts = np.concatenate((pts, rng.uniform(-2, 2, (3, 2))))
    elif kind == 2:  # scattered returns
        pts = rng.uniform(-2.0, 2.0, (int(rng.integers(2, 12)), 2))
    else:  # a wall across the way, near enough to cut some rollouts
        d, a = p.radius + float(rng.uniform(0.01, 0.15)), pose[2] + float(rng.uniform(-0.5, 0.5))
        along = np.linspace(-0.6, 0.6, 31)[:, None] * [-math.sin(a), math.cos(a)]
        pts = np.add(along, (pose[0] + d * math.cos(a), pose[1] + d * math.sin(a)))
    v0 = float(rng.uniform(0.5 if kind == 3 else 0.0, 1.0)) * p.max_v
    w0 = float(rng.uniform(-1.0, 1.0)) * p.max_omega
    if rng.random() < 0.15:  # beyond the limit: more than a period's change away
        w0 = math.copysign(p.max_omega + p.max_alpha * p.period * float(rng.uniform(1.5, 3)), w0)
    b = pose[2] + float(rng.choice([0.0, rng.uniform(-1.0, 1.0), rng.uniform(-3.1, 3.1)]))
    reach = float(rng.choice([0.03, rng.uniform(0.05, 0.6), rng.uniform(0.6, 3.0)]))
    target = (pose[0] + reach * math.cos(b), pose[1] + reach * math.sin(b))
    goal = float(rng.choice([0.0, rng.uniform(0.001, 1.0), rng.uniform(1.0, 4.0)]))
    return pose, v0, w0, target, goal, pts


def _same(r: DwaResult, want: DwaResult) -> None:
    assert (r.v, r.omega) == pytest.approx((want.v, want.omega), abs=1e-12)
    assert (r.admissible, r.samples, r.reason) == (want.admissible, want.samples, want.reason)
    assert r.clearance == pytest.approx(want.clearance, abs=1e-12)
    if math.isnan(want.best_score):
        assert math.isnan(r.best_score)
    else:
        assert r.best_score == pytest.approx(want.best_score, abs=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_dwa_step_is_its_docstring_on_random_settings(seed: int) -> None:
    rng = np.random.default_rng(1000 + seed)
    seen: set[str] = set()
    cut = 0
    for _ in range(60):
        p = _params(rng) if rng.random() < 0.8 else DwaParams()
        pose, v0, w0, target, goal, pts = _case(rng, p)
        field, _ = _clearance(pts)
        r = dwa_step(pose, v0, w0, target, goal, field, p)
        _same(r, _reference(pose, v0, w0, target, goal, field, p))
        seen.add(r.reason)
        cut += r.admissible < r.samples
    assert seen == {"toward target", "avoiding", "no admissible trajectory: braking"}
    assert cut >= 4  # some rollouts cut short of the horizon: not admissible


@pytest.mark.parametrize("seed", range(3))
def test_clear_arc_is_its_docstring_on_random_settings(seed: int) -> None:
    rng = np.random.default_rng(2000 + seed)
    taken = refused = 0
    for _ in range(120):
        p = _params(rng)
        pose, v0, w0, target, goal, pts = _case(rng, p)
        _, at = _clearance(pts)
        r = clear_arc(pose, v0, w0, target, goal, at, p)
        want = _arc_reference(pose, v0, w0, target, goal, at, p)
        if want is None:
            assert r is None
            refused += 1
        else:
            assert r is not None
            _same(r, want)
            taken += 1
    assert taken >= 5
    assert refused >= 5


def _open(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.full(np.shape(x), 5.0)


def test_a_target_dead_ahead_is_not_off_by_a_zero_threshold() -> None:
    """rotate_threshold = 0: only a target *farther* off than 0 rad shrinks the window;
    one straight ahead keeps its speeds and its fast path."""
    p = DwaParams(rotate_threshold=0.0)
    r = dwa_step((0.0, 0.0, 0.0), 0.0, 0.0, (2.0, 0.0), 2.0, _open, p)
    assert r.v == pytest.approx(p.max_accel * p.period)
    arc = clear_arc((0.0, 0.0, 0.0), 0.0, 0.0, (2.0, 0.0), 2.0, lambda x, y: 5.0, p)
    assert arc is not None
    assert (arc.v, arc.omega, arc.admissible, arc.samples) == (p.max_accel * p.period, 0.0, 1, 1)


def test_a_yaw_window_of_one_rate_is_still_a_window() -> None:
    """A yaw rate exactly one period's change beyond the limit: the window is the limit
    alone (not empty), and the fast path takes it."""
    p = DwaParams(max_omega=1.0, max_alpha=2.0, period=0.25)
    arc = clear_arc((0.0, 0.0, 0.0), 0.2, 1.5, (2.0, 0.3), 3.0, lambda x, y: 5.0, p)
    assert arc is not None
    assert arc.omega == 1.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_yaw_rate_far_beyond_the_limit_is_brought_to_the_limit(sign: float) -> None:
    p = DwaParams(fast_path=False)
    r = dwa_step((0.0, 0.0, 0.0), 0.2, sign * 3.0, (2.0, 0.0), 2.0, _open, p)
    assert r.omega == sign * p.max_omega


def test_params_bounds_name_the_field() -> None:
    for name in ("max_v", "max_omega", "max_accel", "max_alpha", "period", "clearance_cap"):
        with pytest.raises(ValueError, match=rf"DwaParams\.{name} must be finite and > 0"):
            DwaParams(**{name: 0.0})  # type: ignore[arg-type]
    for name in ("radius", "latency", "w_heading", "rotate_threshold", "fast_margin"):
        with pytest.raises(ValueError, match=rf"DwaParams\.{name} must be finite and >= 0"):
            DwaParams(**{name: -1.0})  # type: ignore[arg-type]
        with pytest.raises(ValueError, match=rf"DwaParams\.{name}"):
            DwaParams(**{name: math.inf})  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="fast_path must be a bool"):
        DwaParams(fast_path=1)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="omega_samples must be an integer >= 1"):
        DwaParams(omega_samples=2.0)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"dt \(0.5 s\) must be <= horizon"):
        DwaParams(horizon=0.4, dt=0.5)
    # the edges are valid: zeros where >= 0, one sample, one step
    edge = DwaParams(
        radius=0.0, latency=0.0, rotate_threshold=0.0, v_samples=1, horizon=0.5, dt=0.5
    )
    assert (edge.v_samples, edge.dt) == (1, 0.5)


def test_params_are_frozen_and_slotted() -> None:
    p = DwaParams()
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.max_v = 1.0  # type: ignore[misc]
    assert not hasattr(p, "__dict__")


@pytest.mark.parametrize("max_accel", [0.5, 2.0])
def test_a_wall_ahead_admits_exactly_the_speeds_that_stop_in_their_free_length(
    max_accel: float,
) -> None:
    """Straight at a wall: the free length is what each speed drives before its first
    pose under the radius; a speed is admissible iff v * latency + v^2 / (2 max_accel)
    fits in it. The window spans speeds on both sides of that line."""
    p = DwaParams(
        max_v=1.0,
        max_accel=max_accel,
        period=0.4 / max_accel,
        v_samples=9,
        omega_samples=1,
        latency=0.05,
        horizon=1.0,
        dt=0.1,
        radius=0.3,
        rotate_threshold=3.0,
        fast_path=False,
    )
    wall = np.stack((np.full(61, 0.5), np.linspace(-3.0, 3.0, 61)), axis=1)
    field, _ = _clearance(wall)
    v0 = 0.6
    r = dwa_step((0.0, 0.0, 0.0), v0, 0.0, (3.0, 0.0), 3.0, field, p)
    _same(r, _reference((0.0, 0.0, 0.0), v0, 0.0, (3.0, 0.0), 3.0, field, p))
    assert 1 < r.admissible < r.samples - 1
