"""Data from DDS passes the door before any actor sees it (issues 37 and 41): a goal
with x = NaN from a DDS participant is refused by the bridge with a warning on /rosout,
and the run goes on. (Before, the navigator crashed on it: ValueError in _coarse_cell.)"""

from __future__ import annotations

import math
import os

import pytest
from dds_domain import exclusive_domain

from otonav.msgs import Point, Pose, PoseStamped
from otonav.record.cdr import encode
from otonav.ros2 import Ros2Bridge, Ros2Options
from otonav.ros2.dds import Participant
from otonav.ros2.naming import dds_qos
from otonav.runtime import Actor, QoS, run_blocking
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.stack import StackConfig

pytestmark = pytest.mark.smoke

HANG = 30.0
"""Wall seconds a wait on DDS may take: a hang, never a timing assertion."""


class NanGoal(Actor):
    """At 0.5 s of sim time, a DDS participant of its own publishes a goal at x = NaN on
    rt/goal; sim time holds until the bridge's reader has it."""

    def __init__(self, peer: Participant, bridge: Ros2Bridge) -> None:
        super().__init__("nan_goal")
        self.peer = peer
        self.bridge = bridge

    async def run(self) -> None:
        await self.clock.sleep_until(0.5)
        writer = self.peer.writer("rt/goal", PoseStamped, dds_qos(QoS(depth=1), PoseStamped))
        assert await run_blocking(self.peer.wait, lambda: writer.matched.count > 0, HANG)
        writer.write(encode(PoseStamped(pose=Pose(position=Point(x=math.nan, y=1.0)))))
        (goal,) = [e for e in self.bridge._inputs if e.name == "/goal"]
        reader = goal.reader
        assert reader is not None
        arrived = await run_blocking(
            self.bridge.participant.wait, lambda: reader.arrivals > 0, HANG
        )
        assert arrived


@pytest.mark.timeout(90)
def test_a_nan_goal_from_dds_is_refused_and_the_run_goes_on() -> None:
    with exclusive_domain() as domain:
        env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CYCLONEDDS"))}
        bridge = Ros2Bridge(Ros2Options(domain_id=domain), env=env)
        peer = Participant(domain, None)  # the bridge's domain (one per process)
        try:
            verdict = run_scenario(
                ScenarioConfig(),
                StackConfig(),
                record=False,
                plot=False,
                extra_actors=(bridge, NanGoal(peer, bridge)),
            )
        finally:
            peer.close()
    assert verdict.passed, verdict.reason
    statistics = bridge.statistics()
    assert (statistics.received, statistics.rejected) == (0, 1)
