"""Layer 0: every MJCF compiles and every file in config/ validates."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.hal.mujoco import compile_scene, scene_names
from otonav.scenario import ScenarioConfig
from otonav.scenario._builtin import BUILTIN
from otonav.stack import StackConfig
from otonav.stack._files import load_model

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("scene", scene_names())
def test_every_builtin_scene_compiles(scene: str) -> None:
    compile_scene(scene)


def test_stack_config_file_validates_and_matches_the_code_defaults() -> None:
    # config/stack.yaml documents the defaults: drift between the two is a bug.
    assert load_model(ROOT / "config" / "stack.yaml", StackConfig) == StackConfig()


@pytest.mark.parametrize(
    "path", sorted((ROOT / "config" / "scenarios").glob("*.yaml")), ids=lambda p: p.name
)
def test_every_scenario_file_validates(path: Path) -> None:
    load_model(path, ScenarioConfig)


def test_acceptance_scenario_file_is_the_built_in_default() -> None:
    path = ROOT / "config" / "scenarios" / "acceptance.yaml"
    assert load_model(path, ScenarioConfig) == ScenarioConfig()


@pytest.mark.parametrize("name", [n for n in BUILTIN if n not in ("acceptance", "empty")])
def test_every_built_in_course_has_its_file_and_they_agree(name: str) -> None:
    # The wheel ships the code; config/scenarios/NAME.yaml documents it and can be edited
    # into a variant: drift between the two is a bug.
    path = ROOT / "config" / "scenarios" / f"{name}.yaml"
    assert load_model(path, ScenarioConfig) == BUILTIN[name]
