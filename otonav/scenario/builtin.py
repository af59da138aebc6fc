"""Built-in scenarios (defaults in code, so an installed wheel has them)."""

from __future__ import annotations

from otonav.scenario.config import GoalSpec, ScenarioConfig

BUILTIN: dict[str, ScenarioConfig] = {
    "acceptance": ScenarioConfig(),
    "empty": ScenarioConfig(name="empty", scene="empty", goal=GoalSpec(x=3.0, y=-1.0)),
}
"""name -> scenario. ``acceptance`` is the gate's scenario (obstacle scene, goal (4, 1.5))."""


def describe(name: str) -> str:
    s = BUILTIN[name]
    return (
        f"scene {s.scene or 'of the stack (obstacles)'}, "
        f"goal ({s.goal.x:g}, {s.goal.y:g}) within {s.goal_tolerance:g} m, "
        f"{s.sim_budget:g} s budget, clearance {s.min_clearance:g} m"
    )
