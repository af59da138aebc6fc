"""The navigation settings are written once (issue 31): the stack's ``nav.dwa``,
``nav.map``, ``nav.recovery`` sections default to the nav dataclasses' values, and
every field reaches the navigator by name."""

from __future__ import annotations

import dataclasses
import functools
from typing import Any

import pytest

from otonav.actors import Navigator
from otonav.hal._fake import FakeHardware
from otonav.params import CONFIG_KEYS, DwaParams, GoToGoalParams, NavigationParams, SafetyParams
from otonav.stack import StackConfig, build_actors
from otonav.stack._build import navigation_params, safety_params
from otonav.stack._overrides import apply_overrides

pytestmark = pytest.mark.unit

_MAP = {"half_size": "map_half_size", "resolution": "map_resolution"}


def test_the_default_stack_gives_the_nav_defaults_but_for_the_derived_fields() -> None:
    config = StackConfig()
    params = navigation_params(config, FakeHardware().geometry)
    derived = {"radius", "period", "max_accel", "max_alpha"}  # footprint, rate, base
    expected_dwa = dataclasses.replace(
        DwaParams(), **{name: getattr(params.dwa, name) for name in derived}
    )
    assert params == dataclasses.replace(NavigationParams(), dwa=expected_dwa)
    assert safety_params(config, FakeHardware().geometry).scales == SafetyParams().scales


@pytest.mark.parametrize("section", ["dwa", "map", "recovery"])
def test_every_field_of_a_section_reaches_the_navigator(section: str) -> None:
    model = getattr(StackConfig().nav, section)
    changes: list[str] = []
    for name, value in model.model_dump().items():
        if isinstance(value, bool):
            new: object = not value
        elif isinstance(value, int):
            new = value + 1
        else:
            new = round(value * 0.9, 6)  # smaller: stays within the speed limits
        changes.append(f"nav.{section}.{name}={new}")
    config = apply_overrides(StackConfig(), changes)
    params = navigation_params(config, FakeHardware().geometry)
    target = params.dwa if section == "dwa" else params
    for name, value in getattr(config.nav, section).model_dump().items():
        assert getattr(target, _MAP.get(name, name)) == value, name


DERIVED = {
    GoToGoalParams: {"max_v", "max_omega"},  # the robot's speeds, within the base's
    DwaParams: {"max_v", "max_omega", "max_accel", "max_alpha"},  # and what it reaches
    SafetyParams: {"radius"},  # the footprint's
    NavigationParams: {"progress_window", "backup_speed", "follow_speed", "spin_speed"},
}
"""Fields with a config key that stack.build derives (the key only bounds a live value)."""


def _changed(value: Any) -> Any:
    return (
        not value
        if isinstance(value, bool)
        else value + 1
        if isinstance(value, int)
        else 0.9 * value
    )


def _built(config: StackConfig) -> dict[type, Any]:
    hal = FakeHardware()
    try:
        nav = navigation_params(config, hal.geometry)
        stop = next(a for a in build_actors(config, hal) if isinstance(a, Navigator))
        return {
            NavigationParams: nav,
            DwaParams: nav.dwa,
            SafetyParams: safety_params(config, hal.geometry),
            GoToGoalParams: stop.params,
        }
    finally:
        hal.close()


@pytest.mark.parametrize("cls", list(CONFIG_KEYS), ids=lambda cls: cls.__name__)
def test_the_build_reads_each_field_from_the_key_the_live_view_bounds_it_by(cls: type) -> None:
    """One table for both (issue 36): a field the live parameters bound by a config key
    is built from that key, but for the derived ones."""
    keys = {name: key for name, key in CONFIG_KEYS[cls].items() if name not in DERIVED[cls]}
    config = StackConfig.model_validate({"nav": {"planner": "stop"}})

    def read(key: str) -> Any:
        return functools.reduce(getattr, key.split("."), config)

    config = apply_overrides(config, [f"{key}={_changed(read(key))!r}" for key in keys.values()])
    built = _built(config)[cls]
    assert {name: getattr(built, name) for name in keys} == {
        name: read(key) for name, key in keys.items()
    }
