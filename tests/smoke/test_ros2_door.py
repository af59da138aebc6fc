"""Data from DDS passes the door before any actor sees it (issues 37 and 41): goals at
x = NaN, inf and 1e308, each from a ROS 2 participant in a process of its own
(``ros2_peer.py``, plain cyclonedds), are refused by the bridge, each logged on /rosout
with its source, and the run goes on to pass. (Before, the navigator crashed on them:
ValueError/OverflowError in ``_coarse_cell``; a NaN was refused since issue 37, 1e308
was not.)"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from dds_domain import exclusive_domain

from otonav.actors import topics
from otonav.msgs import Twist, Vector3
from otonav.record._reader import read_messages
from otonav.record.cdr import encode
from otonav.ros2 import Ros2Bridge
from otonav.runtime import Actor, run_blocking
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.stack import StackConfig
from otonav.stack._config import Ros2Config

pytestmark = pytest.mark.smoke

PEER = Path(__file__).with_name("ros2_peer.py")
FUZZ_PEER = Path(__file__).with_name("dds_fuzz_peer.py")
HANG = 30.0
"""Wall seconds a wait on DDS may take: a hang, never a timing assertion."""
BAD_X = ("nan", "inf", "1e308")


class Peers(Actor):
    """From 0.5 s of sim time, starts one peer process per goal in ``xs``, one after the
    other: sim time holds until the bridge's /goal reader has the peer's sample, then
    runs 0.2 s so that the bridge takes it (the reader keeps the last sample only)."""

    def __init__(self, bridge: Ros2Bridge, domain: int, env: dict[str, str]) -> None:
        super().__init__("peers")
        self.bridge, self.domain, self.env = bridge, domain, env
        self.processes: list[subprocess.Popen[str]] = []

    def _start(self, x: str) -> None:
        command = [sys.executable, str(PEER), str(self.domain), x, "0.0", str(HANG)]
        self.processes.append(
            subprocess.Popen(command, stdout=subprocess.PIPE, text=True, env=self.env)
        )

    async def run(self) -> None:
        await self.clock.sleep_until(0.5)
        (goal,) = [e for e in self.bridge._inputs if e.name == topics.GOAL]
        reader = goal.reader
        assert reader is not None
        for count, x in enumerate(BAD_X, 1):
            await run_blocking(self._start, x)
            arrived = await run_blocking(
                self.bridge.participant.wait, lambda n=count: reader.arrivals >= n, HANG
            )
            assert arrived, f"the goal at x = {x} never arrived from its peer"
            await self.clock.sleep(0.2)

    def close(self) -> None:
        for process in self.processes:
            process.terminate()
            process.communicate(timeout=HANG)


@pytest.mark.timeout(120)
def test_goals_off_the_world_from_other_processes_are_refused_and_the_run_goes_on(
    tmp_path: Path,
) -> None:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CYCLONEDDS"))}
    with exclusive_domain() as domain:
        bridge = Ros2Bridge(Ros2Config(domain_id=domain), env=env)
        peers = Peers(bridge, domain, env)
        try:
            verdict = run_scenario(
                ScenarioConfig(),
                StackConfig(),
                out_dir=tmp_path,
                plot=False,
                extra_actors=(bridge, peers),
            )
        finally:
            peers.close()
    assert verdict.passed, verdict.reason
    assert (bridge.received, bridge.refusals.count) == (0, len(BAD_X))
    lines = [m.msg for _t, _s, m in read_messages(tmp_path / "recording.mcap", [topics.ROSOUT])]
    refused = [line for line in lines if line.startswith("refused from ROS 2 (rt/goal)")]
    assert len(refused) == len(BAD_X), lines
    for x in ("nan", "inf", "1e+308"):
        assert any(f"goal x = {x}" in line or f"is {x}" in line for line in refused), refused


class Commands(Actor):
    """At 0.5 s of sim time, has a peer process write each of ``payloads`` on
    rt/cmd_vel_nav, holding sim time until each arrived and the bridge took it."""

    def __init__(self, bridge: Ros2Bridge, domain: int, payloads: list[bytes]) -> None:
        super().__init__("commands")
        self.bridge, self.domain, self.payloads = bridge, domain, payloads
        self.process: subprocess.Popen[str] | None = None

    def _start(self) -> subprocess.Popen[str]:
        env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CYCLONEDDS"))}
        command = [sys.executable, str(FUZZ_PEER), str(self.domain), "cmd_vel_nav"]
        return subprocess.Popen(
            command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env
        )

    async def run(self) -> None:
        await self.clock.sleep_until(0.5)
        self.process = peer = await run_blocking(self._start)
        assert peer.stdin is not None
        assert peer.stdout is not None
        assert await run_blocking(peer.stdout.readline) == "matched\n"
        (entry,) = [e for e in self.bridge._inputs if e.name == topics.CMD_VEL_NAV]
        reader = entry.reader
        assert reader is not None
        for n, payload in enumerate(self.payloads, 1):
            peer.stdin.write(payload.hex() + "\n")
            peer.stdin.flush()
            assert await run_blocking(peer.stdout.readline) == f"{n} written\n"
            assert await run_blocking(
                self.bridge.participant.wait, lambda n=n: reader.arrivals >= n, HANG
            )
            await self.clock.sleep(0.05)

    def close(self) -> None:
        if self.process is not None:
            self.process.kill()
            self.process.wait(HANG)
            for stream in (self.process.stdin, self.process.stdout):
                if stream is not None:
                    stream.close()


@pytest.mark.timeout(120)
def test_velocity_commands_beyond_any_base_are_refused_at_the_door(tmp_path: Path) -> None:
    # 1e308 m/s on /cmd_vel_nav, near an obstacle, is an OverflowError in the safety
    # layer's stopping path (safe_command): a planner node of your own may send it.
    bad = [Twist(linear=Vector3(x=1e308)), Twist(angular=Vector3(z=-1e3))]
    with exclusive_domain() as domain:
        env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CYCLONEDDS"))}
        bridge = Ros2Bridge(Ros2Config(domain_id=domain, inputs=(topics.CMD_VEL_NAV,)), env=env)
        commands = Commands(bridge, domain, [encode(twist) for twist in bad])
        try:
            verdict = run_scenario(
                ScenarioConfig(),
                StackConfig(),
                out_dir=tmp_path,
                plot=False,
                extra_actors=(bridge, commands),
            )
        finally:
            commands.close()
    assert verdict.passed, verdict.reason
    assert (bridge.received, bridge.refusals.count) == (0, len(bad))
    lines = [m.msg for _t, _s, m in read_messages(tmp_path / "recording.mcap", [topics.ROSOUT])]
    refused = [line for line in lines if line.startswith("refused from ROS 2 (rt/cmd_vel_nav)")]
    assert len(refused) == len(bad), lines
    assert "beyond the fastest base (10 m/s)" in refused[0]
