"""Scenario and stack config from what a user typed: a built-in name or a YAML path,
a config file, ``--set`` overrides. Each problem is a ``ConfigFileError`` naming
``source`` (the CLI flag, or whatever the caller's users typed)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from otonav.scenario._builtin import BUILTIN
from otonav.scenario._config import ScenarioConfig
from otonav.stack._config import StackConfig
from otonav.stack._files import ConfigFileError, load_model
from otonav.stack._launch import add_actors, check_actors
from otonav.stack._loading import load_stack_file
from otonav.stack._overrides import apply_overrides


def load_scenario(spec: str, *, source: str = "--scenario") -> ScenarioConfig:
    """A built-in scenario by name, or a scenario YAML file."""
    if spec in BUILTIN:
        return BUILTIN[spec]
    path = Path(spec)
    if path.suffix in (".yaml", ".yml") or path.exists():
        return load_model(path, ScenarioConfig)
    raise ConfigFileError(
        f"{source} {spec!r}: not a built-in scenario ({', '.join(BUILTIN)}) nor a YAML file"
    )


def load_stack(
    config: Path | None, overrides: list[str], actors: Sequence[str] = ()
) -> StackConfig:
    """The built-in stack config, or ``config`` (YAML; its relative paths resolved
    against its folder), with ``--actor`` nodes added and ``--set`` overrides applied;
    every launched actor's class imported and its parameters validated."""
    stack = load_stack_file(config) if config is not None else StackConfig()
    if actors:
        stack = add_actors(stack, actors)
    if overrides:
        stack = apply_overrides(stack, overrides)
    check_actors(stack.actors)
    return stack
