"""A running robot stack for async tests, in sim time (or paced to the wall clock)."""

from __future__ import annotations

from collections.abc import AsyncIterator, Sequence
from contextlib import asynccontextmanager
from pathlib import Path

from otonav.engine import LiveStack, open_live_stack
from otonav.hal import BoxObstacle
from otonav.runtime import Actor, TimeMode, Virtual
from otonav.stack import StackConfig
from otonav.stack._loading import load_stack_file


@asynccontextmanager
async def running_stack(
    config: StackConfig | Path | str = StackConfig(),
    *,
    extra_actors: Sequence[Actor] = (),
    extra_obstacles: Sequence[BoxObstacle] = (),
    time: TimeMode = Virtual(),
    record_to: Path | None = None,
) -> AsyncIterator[LiveStack]:
    """Bring up the stack ``config`` launches (world, bridge, base, the planner
    ``nav.planner`` names, the safety layer unless ``safety.enabled: false``, its
    ``actors``, and its ``foxglove``/``ros2`` sections) for the body of an ``async with``:
    :func:`otonav.engine.open_live_stack` (see there) with virtual time as its default and
    a config file accepted. It yields the same :class:`~otonav.engine.LiveStack`
    (``stack.system``, ``stack.hal`` for ground truth, ``stack.publish_goal``,
    ``stack.subscribe``, ``stack.ros2``, ``stack.foxglove``).

    On a :class:`VirtualTimeLoop` (``@pytest.mark.sim``) the world becomes the loop's time
    source: sim time is loop time (with ``ros2.lockstep`` your ROS 2 nodes run in it, ADR
    0065); on exit the loop gets its previous time source back, so the test can go on
    sleeping. ``config`` is a :class:`StackConfig` or the path of the file ``otonav run
    --config`` takes. To drive the robot yourself, say so there: ``nav.planner:
    external`` (your node publishes /cmd_vel_nav, behind the safety layer), plus
    ``safety.enabled: false`` to publish /cmd_vel straight to the base.
    """
    if not isinstance(config, StackConfig):
        config = load_stack_file(config)
    async with open_live_stack(
        config,
        time=time,
        record_to=record_to,
        extra_actors=extra_actors,
        extra_obstacles=extra_obstacles,
    ) as stack:
        yield stack
