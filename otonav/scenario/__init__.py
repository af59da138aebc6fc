"""Scenarios: run the stack toward a goal and judge it from ground truth."""

from otonav.scenario.config import BoxSpec, GoalSpec, ScenarioConfig
from otonav.scenario.judge import Judge
from otonav.scenario.run import Verdict, run_scenario, run_stack_scenario

__all__ = (
    "BoxSpec",
    "GoalSpec",
    "Judge",
    "ScenarioConfig",
    "Verdict",
    "run_scenario",
    "run_stack_scenario",
)
