"""Layer 3: software in the loop. The robot reaches the goal within 0.15 m inside 20 s
of sim time and never comes closer than 0.3 m to an obstacle (ground truth)."""

from __future__ import annotations

import math

import pytest

from otonav.scenario import GoalSpec, ScenarioConfig, StartSpec, run_scenario
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
    """The stop-only planner (nav.planner=stop) keeps its own sabotage."""
    broken = StackConfig(nav=NavConfig(planner="stop", kp_lin=0.0))
    verdict = run_scenario(ScenarioConfig(), broken, wall_ceiling=120)
    assert not verdict.passed
    assert not verdict.reached
    assert verdict.sim_time_s == pytest.approx(20.0, abs=0.01)
    assert "did not reach the goal" in verdict.reason


def test_start_pose_places_the_robot_and_its_odometry() -> None:
    scenario = ScenarioConfig(
        name="from_the_side",
        scene="empty",
        start=StartSpec(x=-1.0, y=1.0, yaw=math.pi / 2),
        goal=GoalSpec(x=2.0, y=-1.0),
    )
    verdict = run_scenario(scenario, wall_ceiling=120)
    assert verdict.passed, verdict.reason
    # From the start pose, not the origin: the path is the straight 3.61 m less the
    # 0.15 m tolerance, plus at most a little for the turn (facing +y, goal lower right).
    straight = math.hypot(2.0 - -1.0, -1.0 - 1.0) - scenario.goal_tolerance
    assert straight - 0.01 <= verdict.path_length_m < straight + 0.3
