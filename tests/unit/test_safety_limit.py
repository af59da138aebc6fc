"""The safety limit on plain numbers: it slows or stops what would break the clearance,
lets through what would not, lets a robot already too close back away, and never
blocks a turn on the spot."""

from __future__ import annotations

import numpy as np
import pytest

from otonav.nav.safety import SafetyParams, safe_command

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
