"""Live parameter sets pass the config's bounds (issue 41): what ``--set`` refuses, a
Foxglove client or a ROS 2 parameter client cannot set either, and a value no config key
bounds is read-only while the robot runs."""

from __future__ import annotations

import math
from typing import Any

import pytest

from otonav.actors import AvoidingNavigator, Navigator, SafetyLayer
from otonav.nav import GoToGoalParams, NavigationParams, SafetyParams
from otonav.params import CONFIG_KEYS
from otonav.stack import StackConfig
from otonav.stack._files import ConfigFileError
from otonav.stack._live_parameters import ActorParameters, ParameterError
from otonav.stack._overrides import apply_overrides

pytestmark = pytest.mark.unit


def _table() -> ActorParameters:
    return ActorParameters(
        [
            SafetyLayer(SafetyParams(), laser_offset_x=0.0),
            AvoidingNavigator(NavigationParams(), laser_offset_x=0.0, name="dwa"),
            Navigator(GoToGoalParams(), name="stop"),
        ]
    )


@pytest.mark.parametrize(
    ("name", "value", "key"),
    [
        ("safety.params.scales", 100_000_000, "safety.scales"),
        ("safety.params.scales", 1e8, "safety.scales"),
        ("safety.params.scales", 10**400, "safety.scales"),
        ("safety.params.scales", 1, "safety.scales"),
        ("safety.params.max_accel", 1e308, "base.max_accel"),
        ("safety.params.radius", 6.0, "safety.clearance"),
        ("dwa.params.dwa.max_v", 11.0, "base.max_v"),
        ("dwa.params.dwa.w_heading", 101.0, "nav.dwa.w_heading"),
        ("dwa.params.dwa.latency", math.inf, "nav.dwa.latency"),
        ("stop.params.max_v", math.nan, "base.max_v"),
        ("stop.params.kp_lin", -1.0, "nav.kp_lin"),
        ("stop.params.kp_lin", 10**400, "nav.kp_lin"),
    ],
)
def test_what_set_refuses_a_live_set_refuses_and_the_old_value_stays(
    name: str, value: Any, key: str
) -> None:
    table = _table()
    before = table.values()[name]
    with pytest.raises(ParameterError, match=rf"the bound of {key}") as refused:
        table.set(name, value)
    assert len(str(refused.value)) < 200  # one line, whatever the client sent
    assert table.values()[name] == before
    try:  # the same value through --set is refused too (where it is representable)
        apply_overrides(StackConfig(), [f"{key}={value}"])
    except ConfigFileError:
        pass
    else:
        raise AssertionError(f"--set {key}={value} was accepted")


@pytest.mark.parametrize(
    ("name", "value", "expected"),
    [
        ("safety.params.scales", 100, 100),
        ("safety.params.scales", 8.0, 8),
        ("dwa.params.dwa.max_v", 0.2, 0.2),
        ("stop.params.kp_lin", 2, 2.0),
        ("safety.params.radius", 0.4, 0.4),
    ],
)
def test_a_value_within_the_bounds_is_taken(name: str, value: Any, expected: Any) -> None:
    table = _table()
    table.set(name, value)
    assert table.values()[name] == expected
    assert type(table.values()[name]) is type(expected)


@pytest.mark.parametrize(
    "name",
    ["safety.params.dt", "safety.params.latency", "dwa.params.map_half_size", "dwa.params.dwa.dt"],
)
def test_a_value_no_config_key_bounds_live_is_read_only(name: str) -> None:
    table = _table()
    assert not table.settable(name)
    with pytest.raises(ParameterError, match="read-only while the robot runs"):
        table.set(name, 1.0)


@pytest.mark.parametrize("value", ["fast", [1.0], {"a": 1}, True, None])
def test_a_value_that_is_not_a_number_is_refused(value: Any) -> None:
    with pytest.raises(ParameterError, match="is not a number"):
        _table().set("safety.params.scales", value)


def test_every_config_key_of_the_table_exists() -> None:
    flat = StackConfig().model_dump()
    for fields in CONFIG_KEYS.values():
        for key in fields.values():
            node: Any = flat
            for part in key.split("."):
                node = node[part]
