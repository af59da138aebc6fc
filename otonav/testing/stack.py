"""A running robot stack for async tests, in sim time (or paced to the wall clock)."""

from __future__ import annotations

from collections.abc import AsyncIterator, Sequence
from contextlib import asynccontextmanager
from pathlib import Path

from otonav.engine import LiveStack, open_live_stack
from otonav.hal import BoxObstacle
from otonav.runtime import Actor, TimeMode, Virtual
from otonav.stack import StackConfig
from otonav.stack.loading import load_stack_file


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
    ``actors``) for the body of an ``async with``: :func:`otonav.engine.open_live_stack`
    with virtual time as its default and a config file accepted. It yields the same
    :class:`~otonav.engine.LiveStack` (``stack.system``, ``stack.hal`` for ground truth,
    ``stack.publish_goal``, ``stack.subscribe``).

    On a :class:`VirtualTimeLoop` (``@pytest.mark.sim``) the world becomes the loop's time
    source: sim time is loop time. With ``time=RealTime(scale)``, the stack runs on the
    current (stock) loop, the world paced to the wall clock times that scale. With
    ``record_to`` every topic is recorded to that MCAP file, finished on every exit.
    On exit the stack is torn down as every runner's is (:mod:`otonav.stack.session`):
    the loop gets its previous time source back, so the test can go on sleeping.

    ``config`` is a :class:`StackConfig` or the path of a stack config file: the same
    file ``otonav run --config`` takes, with its robot and its ``actors``. To drive the
    robot yourself, say so there: ``nav.planner: external`` (your node publishes
    /cmd_vel_nav, behind the safety layer), plus ``safety.enabled: false`` to publish
    /cmd_vel straight to the base.

    The config's optional sections run too, made as every entry point makes them
    (:func:`otonav.engine.open_extras`): with ``ros2.enabled`` the ROS 2 bridge
    (``stack.ros2``), as ``otonav run --ros2`` has it (with ``ros2.lockstep`` your ROS 2
    nodes run in the test's sim time, ADR 0065); with ``foxglove.enabled`` the Foxglove
    live view (``stack.foxglove``: watch a test as it runs, with ``wait_for_subscriber``).
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
