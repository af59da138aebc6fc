"""Arrival, not a fly-by (issue 16, item 1): 2 s after first entering the tolerance the
robot must still be within it, stopped (true speed), with /nav/state ``reached``; each
condition alone fails the arrival."""

from __future__ import annotations

import pytest

from otonav.hal import FakeHardware, GroundTruth
from otonav.scenario import Judge

pytestmark = pytest.mark.unit

GOAL = (2.0, 0.0)


class _Truth(FakeHardware):
    """A world whose ground truth the test sets."""

    def __init__(self) -> None:
        super().__init__()
        self.truth = GroundTruth(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

    def ground_truth(self) -> GroundTruth:
        return self.truth


def _at(x: float, speed: float) -> GroundTruth:
    return GroundTruth(x, 0.0, 0.0, 0.0, 0.0, speed, 0.0)


def _judge(
    end_x: float, end_speed: float, end_state: str, *, nav_must_say_reached: bool = True
) -> Judge:
    hal = _Truth()
    judge = Judge(hal, GOAL, 0.15, nav_must_say_reached=nav_must_say_reached)
    hal.truth = _at(1.9, 0.5)  # enters the tolerance (0.10 m) at 5 s, at full speed
    judge.sample(5.0)
    assert judge.entered
    assert not judge.finished  # entering is not arriving
    hal.truth = _at(end_x, end_speed)
    judge.nav_state = end_state
    judge.sample(6.99)
    assert not judge.finished  # still settling
    judge.sample(7.0)
    assert judge.finished
    return judge


def test_stopped_within_tolerance_and_reached_arrives() -> None:
    judge = _judge(1.95, 0.0, "reached")
    assert judge.reached
    assert judge.arrival_problem is None
    assert judge.time_to_goal == 5.0


@pytest.mark.parametrize(
    ("end_x", "end_speed", "end_state", "problem"),
    [
        (2.5, 0.0, "reached", "0.500 m from the goal"),  # overshot and stopped there
        (1.95, 0.3, "reached", "moving at 0.30 m/s"),  # still rolling
        (1.95, 0.0, "driving", "/nav/state 'driving'"),  # the navigator never said so
    ],
)
def test_each_condition_alone_fails_the_arrival(
    end_x: float, end_speed: float, end_state: str, problem: str
) -> None:
    judge = _judge(end_x, end_speed, end_state)
    assert not judge.reached
    assert judge.arrival_problem is not None
    assert problem in judge.arrival_problem
    assert "entered the goal tolerance at 5.00 s" in judge.arrival_problem


def test_an_external_planner_arrives_on_ground_truth_alone() -> None:
    """nav.planner: external (issue 37): a ROS 2 planner publishes no NavState, so a robot
    stopped within the tolerance arrives whatever /nav/state says (nobody publishes it)."""
    judge = _judge(1.95, 0.0, "starting", nav_must_say_reached=False)
    assert judge.reached, judge.arrival_problem


@pytest.mark.parametrize(
    ("end_x", "end_speed", "problem"),
    [(2.5, 0.0, "0.500 m from the goal"), (1.95, 0.3, "moving at 0.30 m/s")],
)
def test_an_external_planner_still_has_to_stop_within_the_tolerance(
    end_x: float, end_speed: float, problem: str
) -> None:
    judge = _judge(end_x, end_speed, "starting", nav_must_say_reached=False)
    assert not judge.reached
    assert judge.arrival_problem is not None
    assert problem in judge.arrival_problem
    assert "/nav/state" not in judge.arrival_problem
