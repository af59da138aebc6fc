"""Layer 3: software in the loop. The robot reaches the goal within 0.15 m inside 20 s
of sim time, arrives (2 s later it is still there, stopped, and the navigator says
``reached``) and never comes closer than 0.3 m to an obstacle (ground truth)."""

from __future__ import annotations

import math

import pytest

from otonav.actors import topics
from otonav.msgs import Twist
from otonav.runtime import Actor, Output
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
    # The run went on ~2 s past the first entry to check the robot had stopped there.
    assert verdict.sim_time_s == pytest.approx(verdict.time_to_goal_s + 2.0, abs=0.02)


class Ram(Actor):
    """Sabotage: full speed ahead on /cmd_vel at 200 Hz, drowning the navigator's 20 Hz."""

    cmd = Output(topics.CMD_VEL, Twist, topics.COMMAND_QOS)

    def __init__(self) -> None:
        super().__init__("ram")

    async def run(self) -> None:
        rate = self.clock.rate(200.0)
        while True:
            await self.cmd.publish(Twist.planar(0.5, 0.0))
            await rate.sleep()


def test_gate_has_teeth_driving_through_the_goal_fails() -> None:
    """A robot that drives through the goal at full speed enters the tolerance but does
    not arrive. (The gate used to stop at the first sample within 0.15 m: this passed.)"""
    scenario = ScenarioConfig(name="drive_through", scene="empty", goal=GoalSpec(x=3.0, y=0.0))
    verdict = run_scenario(scenario, extra_actors=(Ram(),), wall_ceiling=120)
    assert verdict.time_to_goal_s is not None  # it did pass within 0.15 m of the goal
    assert not verdict.reached
    assert not verdict.passed
    assert "had not arrived 2 s later" in verdict.reason
    assert "m from the goal" in verdict.reason
    assert "moving at 0.5" in verdict.reason
    assert "/nav/state" in verdict.reason
    assert verdict.final_distance_m > 0.5


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
