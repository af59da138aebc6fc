"""Scenarios: run the stack toward a goal and judge it from ground truth.

The config models are imported here; the runner and the judge (the whole stack, MuJoCo,
numpy) are imported on first use, so reading a scenario file or listing the built-ins
stays cheap (``otonav scenarios``, ``otonav --help``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from otonav.scenario._builtin import BUILTIN
from otonav.scenario._config import BoxSpec, Coordinate, GoalSpec, ScenarioConfig, StartSpec

if TYPE_CHECKING:
    from otonav.scenario._generator import (
        DENSE,
        SPARSE,
        GeneratedWorld,
        WorldParams,
        generate_world,
        generate_worlds,
        walled_in,
    )
    from otonav.scenario._judge import Judge
    from otonav.scenario._run import run_scenario
    from otonav.scenario._validate import check_goal
    from otonav.scenario._verdict import Verdict

__all__ = (
    "BUILTIN",
    "DENSE",
    "SPARSE",
    "BoxSpec",
    "Coordinate",
    "GeneratedWorld",
    "GoalSpec",
    "Judge",
    "ScenarioConfig",
    "StartSpec",
    "Verdict",
    "WorldParams",
    "check_goal",
    "generate_world",
    "generate_worlds",
    "run_scenario",
    "walled_in",
)

_LAZY = {
    "DENSE": "otonav.scenario._generator",
    "SPARSE": "otonav.scenario._generator",
    "GeneratedWorld": "otonav.scenario._generator",
    "WorldParams": "otonav.scenario._generator",
    "generate_world": "otonav.scenario._generator",
    "generate_worlds": "otonav.scenario._generator",
    "walled_in": "otonav.scenario._generator",
    "Judge": "otonav.scenario._judge",
    "Verdict": "otonav.scenario._verdict",
    "run_scenario": "otonav.scenario._run",
    "check_goal": "otonav.scenario._validate",
}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
