"""A running robot stack for async tests, in sim time (or paced to the wall clock)."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator, Sequence
from contextlib import asynccontextmanager
from dataclasses import dataclass
from pathlib import Path

from otonav.actors.recorder import Recorder
from otonav.hal import BoxObstacle, RobotHardwareInterface
from otonav.hal.mujoco import Variant
from otonav.record.writer import RecordingWriter
from otonav.runtime import Actor, RealTimeClock, System, VirtualTimeLoop
from otonav.stack import StackConfig, build_actors, build_world
from otonav.stack.rosout import attach_rosout
from otonav.stack.worldmeta import WORLD_METADATA, world_metadata


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
    record_to: Path | None = None,
) -> AsyncIterator[RunningStack]:
    """Bring up world + bridge + base (+ navigator) for the body of an ``async with``.

    On a :class:`VirtualTimeLoop` (``@pytest.mark.sim``) the world becomes the loop's time
    source: sim time is loop time. With ``realtime_scale`` set, the stack runs on the
    current (stock) loop, the world paced to the wall clock times that scale. With
    ``record_to`` every topic is recorded to that MCAP file, finished on every exit.
    """
    hal = build_world(config, extra_obstacles=extra_obstacles, variant=variant)
    writer = RecordingWriter(record_to) if record_to is not None else None
    try:
        if writer is not None:  # where the obstacles are: the kept plot draws them
            writer.add_metadata(WORLD_METADATA, world_metadata(hal, config.world.scene))
        loop = asyncio.get_running_loop()
        actors: list[Actor] = [Recorder(writer)] if writer is not None else []
        actors += [*build_actors(config, hal, navigator=navigator), *extra_actors]
        if realtime_scale is not None:
            clock = RealTimeClock(hal, scale=realtime_scale, max_step_batch=0.05)
            system = System(actors, clock=clock)
        elif isinstance(loop, VirtualTimeLoop):
            loop.attach_source(hal)
            system = System(actors)
        else:
            raise RuntimeError(
                "running_stack needs a VirtualTimeLoop (mark the test @pytest.mark.sim) "
                "or realtime_scale= for real-time mode on this loop"
            )
        attach_rosout(system)
        async with system:
            yield RunningStack(system, hal)
    finally:
        if writer is not None:
            writer.finish()
        hal.close()
