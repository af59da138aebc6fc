"""A running robot stack for async tests, in sim time (or paced to the wall clock)."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator, Sequence
from contextlib import asynccontextmanager
from dataclasses import dataclass

from otonav.hal import BoxObstacle, RobotHardwareInterface
from otonav.hal.mujoco import Variant
from otonav.runtime import Actor, RealTimeClock, System, VirtualTimeLoop
from otonav.stack import StackConfig, build_actors, build_world


@dataclass(slots=True)
class RunningStack:
    """The system (subscribe, publish, graph) and the world (ground truth) of a test."""

    system: System
    hal: RobotHardwareInterface


@asynccontextmanager
async def running_stack(
    config: StackConfig = StackConfig(),
    *,
    navigator: bool = True,
    extra_actors: Sequence[Actor] = (),
    extra_obstacles: Sequence[BoxObstacle] = (),
    variant: Variant = "shipped",
    realtime_scale: float | None = None,
) -> AsyncIterator[RunningStack]:
    """Bring up world + bridge + base (+ navigator) for the body of an ``async with``.

    On a :class:`VirtualTimeLoop` (``@pytest.mark.sim``) the world becomes the loop's time
    source: sim time is loop time. With ``realtime_scale`` set, the stack runs on the
    current (stock) loop, the world paced to the wall clock times that scale.
    """
    hal = build_world(config, extra_obstacles=extra_obstacles, variant=variant)
    try:
        loop = asyncio.get_running_loop()
        if realtime_scale is not None:
            clock = RealTimeClock(hal, scale=realtime_scale)
            system = System(
                [*build_actors(config, hal, navigator=navigator), *extra_actors], clock=clock
            )
        elif isinstance(loop, VirtualTimeLoop):
            loop.attach_source(hal)
            system = System([*build_actors(config, hal, navigator=navigator), *extra_actors])
        else:
            raise RuntimeError(
                "running_stack needs a VirtualTimeLoop (mark the test @pytest.mark.sim) "
                "or realtime_scale= for real-time mode on this loop"
            )
        async with system:
            yield RunningStack(system, hal)
    finally:
        hal.close()
