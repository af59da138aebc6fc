"""Composition: the robot stack from its config (the launch file)."""

from otonav.stack.build import build_actors, build_world
from otonav.stack.config import (
    BaseConfig,
    DwaConfig,
    GuardConfig,
    NavConfig,
    RatesConfig,
    SafetyConfig,
    StackConfig,
    WorldConfig,
)

__all__ = (
    "BaseConfig",
    "DwaConfig",
    "GuardConfig",
    "NavConfig",
    "RatesConfig",
    "SafetyConfig",
    "StackConfig",
    "WorldConfig",
    "build_actors",
    "build_world",
)
