"""Scenarios: run the stack toward a goal and judge it from ground truth.

The config models are imported here; the runner and the judge (the whole stack, MuJoCo,
numpy) are imported on first use, so reading a scenario file or listing the built-ins
stays cheap (``otonav scenarios``, ``otonav --help``).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from otonav.scenario.config import BoxSpec, GoalSpec, ScenarioConfig, StartSpec

if TYPE_CHECKING:
    from otonav.scenario.judge import Judge
    from otonav.scenario.run import Verdict, drive_to_goal, run_scenario

__all__ = (
    "BoxSpec",
    "GoalSpec",
    "Judge",
    "ScenarioConfig",
    "StartSpec",
    "Verdict",
    "drive_to_goal",
    "run_scenario",
)

_LAZY = {
    "Judge": "otonav.scenario.judge",
    "Verdict": "otonav.scenario.run",
    "drive_to_goal": "otonav.scenario.run",
    "run_scenario": "otonav.scenario.run",
}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
