"""Pictures and facts from a recording alone (the forensic artifact): the path from
/odom, and the recorded verdict."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from otonav.actors import _topics as topics
from otonav.hal import BoxObstacle
from otonav.hal.mujoco import SceneError
from otonav.record._reader import read_messages, summarize
from otonav.record._verify import Damage
from otonav.scenario._assembly import effective_stack
from otonav.scenario._config import ScenarioConfig
from otonav.scenario._plot import key_poses, plot_trajectory
from otonav.scenario._verdict import verdict_title
from otonav.stack import StackConfig, build_world
from otonav.stack._worldmeta import WORLD_METADATA, boxes_from_metadata, geometry_from_metadata


def recorded_path(
    recording: Path, damage: list[Damage] | None = None
) -> list[tuple[float, float, float]]:
    """(sim time, x, y) of every /odom message (``damage``: see ``read_messages``)."""
    return [
        (t, m.pose.pose.position.x, m.pose.pose.position.y)
        for _topic, t, m in read_messages(recording, [topics.ODOM], damage=damage)
    ]


def recorded_goal(
    recording: Path, damage: list[Damage] | None = None
) -> tuple[float, float] | None:
    """The last goal published on /goal, (x, y) in the world frame; None if none was."""
    goal = None
    for _topic, _t, m in read_messages(recording, [topics.GOAL], damage=damage):
        goal = (m.pose.position.x, m.pose.position.y)
    return goal


@dataclass(frozen=True, slots=True)
class RecordedPlot:
    """What a recording alone says about its run, as the plot draws it."""

    trajectory: list[tuple[float, float, float]]
    obstacles: tuple[BoxObstacle, ...] | None
    """None: the recording does not say where they are."""
    goal: tuple[float, float] | None
    tolerance: float | None
    title: str
    truncated: bool
    damaged: tuple[Damage, ...] = ()
    """Chunks that failed their CRC: not drawn."""
    closest: tuple[float, float] | None = None
    """Where the recorded verdict says the robot came closest to an obstacle."""
    footprint: tuple[tuple[float, float], ...] = ()
    """The recorded robot's outline (base frame), drawn at the start, closest and end."""
    start_yaw: float = 0.0


def recorded_plot(recording: Path) -> RecordedPlot:
    """The path from /odom, the goal from /goal (or the scenario's), the obstacles and
    walls from the recording's ``otonav.world`` record (or, for older recordings, the
    world rebuilt from its scenario). A cut-off file gives what its complete chunks hold."""
    summary = summarize(recording)
    meta = summary.metadata.get("otonav", {})
    scenario = (
        ScenarioConfig.model_validate_json(meta["scenario_config"])
        if "scenario_config" in meta
        else None
    )
    # Damaged chunks (summary.damaged) are skipped, not drawn: the caller warns.
    damage: list[Damage] | None = [] if summary.damaged else None
    goal = recorded_goal(recording, damage)
    if goal is None and scenario is not None:
        goal = (scenario.goal.x, scenario.goal.y)
    obstacles: tuple[BoxObstacle, ...] | None = None
    if WORLD_METADATA in summary.metadata:
        obstacles = boxes_from_metadata(summary.metadata[WORLD_METADATA])
    elif scenario is not None:
        obstacles = _rebuilt_world(scenario)
    verdict = json.loads(meta["verdict"]) if "verdict" in meta else None
    closest = None
    if verdict is not None:  # the run's verdict, as `otonav run` draws it
        title = verdict_title(
            str(verdict.get("scenario", recording.name)),
            bool(verdict.get("passed")),
            str(verdict.get("reason", "")),
        )
        xy = verdict.get("closest_xy")
        closest = (float(xy[0]), float(xy[1])) if xy else None
    else:
        title = f"{recording.name} (odometry): no verdict recorded"
    if summary.truncated:
        title += ", cut off: complete chunks only"
    if summary.damaged:
        title += f", {len(summary.damaged)} damaged chunk(s) not drawn"
    geometry = geometry_from_metadata(summary.metadata.get(WORLD_METADATA, {}))
    return RecordedPlot(
        recorded_path(recording, damage),
        obstacles,
        goal,
        scenario.goal_tolerance if scenario is not None else None,
        title,
        summary.truncated,
        summary.damaged,
        closest,
        geometry.footprint if geometry is not None else (),
        scenario.start.yaw if scenario is not None else 0.0,
    )


def _rebuilt_world(scenario: ScenarioConfig) -> tuple[BoxObstacle, ...]:
    extra = [b.to_obstacle() for b in scenario.obstacles]
    try:
        world = build_world(effective_stack(scenario, StackConfig()), extra_obstacles=extra)
    except (SceneError, OSError):  # the scene file moved: draw what the scenario says
        return tuple(extra)
    try:
        return world.obstacles() + world.walls()
    finally:
        world.close()


def plot_recording(recording: Path, png: Path | None = None) -> Path:
    """Draw :func:`recorded_plot` into ``png`` (default: next to the recording)."""
    plot = recorded_plot(recording)
    target = png or recording.with_suffix(".png")
    if target.suffix.lower() != ".png":  # matplotlib would append it: say the real name
        target = target.with_name(target.name + ".png")
    return plot_trajectory(
        target,
        plot.trajectory,
        plot.obstacles,
        plot.goal,
        plot.tolerance,
        plot.closest,
        plot.title,
        path_label="path (odometry)",
        footprint=plot.footprint,
        poses=key_poses(plot.trajectory, plot.start_yaw, plot.closest),
    )
