"""Composition: the robot stack from its config (the launch file).

The config models are imported here; ``build_actors`` and ``build_world`` (the actors,
MuJoCo, numpy) on first use, so reading a config file stays cheap (``otonav --help``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

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

if TYPE_CHECKING:
    from otonav.stack.build import build_actors, build_world

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

_LAZY = {"build_actors": "otonav.stack.build", "build_world": "otonav.stack.build"}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
