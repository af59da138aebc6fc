"""The ROS 2 bridge against real Cyclone DDS (issue 25 item 2, ADR 0047): a second
participant in its own process (``ros2_peer.py``, plain cyclonedds, the ROS 2 types
written out by hand) subscribes to rt/odom, rt/scan, rt/tf and rt/clock under ROS 2's
type names, decodes them with Cyclone's own deserializer, and publishes a goal on
rt/goal that the simulated robot then drives to. Without the bridge's input the robot
never moves (no other goal exists), so a broken bridge fails here."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import anyio
import pytest
from dds_domain import exclusive_domain

from otonav.embed import open_live_stack
from otonav.ros2 import Ros2Bridge
from otonav.runtime import RealTime, until
from otonav.stack import StackConfig
from otonav.stack._config import Ros2Config

pytestmark = pytest.mark.smoke

PEER = Path(__file__).with_name("ros2_peer.py")
CEILING = 60.0
"""Wall seconds: a hang, never a timing assertion."""
GOAL = (1.0, 0.3)


@pytest.mark.parametrize("way", ["extra_actor", "embedding_option"])
@pytest.mark.asyncio
async def test_a_ros2_node_reads_odom_and_sends_a_goal_that_is_reached(way: str) -> None:
    with exclusive_domain() as domain:
        await _reads_odom_and_sends_a_goal(way, domain)


async def _reads_odom_and_sends_a_goal(way: str, domain: int) -> None:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CYCLONEDDS"))}
    peer = subprocess.Popen(  # noqa: ASYNC220 (started once, before the stack; not awaited)
        [sys.executable, str(PEER), str(domain), str(GOAL[0]), str(GOAL[1]), "40"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        stack = StackConfig.model_validate({"nav": {"planner": "stop"}})
        if way == "extra_actor":
            bridge = Ros2Bridge(Ros2Config(domain_id=domain), env=env)
            extra: tuple[Ros2Bridge, ...] = (bridge,)
        else:  # the embedding API's own option, from the stack config's ros2 section
            stack = stack.model_copy(
                update={
                    "ros2": stack.ros2.model_copy(update={"domain_id": domain, "enabled": True})
                }
            )
            extra = ()
        with anyio.fail_after(CEILING):
            async with open_live_stack(stack, time=RealTime(4.0), extra_actors=extra) as live:
                if way == "embedding_option":
                    assert isinstance(live.ros2, Ros2Bridge)
                    bridge = live.ros2
                assert bridge.discovery.localhost

                def distance() -> float:
                    truth = live.hal.ground_truth()
                    return float(((truth.x - GOAL[0]) ** 2 + (truth.y - GOAL[1]) ** 2) ** 0.5)

                start = distance()
                await until(
                    lambda: bridge.received >= 1,
                    within=60.0,
                    clock=live.clock,
                    what="the goal from the ROS 2 node arrived",
                )
                taken = live.now()
                await until(
                    lambda: distance() < 0.15,
                    within=15.0,
                    clock=live.clock,
                    what="the robot reached the ROS 2 node's goal",
                )
                trip = live.now() - taken
                # The node says so from /odom, which may lag ground truth: keep the stack
                # up until it has (it exits then), or it may never see the arrival.
                await until(
                    lambda: peer.poll() is not None,
                    within=60.0,
                    clock=live.clock,
                    what="the ROS 2 node saw the robot arrive",
                )
                stats = bridge.statistics()
        out, err = await anyio.to_thread.run_sync(lambda: peer.communicate(timeout=30))
    finally:
        if peer.poll() is None:
            peer.kill()
            peer.wait()
    assert start > 1.0, "the robot started away from the goal"
    assert 1.0 < trip < 15.0, f"drove {start:.2f} m in {trip:.2f} s of sim time"
    assert stats.sent > 0, stats
    assert stats.rejected == 0, stats
    assert peer.returncode == 0, err
    report = json.loads(out.strip().splitlines()[-1])
    assert report["sent_goal"], report
    assert report["reached"], report
    assert all(report["counts"][name] > 0 for name in ("odom", "scan", "tf", "clock")), report
    odom = report["odom"]
    assert (odom["frame_id"], odom["child_frame_id"]) == ("odom", "base_link")
    assert (report["scan_beams"], report["scan_frame"]) == (360, "laser")
    assert "base_link" in report["tf_children"]
    assert report["clock"] > 1.0
