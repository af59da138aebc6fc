"""The safety limit on plain numbers: it slows or stops what would break the clearance,
lets through what would not, lets a robot already too close back away, and never
blocks a turn on the spot."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from otonav.nav._safety import SafetyParams, safe_command, stopping_reach

pytestmark = pytest.mark.unit

P = SafetyParams(radius=0.32, max_accel=1.0, max_alpha=3.0, latency=0.12)


def _wall(x: float) -> np.ndarray:
    ys = np.linspace(-1.0, 1.0, 101)
    return np.stack((np.full_like(ys, x), ys), axis=1)


def _stop_distance(v: float) -> float:
    return v * P.latency + v * v / (2 * P.max_accel)


def test_far_returns_let_the_command_through_untouched() -> None:
    r = safe_command(0.5, 0.3, 0.5, 0.3, _wall(1.5), P)
    assert (r.v, r.omega, r.scale, r.reason) == (0.5, 0.3, 1.0, "clear")
    assert r.nearest == pytest.approx(1.5)


@pytest.mark.parametrize("x", [0.45, 0.5, 0.55, 0.6])
def test_full_speed_at_a_wall_is_slowed_so_it_stops_in_time(x: float) -> None:
    r = safe_command(0.5, 0.0, 0.5, 0.0, _wall(x), P)
    if _stop_distance(0.5) + P.radius <= x:
        assert r.v == 0.5
    else:
        assert r.v < 0.5
        assert r.reason in ("limited", "stopped")
    # Whatever it lets through stops short: the speed reached in the latency from 0.5
    # toward r.v, then braking.
    assert _stop_distance(max(r.v, 0.0)) <= x - P.radius + _stop_distance(0.5)


def test_reverse_into_a_wall_behind_is_stopped() -> None:
    r = safe_command(-0.5, 0.0, -0.2, 0.0, _wall(-0.4), P)
    assert r.v > -0.5
    assert r.reason in ("limited", "stopped")


def test_turning_on_the_spot_beside_a_box_is_allowed() -> None:
    box = np.array([[0.0, 0.33], [0.1, 0.33], [-0.1, 0.33]])
    r = safe_command(0.0, 1.5, 0.0, 0.0, box, P)
    assert (r.v, r.omega) == (0.0, 1.5)


def test_an_arc_into_a_box_is_slowed() -> None:
    box = np.array([[0.35, 0.15], [0.4, 0.2], [0.3, 0.1]])
    r = safe_command(0.5, 1.0, 0.5, 1.0, box, P)
    assert r.v < 0.5


def test_inside_the_radius_it_may_back_away_but_not_approach() -> None:
    close = np.array([[0.25, 0.0]])
    assert safe_command(-0.1, 0.0, 0.0, 0.0, close, P).v == -0.1
    toward = safe_command(0.1, 0.0, 0.0, 0.0, close, P)
    assert toward.v == 0.0
    assert toward.reason == "stopped"


def test_params_validate() -> None:
    with pytest.raises(ValueError, match="radius"):
        SafetyParams(radius=0.0)
    with pytest.raises(ValueError, match="scales"):
        SafetyParams(scales=1)


@settings(max_examples=200, deadline=None)
@given(
    st.floats(-0.5, 0.5),
    st.floats(-1.5, 1.5),
    st.floats(-0.5, 0.5),
    st.floats(-1.5, 1.5),
    st.lists(st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)), min_size=1, max_size=20),
)
def test_returns_beyond_the_stopping_reach_never_change_a_command(
    v: float, w: float, v0: float, w0: float, xy: list[tuple[float, float]]
) -> None:
    """The bound the safety layer and the bare benchmark skip the check on
    (stopping_reach, issue 31): beyond it the command goes through as it came."""
    points = np.array(xy)
    fastest = max(abs(v), abs(v0))
    nearest = float(np.hypot(points[:, 0], points[:, 1]).min())
    r = safe_command(v, w, v0, w0, points, P)
    if nearest >= P.radius + stopping_reach(fastest, P):
        assert (r.v, r.omega, r.reason) == (v, w, "clear")
    else:
        assert r.reason != "clear"


def test_the_stopping_reach_is_latency_braking_and_the_integration_slack() -> None:
    p = SafetyParams(radius=0.3, max_accel=2.0, latency=0.1, dt=0.01)
    assert stopping_reach(0.0, p) == pytest.approx(1e-6, abs=1e-9)
    assert stopping_reach(0.4, p) == pytest.approx(
        0.4 * 0.1 + 0.16 / 4.0 + 2 * 0.01 * 0.4, abs=2e-6
    )
    # A command just inside the reach of a wall ahead is checked (and slowed).
    edge = p.radius + stopping_reach(0.4, p)
    assert safe_command(0.4, 0.0, 0.4, 0.0, _wall(edge + 1e-3), p).reason == "clear"
    assert safe_command(0.4, 0.0, 0.4, 0.0, _wall(edge - 1e-3), p).reason != "clear"


def test_a_tiny_max_accel_bounds_the_stopping_grid_and_stays_safe(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """base.max_accel = 0.001: stopping from 0.5 m/s takes 500 s (125 m). The grid is
    capped (it grew as v^2 / max_accel: ~25,000 steps, ~0.15 s a call) and the path past
    it is bounded, so a wall 40 m ahead is still judged unsafe at full speed."""
    import otonav.nav._safety as safety

    steps: list[int] = []
    profile = safety._profile

    def counted(*args: Any) -> Any:
        out = profile(*args)
        steps.append(out.shape[1])
        return out

    monkeypatch.setattr(safety, "_profile", counted)
    tiny = SafetyParams(radius=0.32, max_accel=0.001, max_alpha=3.0, latency=0.12)
    r = safe_command(0.5, 0.0, 0.5, 0.0, _wall(40.0), tiny)
    assert max(steps) <= 501  # 10 s of path at dt 0.02
    assert r.reason == "stopped"
    # From rest, the same base barely moves in the latency: it may go.
    steps.clear()
    r = safe_command(0.5, 0.0, 0.0, 0.0, _wall(1.0), tiny)
    assert r.reason == "safe"
    assert max(steps) <= 501
