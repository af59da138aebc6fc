"""The safety limit's invariants (issue 24, test rigor), as properties on random scans
and commands, and at the exact edge of the clearance:

* the command it lets through keeps the documented stopping path out of the clearance
  (unless it had to give up: (0, 0), the best there is);
* it only scales the forward speed (same sign, never faster) and keeps the turn, or
  brakes to (0, 0);
* one more return never lets a faster command through (the scale is monotone in the
  scan);
* a return placed 1e-7 m outside the clearance of the path leaves the command alone,
  1e-7 m inside it slows the command: the model is the documented one to the float,
  not roughly.

The stopping path here is the module docstring's model written as a plain loop that
runs until the robot has stopped (not the module's own horizon)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from safety_model import stopping_path as _path
from safety_model import worst_gap as _worst

from otonav.nav._safety import SafetyParams, safe_command, stopping_reach

pytestmark = pytest.mark.unit

PARAMS = (
    SafetyParams(radius=0.32, max_accel=1.0, max_alpha=3.0, latency=0.12, dt=0.02),
    SafetyParams(radius=0.25, max_accel=0.6, max_alpha=2.0, latency=0.05, dt=0.03, scales=4),
    # no latency: the horizon has no slack beyond the stop itself
    SafetyParams(radius=0.3, max_accel=2.0, max_alpha=4.0, latency=0.0, dt=0.05, scales=5),
)


_speeds = st.floats(-0.5, 0.5)
_rates = st.floats(-1.5, 1.5)
_scan = st.lists(
    st.tuples(st.floats(-math.pi, math.pi), st.floats(0.2, 0.9)), min_size=1, max_size=8
)


def _points(polar: list[tuple[float, float]]) -> np.ndarray:
    a = np.array(polar)
    return np.stack((a[:, 1] * np.cos(a[:, 0]), a[:, 1] * np.sin(a[:, 0])), axis=1)


@settings(max_examples=150, deadline=None)
@given(_speeds, _rates, _speeds, _rates, _scan, st.sampled_from(PARAMS))
def test_what_it_lets_through_stops_outside_the_clearance(
    v: float, w: float, v0: float, w0: float, polar: list[tuple[float, float]], p: SafetyParams
) -> None:
    pts = _points(polar)
    r = safe_command(v, w, v0, w0, pts, p)
    # only the forward speed is scaled, never reversed or raised; or (0, 0)
    assert 0.0 <= r.scale <= 1.0
    assert r.v == pytest.approx(r.scale * v, abs=1e-12)
    assert r.omega == w or (r.v, r.omega, r.scale, r.reason) == (0.0, 0.0, 0.0, "stopped")
    if r.scale == 1.0:
        assert r.reason in ("clear", "safe")
    else:
        assert r.reason == ("stopped" if r.scale == 0.0 else "limited")
    if r.reason == "stopped" and r.omega == 0.0:
        return  # (0, 0): braking, the best there is, may be unsafe
    assert _worst(_path(v0, w0, r.v, r.omega, p), pts, p) >= -1e-9  # (rounding of the sums)


@settings(max_examples=100, deadline=None)
@given(_speeds, _rates, _speeds, _rates, _scan, _scan, st.sampled_from(PARAMS))
def test_one_more_return_never_lets_a_faster_command_through(
    v: float,
    w: float,
    v0: float,
    w0: float,
    polar: list[tuple[float, float]],
    more: list[tuple[float, float]],
    p: SafetyParams,
) -> None:
    pts = _points(polar)
    both = np.concatenate((pts, _points(more)))
    a = safe_command(v, w, v0, w0, pts, p)
    b = safe_command(v, w, v0, w0, both, p)
    assert b.scale <= a.scale
    assert abs(b.v) <= abs(a.v)
    assert b.nearest <= a.nearest


def _edge(path: np.ndarray, k: int, direction: float, p: SafetyParams) -> np.ndarray | None:
    """The point along ``direction`` from path pose ``k`` whose smallest distance to the
    path is exactly the radius (bisection), or None when it would be inside the radius
    of the start (then its allowance is not the radius)."""
    u = np.array((math.cos(direction), math.sin(direction)))

    def excess(s: float) -> float:
        q = path[k] + s * u
        return float(np.hypot(path[:, 0] - q[0], path[:, 1] - q[1]).min()) - p.radius

    lo, hi = 0.0, p.radius + 1.0
    if excess(hi) <= 0.0:
        return None
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if excess(mid) < 0.0:
            lo = mid
        else:
            hi = mid
    q: np.ndarray = path[k] + hi * u
    if math.hypot(*q) - 1e-4 <= p.radius + 1e-6:
        return None
    return q


@pytest.mark.parametrize("p", PARAMS)
def test_a_return_at_the_edge_of_the_clearance_is_decided_to_the_float(p: SafetyParams) -> None:
    rng = np.random.default_rng(24)
    cases = 0
    while cases < 40:
        v0 = float(rng.uniform(-0.5, 0.5))
        w0 = float(rng.uniform(-1.5, 1.5))
        v = float(rng.uniform(-0.5, 0.5))
        w = float(rng.uniform(-1.5, 1.5))
        path = _path(v0, w0, v, w, p)
        k = int(rng.integers(0, path.shape[0]))
        q = _edge(path, k, float(rng.uniform(-math.pi, math.pi)), p)
        if q is None:
            continue
        cases += 1
        # the binding pose's outward direction: 1e-7 m beyond the edge or inside it
        away = q - path[int(np.hypot(path[:, 0] - q[0], path[:, 1] - q[1]).argmin())]
        away /= np.hypot(*away)
        outside = safe_command(v, w, v0, w0, (q + 1e-7 * away)[None, :], p)
        inside = safe_command(v, w, v0, w0, (q - 1e-7 * away)[None, :], p)
        assert (outside.v, outside.omega, outside.reason) == (v, w, "safe"), (v0, w0, v, w, q)
        assert inside.scale < 1.0, (v0, w0, v, w, q)
        assert inside.reason in ("limited", "stopped")


@pytest.mark.parametrize("p", PARAMS)
@pytest.mark.parametrize("v", [0.0, 0.3, -0.45])
def test_a_return_exactly_at_the_stopping_reach_is_skipped_and_one_ulp_nearer_is_not(
    p: SafetyParams, v: float
) -> None:
    """stopping_reach: a return *farther* than radius + reach cannot matter; at exactly
    that distance it is skipped too (clear), one float nearer it is checked."""
    edge = p.radius + stopping_reach(abs(v), p)
    at = safe_command(v, 0.7, v, 0.0, np.array([[edge, 0.0]]), p)
    nearer = safe_command(v, 0.7, v, 0.0, np.array([[math.nextafter(edge, 0.0), 0.0]]), p)
    assert at.reason == "clear"
    assert nearer.reason != "clear"


def test_a_robot_at_rest_with_no_latency_is_checked_and_safe() -> None:
    """No speed, no turn, no latency: the stopping path is the start alone (one step);
    a return inside the radius or at its edge does not stop a robot that stays put."""
    p = PARAMS[2]
    for d in (0.2, p.radius + 5e-7):
        r = safe_command(0.0, 0.0, 0.0, 0.0, np.array([[0.0, d]]), p)
        assert (r.v, r.omega, r.scale, r.reason) == (0.0, 0.0, 1.0, "safe")
