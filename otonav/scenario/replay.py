"""Pictures and facts from a recording alone (the forensic artifact): the path from
/odom, and the recorded verdict."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from otonav.actors import topics
from otonav.hal import BoxObstacle
from otonav.hal.mujoco import SceneError
from otonav.record.reader import read_messages, summarize
from otonav.scenario.config import ScenarioConfig
from otonav.scenario.plot import plot_trajectory
from otonav.scenario.run import effective_stack
from otonav.stack import StackConfig, build_world


def recorded_path(recording: Path) -> list[tuple[float, float, float]]:
    """(sim time, x, y) of every /odom message."""
    return [
        (t, m.pose.pose.position.x, m.pose.pose.position.y)
        for _topic, t, m in read_messages(recording, [topics.ODOM])
    ]


def recorded_verdict(recording: Path) -> dict[str, Any] | None:
    """The verdict figures stored in the recording's metadata, if any."""
    meta = summarize(recording).metadata.get("otonav", {})
    return json.loads(meta["verdict"]) if "verdict" in meta else None


def plot_recording(recording: Path, png: Path | None = None) -> Path:
    """Draw the recorded path (odometry), the goal and the extra obstacles of the
    recorded scenario into ``png`` (default: next to the recording)."""
    meta = summarize(recording).metadata.get("otonav", {})
    scenario = (
        ScenarioConfig.model_validate_json(meta["scenario_config"])
        if "scenario_config" in meta
        else None
    )
    obstacles: tuple[BoxObstacle, ...] = ()
    goal = (0.0, 0.0)
    tolerance = 0.15
    if scenario is not None:
        goal, tolerance = (scenario.goal.x, scenario.goal.y), scenario.goal_tolerance
        extra = [b.to_obstacle() for b in scenario.obstacles]
        try:
            world = build_world(effective_stack(scenario, StackConfig()), extra_obstacles=extra)
        except (SceneError, OSError):  # the scene file moved: draw what the file says
            obstacles = tuple(extra)
        else:
            obstacles = world.obstacles() + world.walls()
            world.close()
    target = png or recording.with_suffix(".png")
    if target.suffix.lower() != ".png":  # matplotlib would append it: say the real name
        target = target.with_name(target.name + ".png")
    return plot_trajectory(
        target,
        recorded_path(recording),
        obstacles,
        goal,
        tolerance,
        None,
        f"{recording.name} (odometry)",
    )
