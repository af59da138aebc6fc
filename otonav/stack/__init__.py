"""Composition: the robot stack from its config (the launch file), and the session
that runs it (time mode, recording, one teardown: ``otonav.stack._session``).

The config models are imported here; ``build_actors``, ``build_world`` and the session
(the actors, MuJoCo, numpy) on first use, so reading a config file stays cheap (``otonav --help``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from otonav.params import BaseConfig, DwaConfig, GuardConfig, NavConfig, RatesConfig, SafetyConfig
from otonav.stack._config import StackConfig, WorldConfig
from otonav.stack._files import ConfigFileError, describe_validation_error, to_json
from otonav.stack._overrides import apply_overrides

if TYPE_CHECKING:
    from otonav.stack._build import build_actors, build_world
    from otonav.stack._loading import load_stack_file
    from otonav.stack._session import StackSession

__all__ = (
    "BaseConfig",
    "ConfigFileError",
    "DwaConfig",
    "GuardConfig",
    "NavConfig",
    "RatesConfig",
    "SafetyConfig",
    "StackConfig",
    "StackSession",
    "WorldConfig",
    "apply_overrides",
    "build_actors",
    "build_world",
    "describe_validation_error",
    "load_stack_file",
    "to_json",
)

_LAZY = {
    "build_actors": "otonav.stack._build",
    "build_world": "otonav.stack._build",
    "load_stack_file": "otonav.stack._loading",
    "StackSession": "otonav.stack._session",
}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
