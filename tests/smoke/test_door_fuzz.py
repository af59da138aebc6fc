"""The door under fuzz (issue 41): in one virtual-time run, a real Foxglove client sends
1,000 random and mutated frames (ops with ids of every kind, parameter sets of every
value, client messages in JSON and CDR, bit-flipped and cut goals, random bytes), and a
DDS participant in another process writes 1,000 random goal payloads on rt/goal. The run
goes on to its end, every /goal an actor sees passes the door's check, every parameter
stays within its config bounds, RSS stays bounded and the recording is complete.

Seeded: the same frames on every run (``FUZZ_SEED`` picks others)."""

from __future__ import annotations

import json
import math
import os
import random
import struct
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

import pytest
from dds_domain import exclusive_domain
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from otonav.actors import topics
from otonav.foxglove import FoxgloveServer, LiveView
from otonav.msgs import Point, Pose, PoseStamped
from otonav.record._reader import read_messages
from otonav.record.cdr import encode
from otonav.ros2 import Ros2Bridge
from otonav.runtime import Actor, Input, QoS, Reliability, System, run_blocking, until
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.stack import StackConfig
from otonav.stack._config import FoxgloveConfig, Ros2Config
from otonav.stack._door import refusal
from otonav.stack._live_parameters import _validator

pytestmark = pytest.mark.smoke

PEER = Path(__file__).with_name("dds_fuzz_peer.py")
HANG = 60.0
"""Wall seconds a wait may take: a hang, never a timing assertion."""
COUNT = 1000
SEED = int(os.environ.get("FUZZ_SEED", "41"))
RSS_GROWTH_MB = 64
"""The most the process may grow while the fuzz runs (measured: see the test's print)."""
_NAME = PoseStamped.ros_type


def _rss_mb() -> float:
    with open("/proc/self/status") as status:
        line = next(x for x in status if x.startswith("VmRSS:"))
    return int(line.split()[1]) / 1024


def _number(rng: random.Random) -> Any:
    return rng.choice(
        [
            rng.uniform(-5, 5),
            rng.uniform(-2000, 2000),
            1e308,
            -1e308,
            10**400,
            rng.randint(-(2**40), 2**40),
            0,
            True,
            "1.0",
            None,
            [1.0],
            {"x": 1},
        ]
    )


def _goal(rng: random.Random) -> PoseStamped:
    special = [math.nan, math.inf, -math.inf, 1e308, -1e308, 1000.0, 1000.0001]
    x, y = (rng.choice(special) if rng.random() < 0.4 else rng.uniform(-3, 3) for _ in "xy")
    return PoseStamped.model_construct(pose=Pose.model_construct(position=Point(x=x, y=y)))


def _cdr(rng: random.Random) -> bytes:
    """A goal's CDR, then perhaps mutated: bytes flipped, cut, or extended."""
    data = bytearray(encode(_goal(rng)))
    kind = rng.random()
    if kind < 0.2:
        for _ in range(rng.randint(1, 8)):
            data[rng.randrange(4, len(data))] = rng.randrange(256)
    elif kind < 0.3:
        del data[rng.randrange(4, len(data)) :]
    elif kind < 0.35:
        data += rng.randbytes(rng.randint(1, 64))
    return bytes(data)


def _json_goal(rng: random.Random) -> bytes:
    x = rng.choice(["NaN", "Infinity", "-Infinity", "1e999", "1e308", "2.5", '"x"', "[]"])
    return ('{"header": {"frame_id": "odom"}, "pose": {"position": {"x": ' + x + "}}}").encode()


