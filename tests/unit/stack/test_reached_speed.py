"""The navigator adapts to what the robot really reaches (issue 38, ADR 0066): the
DWA's accelerations, the progress window and the scenario budget follow the identified
figures; a robot within 5 % of the asked speed is taken at the asked one."""

from __future__ import annotations

import pytest

from otonav.hal._fake import FakeHardware
from otonav.hal._types import Reach
from otonav.scenario._assembly import for_robot
from otonav.scenario._builtin import BUILTIN
from otonav.stack import StackConfig
from otonav.stack._build import navigation_params
from otonav.stack._robot import deadband

pytestmark = pytest.mark.unit


def reach(v: float, accel: float = 5.0, alpha: float = 50.0) -> Reach:
    return Reach(
        asked_v=0.4, asked_omega=1.2, v=v, omega=1.0, accel=accel, alpha=alpha, deadband=0.8
    )


def test_a_robot_at_70_percent_gets_a_longer_progress_window_and_its_accelerations() -> None:
    config = StackConfig()
    nominal = navigation_params(config, FakeHardware().geometry)
    slow = navigation_params(config, FakeHardware().geometry, reach(0.28, accel=0.6, alpha=2.0))
    assert slow.progress_window == pytest.approx(nominal.progress_window / 0.7)
    assert (slow.dwa.max_accel, slow.dwa.max_alpha) == (0.6, 2.0)
    assert slow.dwa.max_v == nominal.dwa.max_v  # asked most, it reaches most


def test_a_robot_within_5_percent_is_taken_at_the_asked_speed() -> None:
    config = StackConfig()
    nominal = navigation_params(config, FakeHardware().geometry)
    assert navigation_params(config, FakeHardware().geometry, reach(0.385)) == nominal


def test_the_budget_follows_the_speed_really_reached() -> None:
    box = BUILTIN["box"]
    assert for_robot(box, StackConfig(), reach(0.39)).sim_budget == box.sim_budget
    assert for_robot(box, StackConfig(), reach(0.2)).sim_budget == pytest.approx(
        box.sim_budget * 0.4 / 0.2
    )


def test_a_robot_that_never_moved_is_taken_at_the_asked_figures() -> None:
    config = StackConfig()
    nominal = navigation_params(config, FakeHardware().geometry)
    assert navigation_params(config, FakeHardware().geometry, reach(0.0)) == nominal
    assert for_robot(BUILTIN["box"], config, reach(0.0)).sim_budget == BUILTIN["box"].sim_budget


def test_the_verdict_table_says_what_the_robot_reached() -> None:
    from otonav.cli._run import reach_row

    assert reach_row({"v": 0.187, "asked_v": 0.22}) == [
        ("reaches", "0.187 of 0.22 m/s asked (85%)")
    ]
    assert reach_row(None) == []


def test_the_base_carries_the_deadband_only_of_a_robot_slower_than_asked() -> None:
    assert deadband(reach(0.28)) == 0.8
    assert deadband(reach(0.39)) == 0.0  # reaches its speed: driven as before
    assert deadband(None) == 0.0
