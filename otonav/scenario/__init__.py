"""Scenarios: run the stack toward a goal and judge it from ground truth."""

from otonav.scenario.config import BoxSpec, GoalSpec, ScenarioConfig, StartSpec
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
