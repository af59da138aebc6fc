"""The safety limit against its module docstring, written as a plain loop: for random
commands, speeds and returns near the robot, ``safe_command`` picks exactly what the
documented model picks (issue 24: pin the safety math so a changed sign, bound or
constant fails a unit test)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from safety_model import stopping_path, worst_gap

from otonav.nav._safety import SafetyParams, safe_command

pytestmark = pytest.mark.unit


def _worst(v0: float, w0: float, v_t: float, w_t: float, pts: np.ndarray, p: SafetyParams) -> float:
    """Smallest (distance - allowed) along the stopping path, integrated every dt until
    the robot has stopped (the reference does not use the module's duration)."""
    return worst_gap(stopping_path(v0, w0, v_t, w_t, p), pts, p)


def _reference(
    v_cmd: float, w_cmd: float, v0: float, w0: float, pts: np.ndarray, p: SafetyParams
) -> tuple[float, float, float, str]:
    """(v, omega, scale, reason) by the docstring: the largest of 1, ..., 0 that is
    safe (turn kept), else (0, 0)."""
    for i in range(p.scales):
        scale = 1.0 - i / (p.scales - 1)
        if _worst(v0, w0, scale * v_cmd, w_cmd, pts, p) >= 0.0:
            if i == 0:
                return v_cmd, w_cmd, 1.0, "safe"
            return scale * v_cmd, w_cmd, scale, "limited" if scale > 0.0 else "stopped"
    return 0.0, 0.0, 0.0, "stopped"


@pytest.mark.parametrize(
    "params",
    [
        SafetyParams(radius=0.32, max_accel=1.0, max_alpha=3.0, latency=0.12),
        SafetyParams(radius=0.25, max_accel=0.6, max_alpha=2.0, latency=0.05, dt=0.03, scales=4),
    ],
)
def test_safe_command_is_the_model_its_docstring_describes(params: SafetyParams) -> None:
    rng = np.random.default_rng(7)
    outcomes: dict[str, int] = {}
    for _ in range(250):
        v_cmd, v0 = rng.uniform(-0.5, 0.5, 2)
        w_cmd, w0 = rng.uniform(-1.5, 1.5, 2)
        n = int(rng.integers(1, 6))
        bearing = rng.uniform(-math.pi, math.pi, n)
        reach = rng.uniform(0.25, 0.8, n)
        pts = np.stack((reach * np.cos(bearing), reach * np.sin(bearing)), axis=1)
        r = safe_command(float(v_cmd), float(w_cmd), float(v0), float(w0), pts, params)
        nearest = float(np.hypot(pts[:, 0], pts[:, 1]).min())
        assert r.nearest == pytest.approx(nearest, abs=1e-12)
        if r.reason == "clear":  # nothing within reach: no stopping path comes near
            assert _worst(v0, w0, v_cmd, w_cmd, pts, params) >= 0.0
            assert (r.v, r.omega, r.scale) == (v_cmd, w_cmd, 1.0)
        else:
            v, w, scale, reason = _reference(v_cmd, w_cmd, v0, w0, pts, params)
            assert r.reason == reason
            assert r.scale == pytest.approx(scale, abs=1e-12)
            assert r.v == pytest.approx(v, abs=1e-12)
            assert r.omega == w
        outcomes[r.reason] = outcomes.get(r.reason, 0) + 1
    # every branch is exercised (seeded): clear, safe, limited and stopped
    assert set(outcomes) == {"clear", "safe", "limited", "stopped"}, outcomes


def test_params_name_the_field_and_bound() -> None:
    bad: dict[str, float]
    for bad in ({"max_accel": 0.0}, {"max_alpha": -1.0}, {"dt": math.inf}):
        (field,) = bad
        with pytest.raises(ValueError, match=f"SafetyParams.{field} must be finite and > 0"):
            SafetyParams(**bad)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="latency must be finite and >= 0"):
        SafetyParams(latency=-0.01)
    assert SafetyParams(latency=0.0).latency == 0.0
    assert SafetyParams(scales=2).scales == 2
    with pytest.raises(ValueError, match="scales must be an integer >= 2"):
        SafetyParams(scales=2.0)  # type: ignore[arg-type]


def test_an_empty_scan_lets_every_command_through() -> None:
    r = safe_command(0.5, -1.0, 0.0, 0.0, np.empty((0, 2)), SafetyParams())
    assert (r.v, r.omega, r.scale, r.nearest, r.reason) == (0.5, -1.0, 1.0, math.inf, "clear")


def test_params_and_results_are_frozen_and_slotted() -> None:
    import dataclasses

    p = SafetyParams()
    r = safe_command(0.1, 0.0, 0.0, 0.0, np.empty((0, 2)), p)
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.radius = 1.0  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.v = 1.0  # type: ignore[misc]
    assert not hasattr(p, "__dict__")
    assert not hasattr(r, "__dict__")
