"""Composition: the robot stack from its config (the launch file)."""

from otonav.stack.build import build_actors, build_world
from otonav.stack.config import (
    BaseConfig,
    GuardConfig,
    NavConfig,
    RatesConfig,
    SafetyConfig,
    StackConfig,
    WorldConfig,
)

__all__ = (
    "BaseConfig",
    "GuardConfig",
    "NavConfig",
    "RatesConfig",
    "SafetyConfig",
    "StackConfig",
    "WorldConfig",
    "build_actors",
    "build_world",
)
