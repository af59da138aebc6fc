"""Layer 3: software in the loop. The robot reaches the goal within 0.15 m inside 20 s
of sim time and never comes closer than 0.3 m to an obstacle (ground truth)."""

from __future__ import annotations

import pytest

from otonav.scenario import ScenarioConfig, run_scenario
from otonav.stack import NavConfig, StackConfig

pytestmark = pytest.mark.sil


def test_acceptance_reaches_goal_with_clearance() -> None:
    scenario = ScenarioConfig()
    verdict = run_scenario(scenario, wall_ceiling=120)
    assert verdict.reached, verdict.reason
    assert verdict.time_to_goal_s is not None
    assert verdict.time_to_goal_s <= 20.0
    assert verdict.final_distance_m <= 0.15
    assert verdict.min_clearance_m >= 0.3, verdict.reason
    assert verdict.passed


def test_gate_has_teeth_zero_linear_gain_fails() -> None:
    broken = StackConfig(nav=NavConfig(kp_lin=0.0))
    verdict = run_scenario(ScenarioConfig(), broken, wall_ceiling=120)
    assert not verdict.passed
    assert not verdict.reached
    assert verdict.sim_time_s == pytest.approx(20.0, abs=0.01)
    assert "did not reach the goal" in verdict.reason
