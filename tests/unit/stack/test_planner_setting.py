"""Which planner runs and whether the safety layer does are the stack config's, one
setting each (ADR 0055): ``navigator=False`` is ``nav.planner: external`` spelled the
old way, and keeps the safety layer as that does (it used to drop it silently)."""

from __future__ import annotations

import pytest

from otonav.actors import CommandWatch, SafetyLayer
from otonav.hal.fake import FakeHardware
from otonav.runtime import Actor
from otonav.stack import StackConfig, build_actors

pytestmark = pytest.mark.unit

EXTERNAL = StackConfig.model_validate({"nav": {"planner": "external"}})


def _kinds(actors: list[Actor]) -> list[str]:
    return [type(a).__name__ for a in actors]


def test_navigator_false_is_the_external_planner_with_its_safety_layer() -> None:
    hal = FakeHardware()
    try:
        with pytest.warns(DeprecationWarning, match="nav.planner: external"):
            old = build_actors(StackConfig(), hal, navigator=False)
        new = build_actors(EXTERNAL, hal)
    finally:
        hal.close()
    assert _kinds(old) == _kinds(new)
    assert any(isinstance(a, SafetyLayer) for a in old)
    assert any(isinstance(a, CommandWatch) for a in old)  # says so if nobody drives


def test_the_safety_layer_goes_only_when_the_config_says_so() -> None:
    hal = FakeHardware()
    try:
        bare = build_actors(
            StackConfig.model_validate(
                {"nav": {"planner": "external"}, "safety": {"enabled": False}}
            ),
            hal,
        )
    finally:
        hal.close()
    assert not any(isinstance(a, SafetyLayer) for a in bare)
