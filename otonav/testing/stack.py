"""A running robot stack for async tests, in sim time (or paced to the wall clock)."""

from __future__ import annotations

from collections.abc import AsyncIterator, Sequence
from contextlib import asynccontextmanager
from dataclasses import dataclass
from pathlib import Path

from otonav.hal import BoxObstacle, RobotHardwareInterface
from otonav.runtime import Actor, System
from otonav.stack import StackConfig, build_actors, build_world
from otonav.stack.loading import load_stack_file
from otonav.stack.robot import robot_frames
from otonav.stack.session import StackSession


@dataclass(slots=True)
class RunningStack:
    """The system (subscribe, publish, graph) and the world (ground truth) of a test."""

    system: System
    hal: RobotHardwareInterface
    ros2: Actor | None = None
    """The ROS 2 bridge, when the config's ``ros2.enabled`` (ADR 0047, 0065)."""


@asynccontextmanager
async def running_stack(
    config: StackConfig | Path | str = StackConfig(),
    *,
    navigator: bool = True,
    extra_actors: Sequence[Actor] = (),
    extra_obstacles: Sequence[BoxObstacle] = (),
    realtime_scale: float | None = None,
    record_to: Path | None = None,
) -> AsyncIterator[RunningStack]:
    """Bring up the stack ``config`` launches (world, bridge, base, the planner
    ``nav.planner`` names, the safety layer unless ``safety.enabled: false``, its
    ``actors``) for the body of an ``async with``.

    On a :class:`VirtualTimeLoop` (``@pytest.mark.sim``) the world becomes the loop's time
    source: sim time is loop time. With ``realtime_scale`` set, the stack runs on the
    current (stock) loop, the world paced to the wall clock times that scale. With
    ``record_to`` every topic is recorded to that MCAP file, finished on every exit.
    On exit the stack is torn down as every runner's is (:mod:`otonav.stack.session`):
    the loop gets its previous time source back, so the test can go on sleeping.

    ``config`` is a :class:`StackConfig` or the path of a stack config file: the same
    file ``otonav run --config`` takes, with its robot and its ``actors``. To drive the
    robot yourself, say so there: ``nav.planner: external`` (your node publishes
    /cmd_vel_nav, behind the safety layer), plus ``safety.enabled: false`` to publish
    /cmd_vel straight to the base. ``navigator=False`` is the deprecated spelling of
    ``nav.planner: external`` (ADR 0055).

    With ``ros2.enabled`` in the config, the ROS 2 bridge runs too (``stack.ros2``), as
    ``otonav run --ros2`` has it; with ``ros2.lockstep`` your ROS 2 nodes run in the
    test's sim time (ADR 0065).
    """
    if not isinstance(config, StackConfig):
        config = load_stack_file(config)
    hal = build_world(config, extra_obstacles=extra_obstacles)
    try:
        actors = [*build_actors(config, hal, navigator=navigator), *extra_actors]
        bridge: Actor | None = None
        if config.ros2.enabled:
            from otonav.ros2 import bridge_for

            bridge = bridge_for(config.ros2, base_frame=robot_frames(config.robot).base)
            actors.append(bridge)
    except BaseException:
        hal.close()
        raise
    session = StackSession(
        hal,
        actors,
        realtime=realtime_scale,
        record_to=record_to,
    )
    async with session.running() as system:
        yield RunningStack(system, hal, bridge)
