"""One key for the top speed (issue 42): ``robot.max_v`` / ``robot.max_omega`` set what
the base and the navigator use, up or down; a lower key set away from its default lowers
them, with a warning."""

from __future__ import annotations

import warnings

import pytest

from otonav.stack import StackConfig
from otonav.stack._build import navigation_params
from otonav.stack._overrides import apply_overrides
from otonav.stack._robot import nav_speeds, robot_base

pytestmark = pytest.mark.unit


def _stack(*sets: str) -> StackConfig:
    return apply_overrides(StackConfig(), list(sets))


def test_robot_max_v_raises_the_base_and_the_navigator() -> None:
    stack = _stack("robot.max_v=2.0", "robot.max_omega=4.0")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no lower key set: no warning
        base = robot_base(stack)
        assert (base.max_v, base.max_omega) == (2.0, 4.0)
        assert nav_speeds(stack) == (2.0, 4.0)


def test_robot_max_v_lowers_them_too() -> None:
    stack = _stack("robot.max_v=0.3")
    assert robot_base(stack).max_v == 0.3
    assert nav_speeds(stack) == (0.3, StackConfig().nav.max_omega)


def test_without_a_stated_top_speed_the_sections_keep_their_own() -> None:
    stack = StackConfig()
    assert robot_base(stack).max_v == stack.base.max_v
    assert nav_speeds(stack) == (stack.nav.max_v, stack.nav.max_omega)


def test_a_lower_key_lowers_it_with_a_warning() -> None:
    stack = _stack("robot.max_v=2.0", "nav.max_v=1.5")
    with pytest.warns(UserWarning, match=r"nav\.max_v 1\.5 overrides robot\.max_v 2"):
        assert nav_speeds(stack)[0] == 1.5
    stack = _stack("robot.max_v=2.0", "base.max_v=3.0")
    with pytest.warns(UserWarning, match=r"base\.max_v 3 overrides robot\.max_v 2 \(capped"):
        assert robot_base(stack).max_v == 2.0


def test_the_dwa_gets_the_robot_top_speed() -> None:
    from otonav.hal import RobotGeometry

    geometry = RobotGeometry(0.05, 0.22, 0.06, 0.09)
    params = navigation_params(_stack("robot.max_v=2.0"), geometry)
    assert params.dwa.max_v == 2.0
