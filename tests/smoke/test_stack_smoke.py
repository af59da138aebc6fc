"""Layer 2: the stack comes up, /clock /odom /imu /scan arrive, /cmd_vel moves the robot."""

from __future__ import annotations

import asyncio
import time
from typing import Any

import anyio
import pytest

from otonav.actors import topics
from otonav.msgs import Clock, Imu, LaserScan, Odometry, Twist
from otonav.runtime import RealTime, Subscription, TimeMode, Virtual, until
from otonav.stack import StackConfig
from otonav.testing import running_stack

pytestmark = pytest.mark.smoke

#: The robot driven straight through /cmd_vel: no planner, no safety layer, said in the
#: config (``navigator=False`` meant this until ADR 0055; it now keeps the safety layer).
BASE_ONLY = StackConfig.model_validate(
    {"nav": {"planner": "external"}, "safety": {"enabled": False}}
)

SENSORS: dict[str, type[Any]] = {
    topics.CLOCK: Clock,
    topics.ODOM: Odometry,
    topics.IMU: Imu,
    topics.SCAN: LaserScan,
}


async def _drive_and_watch(time: TimeMode, within: float) -> dict[str, int]:
    counts = dict.fromkeys(SENSORS, 0)
    last_odom: list[Odometry] = []
    async with running_stack(BASE_ONLY, time=time) as stack:
        system = stack.system
        start_x = stack.hal.ground_truth().x
        subs: dict[str, Subscription[Any]] = {
            topic: system.subscribe(
                topic, kind, topics.CLOCK_QOS if topic == topics.CLOCK else topics.SENSOR_QOS
            )
            for topic, kind in SENSORS.items()
        }
        cmd_vel = system.publisher(topics.CMD_VEL, Twist, topics.COMMAND_QOS, name="test")

        async def count(topic: str) -> None:
            async for message in subs[topic]:
                counts[topic] += 1
                if isinstance(message, Odometry):
                    last_odom[:] = [message]

        async def command() -> None:
            while True:
                await cmd_vel.publish(Twist.planar(0.3, 0.0))
                await system.clock.sleep(0.1)

        def moved() -> bool:
            return (
                all(counts.values())
                and bool(last_odom)
                and last_odom[0].pose.pose.position.x > 0.1
                and stack.hal.ground_truth().x - start_x > 0.1
            )

        async with anyio.create_task_group() as tg:
            for topic in SENSORS:
                tg.start_soon(count, topic)
            tg.start_soon(command)
            await until(
                moved, within=within, observe=lambda: dict(counts), what="all sensors + moved"
            )
            tg.cancel_scope.cancel()
    return counts


@pytest.mark.sim(wall_ceiling=45)
async def test_sensors_arrive_and_cmd_vel_moves_the_robot() -> None:
    loop = asyncio.get_running_loop()
    counts = await _drive_and_watch(Virtual(), within=3.0)
    # 0.3 m/s after a 1 m/s² ramp: past 0.1 m in well under a second of sim time.
    assert loop.time() < 1.0
    assert counts[topics.ODOM] >= 50
    assert counts[topics.SCAN] >= 5


async def _realtime() -> tuple[dict[str, int], float]:
    wall = time.monotonic()
    counts = await _drive_and_watch(RealTime(1.0), within=3.0)
    return counts, time.monotonic() - wall


def test_real_time_mode_paces_the_same_stack_to_the_wall_clock() -> None:
    counts, wall = asyncio.run(_realtime())
    assert counts[topics.ODOM] >= 30
    # Paced at 1x: the ~0.6 s of sim it needs took at least that long on the wall clock.
    assert wall >= 0.4
