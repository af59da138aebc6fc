"""Composition: the robot stack from its config (the launch file), and the session
that runs it (time mode, recording, one teardown)."""

from otonav.stack.build import build_actors, build_world
from otonav.stack.config import (
    BaseConfig,
    GuardConfig,
    NavConfig,
    RatesConfig,
    StackConfig,
    WorldConfig,
)
from otonav.stack.session import RealTime, StackSession

__all__ = (
    "BaseConfig",
    "GuardConfig",
    "NavConfig",
    "RatesConfig",
    "RealTime",
    "StackConfig",
    "StackSession",
    "WorldConfig",
    "build_actors",
    "build_world",
)
