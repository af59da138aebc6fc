"""What a judged run is made of: the scenario as run with the stack's robot, its
world (checked), the judge and the session recording to the out directory."""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from otonav import limits
from otonav.hal import RobotHardwareInterface
from otonav.hal._types import Reach
from otonav.params import NavConfig
from otonav.record._outlock import lock_output
from otonav.runtime import (
    Actor,
    System,
    TimeMode,
    Virtual,
)
from otonav.scenario._artifacts import RUN_METADATA, run_metadata
from otonav.scenario._config import ScenarioConfig
from otonav.scenario._judge import Judge
from otonav.scenario._validate import check_cost, check_goal
from otonav.stack import StackConfig, build_actors, build_world
from otonav.stack._robot import describe_robot, reached, slower
from otonav.stack._session import StackSession

BUDGET_SPEED = 0.4
"""m/s: scenario budgets are written for a robot that drives this fast (otonav's robot
under the default ``nav.max_v``). A robot whose description states a lower top speed
(``robot.max_v``; the ``burger``'s 0.22 m/s) gets every budget scaled by BUDGET_SPEED /
its top speed, so the same courses judge it fairly (ADR 0041)."""


def for_robot(
    scenario: ScenarioConfig, stack: StackConfig, reach: Reach | None = None
) -> ScenarioConfig:
    """``scenario`` as run with ``stack``'s robot: its sim budget scaled to the robot's
    stated top speed, or to the one it really reaches or its control range allows
    (``reach``, ADR 0066), when that is below :data:`BUDGET_SPEED`."""
    top = describe_robot(stack.robot).max_v
    if reach is not None:  # what it reaches, or may be asked (its control range)
        real = reach.v if slower(reach) < 1.0 else reach.asked_v
        top = min(top, real) if top is not None else real
    if top is None or top >= BUDGET_SPEED:
        return scenario
    budget = min(scenario.sim_budget * BUDGET_SPEED / top, limits.MAX_SIM_BUDGET_S)
    return scenario.model_copy(update={"sim_budget": round(budget, 3)})


def scenario_world(
    scenario: ScenarioConfig, stack: StackConfig, *, source: str
) -> tuple[ScenarioConfig, StackConfig, RobotHardwareInterface]:
    """The scenario as run with the stack's robot (:func:`for_robot`), the stack config
    with the scenario's scene, and its world with the scenario's obstacles and start
    pose, checked: a goal or start outside the arena or on an obstacle raises
    ``ConfigFileError`` naming ``source`` (the world is then closed)."""
    stack = effective_stack(scenario, stack)
    hal = build_world(
        stack,
        extra_obstacles=[b.to_obstacle() for b in scenario.obstacles],
        start=scenario.start.as_tuple(),
    )
    try:
        scenario = for_robot(scenario, stack, reached(stack, hal))
        check_goal(scenario, stack.world.scene, hal.obstacles(), hal.walls(), source=source)
        check_cost(scenario, stack, len(hal.obstacles() + hal.walls()), source=source)
    except BaseException:
        hal.close()
        raise
    return scenario, stack, hal


def effective_stack(scenario: ScenarioConfig, stack: StackConfig) -> StackConfig:
    """The stack config with the scenario's scene, if it names one, and the navigator's
    goal tolerance following the scenario's (half of it, never below ``nav.tolerance``'s
    default) unless ``nav.tolerance`` is set (issue 42, ADR 0079)."""
    updates: dict[str, Any] = {}
    if scenario.scene is not None:
        updates["world"] = stack.world.model_copy(update={"scene": scenario.scene})
    default = NavConfig().tolerance
    if stack.nav.tolerance == default and scenario.goal_tolerance / 2 > default:
        updates["nav"] = stack.nav.model_copy(update={"tolerance": scenario.goal_tolerance / 2})
    return stack.model_copy(update=updates) if updates else stack


def scenario_session(
    scenario: ScenarioConfig,
    stack: StackConfig,
    hal: RobotHardwareInterface,
    judge: Judge,
    *,
    extra_actors: tuple[Actor, ...] = (),
    time: TimeMode = Virtual(),
    recording: Path | None = None,
) -> StackSession:
    """The session of a scenario run in ``time``: the recorder (with ``recording``), the
    extra actors, the robot stack starting at the scenario's start pose, and the judge."""
    try:
        robot = build_actors(stack, hal, initial_pose=scenario.start.as_tuple())
    except BaseException:
        hal.close()
        raise
    session = StackSession(hal, [*extra_actors, *robot, judge], time=time, record_to=recording)
    if session.writer is not None:
        session.writer.add_metadata(RUN_METADATA, run_metadata(scenario, stack))
    return session


@contextlib.contextmanager
def opened_scenario(
    scenario: ScenarioConfig,
    stack: StackConfig,
    out_dir: Path | None,
    record: bool,
    source: str,
    progress: Callable[[Judge, float], None] | None,
    extra_actors: tuple[Actor, ...],
    time: TimeMode = Virtual(),
    on_system: Callable[[System], None] | None = None,
) -> Iterator[tuple[ScenarioConfig, StackConfig, RobotHardwareInterface, Judge, StackSession]]:
    """What a judged run opens, in the virtual and the real-time runner alike: the lock
    on ``out_dir`` (held until the block ends: one run per out_dir, issue 27, refused
    before it touches a file), the world, the judge and the session recording to
    ``out_dir/recording.mcap`` (with ``record``); ``on_system(system)`` is called with the
    session's wired system before it runs (the session is closed if it raises)."""
    with lock_output(out_dir) if out_dir is not None else contextlib.nullcontext():
        scenario, stack, hal = scenario_world(scenario, stack, source=source)
        judge = Judge(
            hal,
            (scenario.goal.x, scenario.goal.y),
            scenario.goal_tolerance,
            progress=progress,
            nav_must_say_reached=stack.nav.planner != "external",
            arrival=scenario.arrival,
        )
        session = scenario_session(
            scenario,
            stack,
            hal,
            judge,
            time=time,
            extra_actors=extra_actors,
            recording=out_dir / "recording.mcap" if out_dir and record else None,
        )
        if on_system is not None:
            try:
                on_system(session.system)
            except BaseException:
                session.close()
                raise
        yield scenario, stack, hal, judge, session
