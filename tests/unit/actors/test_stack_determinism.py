"""Determinism: the same fake stack, run twice, says exactly the same things at exactly
the same sim instants on /cmd_vel and /odom."""

from __future__ import annotations

import hashlib
from typing import Any

import anyio
import pytest

from otonav.actors import BaseController, Bridge, Navigator, topics
from otonav.control import DiffDriveGeometry
from otonav.hal import BoxObstacle, FakeHardware
from otonav.msgs import Odometry, Twist
from otonav.runtime import QoS, Reliability, Subscription, System, virtual_loop_factory

pytestmark = pytest.mark.unit

OBSERVE = QoS(Reliability.BEST_EFFORT, depth=100_000)


def _run_stack(goal: tuple[float, float]) -> tuple[str, int, float]:
    """Run FakeHardware + bridge + base + nav for 3 s of sim time; return the sha256 of
    every (sim time, topic, message) on /cmd_vel and /odom in order of arrival, the
    number of records, and the true x reached."""
    # A box off to the side and wheels that lag: turning, guard checks, transients.
    hal = FakeHardware(obstacles=[BoxObstacle(1.0, 0.6, 0.2, 0.2)], wheel_time_constant=0.03)
    geometry = DiffDriveGeometry(hal.geometry.wheel_radius, hal.geometry.wheel_separation)
    actors = [Bridge(hal), BaseController(geometry), Navigator(goal=goal)]
    records: list[tuple[float, str, str]] = []

    async def drain(sub: Subscription[Any]) -> None:
        async for message in sub:
            # repr round-trips floats exactly: any difference in any bit shows.
            records.append((anyio.current_time(), sub.topic, repr(message)))

    async def main() -> None:
        async with System(actors) as system:
            subs = [
                system.subscribe(topics.CMD_VEL, Twist, OBSERVE),
                system.subscribe(topics.ODOM, Odometry, OBSERVE),
            ]
            async with anyio.create_task_group() as tg:
                for sub in subs:
                    tg.start_soon(drain, sub)
                await anyio.sleep(3.0 + 1e-3)  # what is published at 3.0 s is in
                tg.cancel_scope.cancel()

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(hal, wall_ceiling=10)})
    digest = hashlib.sha256(repr(records).encode()).hexdigest()
    return digest, len(records), hal.ground_truth().x


def test_two_runs_of_the_fake_stack_are_identical() -> None:
    first = _run_stack((2.0, 1.0))
    second = _run_stack((2.0, 1.0))
    _, count, x = first
    assert count == 300 + 60  # /odom at 100 Hz + /cmd_vel at 20 Hz, for 3 s
    assert x > 0.5  # the run did something worth comparing
    assert second == first


def test_the_hash_sees_a_different_run() -> None:
    # The comparison has teeth: a goal 1 cm away from the other changes the record.
    assert _run_stack((2.0, 1.0))[0] != _run_stack((2.0, 1.01))[0]
