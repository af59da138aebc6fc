"""``otonav run --foxglove`` serves the run's parameters (Foxglove's Parameters panel),
as ros-foxglove-bridge does on a robot: the real CLI in a subprocess, a real WebSocket
client over TCP. The client reads every actor's parameters while sim time is held at the
start (``--foxglove-wait``), slows the navigator down, sees a refused value answered with
an error, and the change is on /rosout (live and in the recording) at sim time 0; the
recorded odometry never goes faster than the new limit. Both runners (virtual and real
time) hand the wired system to ``on_system``, the hook the CLI uses."""

from __future__ import annotations

import asyncio
import json
import struct
import sys
from pathlib import Path
from typing import Any

import pytest
from foxglove_client import SUBPROTOCOLS, Channel
from test_foxglove_live import _free_port
from websockets.asyncio.client import ClientConnection, connect

from otonav.actors import topics
from otonav.record._reader import read_messages
from otonav.runtime import ActorStatus, RealTime, System, Virtual
from otonav.scenario import run_scenario
from otonav.scenario._builtin import BUILTIN

pytestmark = pytest.mark.smoke

CEILING = 90.0
"""Wall seconds: a hang, never a timing assertion."""
SLOW = 0.15
"""m/s: the navigator's new top speed (its default is 0.4)."""
CHANGED = f"parameter nav.params.max_v: 0.4 -> {SLOW!r} (set by a client)"


async def _line_with(stream: asyncio.StreamReader, text: str) -> str:
    """The first line of ``stream`` that contains ``text`` (fails at its end)."""
    seen = []
    while line := (await stream.readline()).decode():
        seen.append(line)
        if text in line:
            return line
    raise AssertionError(f"the command never said {text!r}; it said:\n{''.join(seen)}")


class _Session:
    """Reads a connection's JSON ops, remembering the channels advertised on the way."""

    def __init__(self, ws: ClientConnection) -> None:
        self.ws = ws
        self.channels: dict[str, Channel] = {}

    async def next_op(self, op: str) -> dict[str, Any]:
        while True:
            frame = await self.ws.recv()
            if not isinstance(frame, str):
                continue
            message: dict[str, Any] = json.loads(frame)
            if message["op"] == "advertise":
                for c in message["channels"]:
                    self.channels[c["topic"]] = Channel(
                        c["id"], c["topic"], c["encoding"], c["schemaName"],
                        c.get("schemaEncoding", ""), c["schema"],
                    )  # fmt: skip
            if message["op"] == op:
                return message

    async def parameters(self, op: str, request_id: str, **body: Any) -> dict[str, Any]:
        await self.ws.send(json.dumps({"op": op, "id": request_id, **body}))
        while True:
            reply = await self.next_op("parameterValues")
            if reply.get("id") == request_id:
                return {p["name"]: p["value"] for p in reply["parameters"]}


@pytest.mark.asyncio
async def test_otonav_run_foxglove_serves_and_sets_the_actors_parameters(
    tmp_path: Path,
) -> None:
    port = _free_port()
    out = tmp_path / "out"
    command = [
        sys.executable, "-m", "otonav", "run", "--scenario", "empty", "--foxglove",
        "--foxglove-port", str(port), "--foxglove-wait", "30", "--out", str(out),
        "--set", "nav.planner=stop",  # the go-to-goal navigator: its gains are its params
    ]  # fmt: skip
    proc = await asyncio.create_subprocess_exec(
        *command, stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE
    )
    try:
        async with asyncio.timeout(CEILING):
            assert proc.stderr is not None
            said = await _line_with(proc.stderr, "foxglove: serving the parameters")
            assert "nav.params.FIELD" in said  # it says which ones can be set
            async with connect(
                f"ws://127.0.0.1:{port}", subprotocols=SUBPROTOCOLS, max_size=None
            ) as ws:
                session = _Session(ws)
                info = await session.next_op("serverInfo")
                assert "parameters" in info["capabilities"]

                values = await session.parameters("getParameters", "all", parameterNames=[])
                assert values["nav.params.max_v"] == pytest.approx(0.4)
                assert "safety.params.radius" in values

                changed = await session.parameters(
                    "setParameters",
                    "slow",
                    parameters=[{"name": "nav.params.max_v", "value": SLOW}],
                )
                assert changed == {"nav.params.max_v": SLOW}
                await ws.send(
                    json.dumps(
                        {
                            "op": "setParameters",
                            "id": "bad",
                            "parameters": [{"name": "nav.params.max_v", "value": -1}],
                        }
                    )
                )
                status = await session.next_op("status")
                assert status["level"] == 2
                assert "nav.params.max_v" in status["message"]
                kept = await session.parameters(
                    "getParameters", "again", parameterNames=["nav.params.max_v"]
                )
                assert kept == {"nav.params.max_v": SLOW}

                # Subscribing releases the held sim time; the change is on /rosout live.
                rosout = session.channels[topics.ROSOUT]
                subscribe = {
                    "op": "subscribe",
                    "subscriptions": [{"id": 1, "channelId": rosout.id}],
                }
                await ws.send(json.dumps(subscribe))
                live: list[tuple[int, str]] = []
                while not any(CHANGED in text for _t, text in live):
                    frame = await ws.recv()
                    if isinstance(frame, bytes) and frame[0] == 0x01:
                        _op, _sub, log_time = struct.unpack_from("<BIQ", frame)
                        log = rosout.decode(frame[13:])
                        live.append((log_time, log.msg))
            code = await proc.wait()
    finally:
        if proc.returncode is None:
            proc.kill()
            await proc.wait()
    # The verdict is the scenario's business (a slow robot may miss the budget).
    assert code in (0, 1)
    assert [t for t, text in live if CHANGED in text] == [0]  # at sim time 0, live

    recording = out / "recording.mcap"
    lines = [(t, m.msg) for _tp, t, m in read_messages(recording, [topics.ROSOUT])]
    assert [t for t, text in lines if CHANGED in text] == [0.0]
    assert any("refused from a foxglove client's parameters" in text for _t, text in lines)
    speeds = [m.twist.twist.linear.x for _tp, _t, m in read_messages(recording, [topics.ODOM])]
    assert max(speeds) > 0.1  # it drove
    assert max(speeds) <= SLOW * 1.05  # never faster than the client's limit


@pytest.mark.parametrize("realtime", [None, 20.0], ids=["virtual", "realtime"])
def test_both_runners_hand_the_wired_system_to_on_system_before_it_runs(
    realtime: float | None,
) -> None:
    seen: list[tuple[str, ActorStatus]] = []

    def on_system(system: System) -> None:
        seen.extend((a.name, a.status) for a in system.graph().actors)
        assert system.actor("nav").name == "nav"  # the actors themselves, not only names

    short = BUILTIN["empty"].model_copy(update={"sim_budget": 0.5})
    verdict = run_scenario(
        short,
        record=False,
        plot=False,
        time=Virtual() if realtime is None else RealTime(realtime),
        on_system=on_system,
    )
    assert verdict.sim_time_s > 0.4  # then the run went on as usual
    names = [name for name, _ in seen]
    assert {"nav", "safety", "judge"} <= set(names)
    assert len(names) == len(set(names))  # called once
    assert {status for _, status in seen} == {ActorStatus.CREATED}  # none started yet