def foxglove_frames(rng: random.Random, parameters: list[str]) -> list[str | bytes]:
    """``COUNT`` frames; the first advertises channels 1 (JSON) and 2 (CDR) on /goal."""
    channels = [
        {"id": 1, "topic": topics.GOAL, "encoding": "json", "schemaName": _NAME},
        {"id": 2, "topic": topics.GOAL, "encoding": "cdr", "schemaName": _NAME},
    ]
    frames: list[str | bytes] = [json.dumps({"op": "advertise", "channels": channels})]
    while len(frames) < COUNT:
        kind = rng.randrange(9)
        if kind == 0:
            subs = [{"id": _number(rng), "channelId": _number(rng)} for _ in range(3)]
            subs.append({"id": rng.randrange(100), "channelId": rng.randrange(1, 40)})
            frames.append(json.dumps({"op": "subscribe", "subscriptions": subs}))
        elif kind == 1:
            ids = [_number(rng), rng.randrange(100)]
            frames.append(json.dumps({"op": "unsubscribe", "subscriptionIds": ids}))
        elif kind == 2:
            name = rng.choice([*parameters, "nav.params.no_such", ""])
            frames.append(
                json.dumps(
                    {
                        "op": "setParameters",
                        "id": rng.choice(["s", 1e300, None]),
                        "parameters": [{"name": name, "value": _number(rng)}],
                    }
                )
            )
        elif kind == 3:
            frames.append(struct.pack("<BI", 0x01, 2) + _cdr(rng))
        elif kind == 4:
            frames.append(struct.pack("<BI", 0x01, 1) + _json_goal(rng))
        elif kind == 5:
            frames.append(rng.randbytes(rng.randrange(0, 12)))
        elif kind == 6:  # a valid frame, mutated
            text = bytearray(
                json.dumps({"op": "getParameters", "parameterNames": parameters}), "utf8"
            )
            for _ in range(rng.randint(1, 4)):
                text[rng.randrange(len(text))] = rng.randrange(32, 127)
            frames.append(text.decode())
        elif kind == 7:
            depth = rng.choice([10, 1000, 100_000])
            frames.append("[" * depth + "]" * depth)
        else:
            frames.append(rng.choice(["", "null", "1e999", '{"op": 1e999}', '{"op": "time"}']))
    return frames


def dds_payloads(rng: random.Random) -> list[bytes]:
    """``COUNT`` payloads on rt/goal: goals with every kind of number, mutated and cut
    goals, and random bodies (the 4-byte encapsulation header kept: Cyclone's own)."""
    payloads = []
    for _ in range(COUNT):
        if rng.random() < 0.8:
            payloads.append(_cdr(rng))
        else:
            payloads.append(b"\x00\x01\x00\x00" + rng.randbytes(rng.randrange(0, 200)))
    return payloads


class FoxgloveFuzzer(threading.Thread):
    """Sends the frames and reads every reply (a client that reads is never cut off)."""

    def __init__(self, url: str, frames: list[str | bytes]) -> None:
        super().__init__(name="foxglove-fuzzer", daemon=True)
        self.url, self.frames = url, frames
        self.replies = 0
        self.done = threading.Event()
        self.error: BaseException | None = None

    def run(self) -> None:
        try:
            with connect(self.url, subprotocols=["foxglove.websocket.v1"], max_size=None) as ws:  # type: ignore[list-item]
                for frame in self.frames:
                    ws.send(frame)
                ws.send(json.dumps({"op": "getParameters", "id": "done", "parameterNames": []}))
                while True:
                    reply = ws.recv(HANG)
                    self.replies += 1
                    if isinstance(reply, str) and '"id": "done"' in reply:
                        return
        except (ConnectionClosed, TimeoutError) as exc:
            self.error = exc
        finally:
            self.done.set()


class GoalSpy(Actor):
    """Sees every /goal that reaches the actors (a deep mailbox: none dropped)."""

    goal = Input(topics.GOAL, PoseStamped, QoS(Reliability.BEST_EFFORT, depth=100_000))

    def __init__(self) -> None:
        super().__init__("goal_spy")
        self.seen: list[PoseStamped] = []

    async def run(self) -> None:
        async for message in self.goal:
            self.seen.append(message)


