"""Which planner runs and whether the safety layer does are the stack config's, one
setting each (ADR 0055): ``nav.planner: external`` keeps the safety layer."""

from __future__ import annotations

import pytest

from otonav.actors import SafetyLayer
from otonav.hal._fake import FakeHardware
from otonav.runtime import Actor
from otonav.stack import StackConfig, build_actors

pytestmark = pytest.mark.unit

EXTERNAL = StackConfig.model_validate({"nav": {"planner": "external"}})


def _kinds(actors: list[Actor]) -> list[str]:
    return [type(a).__name__ for a in actors]


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
