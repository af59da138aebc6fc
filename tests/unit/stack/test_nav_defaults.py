"""The navigation settings are written once (issue 31): the stack's ``nav.dwa``,
``nav.map``, ``nav.recovery`` sections default to the nav dataclasses' values, and
every field reaches the navigator by name."""

from __future__ import annotations

import dataclasses

import pytest

from otonav.hal.fake import FakeHardware
from otonav.nav.dwa import DwaParams
from otonav.nav.navigation import NavigationParams
from otonav.nav.safety import SafetyParams
from otonav.stack import StackConfig
from otonav.stack.build import navigation_params, safety_params
from otonav.stack.overrides import apply_overrides

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
