"""Every scenario of a sweep checked before the first run starts: a goal inside a box
or outside the arena, a scene that does not load, a run too costly for its budget
would otherwise surface as "error" runs after the others had run. So would the user's
nodes that cannot be built or wired (issue 41: one line, exit 2, as ``otonav run``)."""

from __future__ import annotations

from collections.abc import Sequence

from otonav.hal import BoxObstacle
from otonav.hal.mujoco import SceneError
from otonav.runtime import System
from otonav.scenario import ScenarioConfig
from otonav.scenario._assembly import effective_stack
from otonav.scenario._validate import check_cost, check_goal
from otonav.stack import StackConfig, build_actors, build_world
from otonav.stack._files import ConfigFileError
from otonav.sweep._plan import RunTask

__all__ = ["check_tasks"]

_Scene = tuple[tuple[BoxObstacle, ...], tuple[BoxObstacle, ...]]


def check_tasks(tasks: Sequence[RunTask]) -> list[str]:
    """One line per bad scenario of the plan, naming its file (or name) and the key;
    empty when every run can start. Each scene is loaded once; generated worlds are
    valid by construction and not checked again."""
    problems: dict[str, str] = {}
    scenes: dict[str, _Scene | str] = {}
    launches: set[str] = set()
    for task in tasks:
        if task.stack_json not in launches:  # the user's nodes built and wired once
            launches.add(task.stack_json)
            _check_launch(StackConfig.model_validate_json(task.stack_json))
        where = task.source or task.scenario
        if not task.scenario_json or where in problems:
            continue
        scenario = ScenarioConfig.model_validate_json(task.scenario_json)
        stack = effective_stack(scenario, StackConfig.model_validate_json(task.stack_json))
        scene = stack.world.scene
        if scene not in scenes:
            scenes[scene] = _load_scene(stack)
        loaded = scenes[scene]
        if isinstance(loaded, str):
            problems[where] = f"{where}: scene: {loaded}"
            continue
        obstacles = loaded[0] + tuple(box.to_obstacle() for box in scenario.obstacles)
        try:
            check_goal(scenario, scene, obstacles, loaded[1], source=where)
            check_cost(scenario, stack, len(obstacles) + len(loaded[1]), source=where)
        except ConfigFileError as exc:
            problems[where] = str(exc)
    return list(problems.values())


def _load_scene(stack: StackConfig) -> _Scene | str:
    """The scene's own boxes (obstacles, walls), or why it does not load."""
    try:
        world = build_world(stack)
    except (SceneError, ConfigFileError) as exc:
        return str(exc)
    try:
        return world.obstacles(), world.walls()
    finally:
        world.close()


def _check_launch(stack: StackConfig) -> None:
    """Raise what ``otonav run`` would if the stack's own nodes cannot start (an
    ``__init__`` that raises, a port whose type or QoS does not match its topic): a
    :class:`~otonav.errors.UsageError`, one line, before anything runs."""
    if not stack.actors:
        return
    world = build_world(stack)
    try:
        System(build_actors(stack, world))
    finally:
        world.close()