class Fuzz(Actor):
    """Starts both fuzzers as the run starts; writes the DDS payloads one at a time,
    holding sim time until each arrived and the bridge took it; then waits for the
    Foxglove fuzzer's last reply."""

    def __init__(self, bridge: Ros2Bridge, view: LiveView, domain: int) -> None:
        super().__init__("fuzz")
        self.bridge, self.view, self.server, self.domain = bridge, view, view.server, domain
        self.peer: subprocess.Popen[str] | None = None
        self.rss: list[float] = []
        self.written = 0
        """DDS payloads the peer's writer took (and the bridge's reader got)."""
        self.dds_refused = 0
        """DDS payloads Cyclone's own writer refused (too short for the type)."""
        self.finished_at = math.nan

    def _start_peer(self) -> subprocess.Popen[str]:
        env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CYCLONEDDS"))}
        return subprocess.Popen(
            [sys.executable, str(PEER), str(self.domain)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            env=env,
        )

    async def run(self) -> None:
        await self.clock.sleep_until(0.1)  # the bridge's readers are made as it starts
        rng = random.Random(SEED)
        parameters = [p["name"] for p in self.view.get_parameters([])]
        fuzzer = FoxgloveFuzzer(self.server.url, foxglove_frames(rng, parameters))
        payloads = dds_payloads(rng)
        self.rss.append(_rss_mb())
        self.peer = peer = await run_blocking(self._start_peer)
        assert peer.stdin is not None
        assert peer.stdout is not None
        assert await run_blocking(peer.stdout.readline) == "matched\n"
        fuzzer.start()
        (entry,) = [e for e in self.bridge._inputs if e.name == topics.GOAL]
        reader = entry.reader
        assert reader is not None
        bridge = self.bridge
        for n, payload in enumerate(payloads, 1):
            peer.stdin.write(payload.hex() + "\n")
            peer.stdin.flush()
            answer = await run_blocking(peer.stdout.readline)
            assert answer in (f"{n} written\n", f"{n} refused\n"), answer
            if answer.endswith("refused\n"):  # Cyclone's writer checks the size first
                self.dds_refused += 1
                continue
            self.written += 1
            arrived = await run_blocking(
                bridge.participant.wait, lambda: reader.arrivals >= self.written, HANG
            )
            assert arrived, f"payload {n} never arrived"
            await until(
                lambda: bridge.received + bridge.refusals.count >= self.written,
                within=1.0,
                clock=self.clock,
                what=f"the bridge took payload {n}",
            )
        peer.stdin.close()
        assert await run_blocking(fuzzer.done.wait, HANG)
        assert fuzzer.error is None, fuzzer.error
        self.rss.append(_rss_mb())
        self.finished_at = self.clock.now()


@pytest.mark.timeout(300)
def test_a_thousand_foxglove_frames_and_dds_goals_reach_no_actor_unchecked(
    tmp_path: Path,
) -> None:
    server = FoxgloveServer(FoxgloveConfig(port=0))
    view = LiveView(server)
    spy = GoalSpy()

    def serve(system: System) -> None:
        view.serve_parameters(system.actor(a.name) for a in system.graph().actors)

    with exclusive_domain() as domain:
        env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CYCLONEDDS"))}
        bridge = Ros2Bridge(Ros2Config(domain_id=domain), env=env)
        fuzz = Fuzz(bridge, view, domain)
        try:
            verdict = run_scenario(
                ScenarioConfig(sim_budget=60.0),
                StackConfig(),
                out_dir=tmp_path,
                plot=False,
                extra_actors=(view, bridge, spy, fuzz),
                on_system=serve,
            )
        finally:
            server.close()
            if fuzz.peer is not None:
                fuzz.peer.kill()
                fuzz.peer.wait(timeout=HANG)
                for stream in (fuzz.peer.stdin, fuzz.peer.stdout):
                    if stream is not None:
                        stream.close()
    # the run went on to its end: judged, not crashed
    assert verdict.reason
    assert not math.isnan(fuzz.finished_at), "the fuzz did not finish within the run"
    # nothing reached an actor unchecked
    assert all(refusal(goal) is None for goal in spy.seen)
    assert fuzz.written + fuzz.dds_refused == COUNT
    # taken, or refused (at the door, or dropped: the navigator's reliable /goal mailbox,
    # depth 1, was full)
    assert bridge.received + bridge.refusals.count == fuzz.written
    assert len(spy.seen) == 1 + view.client_messages + bridge.received  # 1: the scenario's
    table = view._parameters
    assert table is not None, "the live view served no parameters"
    for name, value in table.values().items():
        key = table._config_key(name)
        if key is not None:
            _validator(key).validate_python(value)
    # bounded
    grown = fuzz.rss[1] - fuzz.rss[0]
    print(
        f"fuzz: {COUNT} foxglove frames ({view.refusals.count} refused, "
        f"{view.client_messages} goals taken), {COUNT} DDS payloads ({fuzz.dds_refused} "
        f"refused by Cyclone's writer, {bridge.refusals.count} by the door, "
        f"{bridge.received} taken); RSS {fuzz.rss[0]:.0f} -> {fuzz.rss[1]:.0f} MB"
    )
    assert grown < RSS_GROWTH_MB, fuzz.rss
    # the recording is complete: indexed, up to the run's end, with the refusals
    clock = [t for _topic, t, _m in read_messages(tmp_path / "recording.mcap", ["/clock"])]
    assert clock[-1] >= fuzz.finished_at
    goals = list(read_messages(tmp_path / "recording.mcap", [topics.GOAL]))
    assert len(goals) == len(spy.seen)
    rosout = [m.msg for _t, _s, m in read_messages(tmp_path / "recording.mcap", [topics.ROSOUT])]
    assert any(line.startswith("refused from ROS 2 (rt/goal)") for line in rosout)
    assert any(line.startswith("refused from foxglove client") for line in rosout)
