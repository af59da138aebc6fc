"""What a Foxglove client sends passes the door, and a client is bounded (issue 41), with
a real WebSocket client over TCP against a running stack:

1. goals at x = NaN, inf, 1e308 (JSON and CDR) are refused with a status, counted and
   logged on /rosout; no actor sees them (the navigator crashed on them before);
3. and 8. ``setParameters`` of ``safety.params.scales`` = 1e8 and of the integer 10**400
   are refused with the bound ``--set safety.scales`` has (1e8 was taken, and the
   safety layer ran out of memory; 10**400 was an OverflowError and no reply);
7. ids of 1e999, a 200,000-deep JSON array and binary frames under 5 bytes are each
   answered by a status, and the connection goes on (a traceback each before);
9. 10,000 subscription ids on /scan: one is taken, one status says the rest were
   refused, and each /scan message is one frame (one per id before);
4. a client that never reads its replies is disconnected once it has 1024 unread (the
   queue grew without bound before).
"""

from __future__ import annotations

import json
import math
import struct
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import anyio
import pytest
from mcap_ros2._dynamic import serialize_dynamic
from websockets.asyncio.client import ClientConnection, connect
from websockets.exceptions import ConnectionClosed
from websockets.typing import Subprotocol

from otonav.actors import AvoidingNavigator, topics
from otonav.embed import LiveStack, open_live_stack
from otonav.foxglove import FoxgloveServer, LiveView
from otonav.foxglove._protocol import CONTROL_BACKLOG
from otonav.msgs import PoseStamped
from otonav.record._reader import read_messages
from otonav.record._schemas import schema_for
from otonav.runtime import RealTime, until
from otonav.stack import StackConfig
from otonav.stack._config import FoxgloveConfig

pytestmark = pytest.mark.smoke

CEILING = 60.0
"""Wall seconds: a hang, never a timing assertion."""
PROTOCOL = [Subprotocol("foxglove.websocket.v1")]


@dataclass
class Run:
    live: LiveStack
    view: LiveView
    server: FoxgloveServer
    record: Path


@asynccontextmanager
async def _running(tmp_path: Path) -> AsyncIterator[Run]:
    server = FoxgloveServer(FoxgloveConfig(port=0))
    view = LiveView(server)
    record = tmp_path / "live.mcap"
    with anyio.fail_after(CEILING):
        async with open_live_stack(
            StackConfig(), time=RealTime(4.0), record_to=record, extra_actors=(view,)
        ) as live:
            view.serve_parameters(live.system.actor(a.name) for a in live.graph().actors)
            yield Run(live, view, server, record)
            assert live.running


async def _next_op(ws: ClientConnection, op: str) -> dict[str, Any]:
    while True:
        frame = await ws.recv()
        if isinstance(frame, str) and (message := json.loads(frame))["op"] == op:
            return message  # type: ignore[no-any-return]


async def _sim_sleep(live: LiveStack, seconds: float) -> None:
    end = live.now() + seconds
    await until(lambda: live.now() >= end, within=seconds + 1.0, clock=live.clock, what="time")


def _rosout(record: Path) -> list[str]:
    return [m.msg for _t, _s, m in read_messages(record, [topics.ROSOUT])]


def _cdr_goal(x: float) -> bytes:
    name, definition = schema_for(PoseStamped)
    encode = serialize_dynamic(name, definition)[name]
    return bytes(
        encode(
            {
                "header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": "odom"},
                "pose": {
                    "position": {"x": x, "y": 0.0, "z": 0.0},
                    "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
                },
            }
        )
    )


def _json_goal(x: str) -> bytes:
    return ('{"header": {"frame_id": "odom"}, "pose": {"position": {"x": ' + x + "}}}").encode()


@pytest.mark.asyncio
async def test_goals_off_the_world_are_refused_at_the_door_json_and_cdr(tmp_path: Path) -> None:
    name = schema_for(PoseStamped)[0]
    sent = [(1, _json_goal(x)) for x in ("NaN", "Infinity", "1e999", "1e308")]
    sent += [(2, _cdr_goal(x)) for x in (math.nan, math.inf, 1e308)]
    async with (
        _running(tmp_path) as run,
        connect(run.server.url, subprotocols=PROTOCOL, max_queue=None) as ws,
    ):
        channels = [
            {"id": 1, "topic": topics.GOAL, "encoding": "json", "schemaName": name},
            {"id": 2, "topic": topics.GOAL, "encoding": "cdr", "schemaName": name},
        ]
        await ws.send(json.dumps({"op": "advertise", "channels": channels}))
        statuses = []
        for channel, payload in sent:
            await ws.send(struct.pack("<BI", 0x01, channel) + payload)
            statuses.append(await _next_op(ws, "status"))
        await _sim_sleep(run.live, 0.5)  # sim time: the navigator runs ten steps meanwhile
        nav = run.live.system.actor("nav")
        assert isinstance(nav, AvoidingNavigator)
    assert all(s["level"] == 2 and s["message"].startswith("/goal: ") for s in statuses)
    assert all("goal x = " in s["message"] or " is " in s["message"] for s in statuses)
    assert run.view.client_messages == 0
    assert run.view.refusals.count == len(sent)
    assert nav.refused_goals == 0  # nothing reached the navigator
    lines = [line for line in _rosout(run.record) if line.startswith("refused from foxglove")]
    assert len(lines) == len(sent), lines


@pytest.mark.asyncio
async def test_parameters_out_of_the_config_bounds_are_refused(tmp_path: Path) -> None:
    huge = "1" + "0" * 400  # the integer 10**400, as JSON carries it
    async with (
        _running(tmp_path) as run,
        connect(run.server.url, subprotocols=PROTOCOL, max_queue=None) as ws,
    ):
        for request, value in (("big", "100000000"), ("huge", huge), ("float", "1e8")):
            change = '{"name": "safety.params.scales", "value": ' + value + "}"
            await ws.send(f'{{"op": "setParameters", "id": "{request}", "parameters": [{change}]}}')
            status = await _next_op(ws, "status")
            assert status["level"] == 2
            assert "the bound of safety.scales" in status["message"], status
            assert len(status["message"]) < 300
            reply = await _next_op(ws, "parameterValues")
            assert reply["id"] == request
            assert reply["parameters"] == [{"name": "safety.params.scales", "value": 6}]
        await _sim_sleep(run.live, 1.0)  # the safety layer runs 20 checks with its old scales
        assert run.live.system.actor("safety").params.scales == 6  # type: ignore[attr-defined]
    lines = [line for line in _rosout(run.record) if "safety.params.scales" in line]
    assert len(lines) == 3, lines


@pytest.mark.asyncio
async def test_malformed_frames_are_answered_and_the_connection_goes_on(tmp_path: Path) -> None:
    frames: list[str | bytes] = [
        '{"op": "subscribe", "subscriptions": [{"id": 1e999, "channelId": 1}]}',
        '{"op": "unsubscribe", "subscriptionIds": [1e999]}',
        '{"op": "advertise", "channels": [{"id": 1e999, "topic": "/goal", "encoding": "cdr"}]}',
        '{"op": "getParameters", "id": 1e999, "parameterNames": 5}',
        "[" * 200_000 + "]" * 200_000,
        '{"op": ' * 50_000,
        json.dumps({"op": "setParameters", "parameters": [{"name": "a", "value": 1}] * 65}),
        "[1, 2]",
        "not json",
        b"",
        b"\x01",
        b"\x01\x00\x00\x00",
    ]
    async with (
        _running(tmp_path) as run,
        connect(run.server.url, subprotocols=PROTOCOL, max_queue=None) as ws,
    ):
        for frame in frames:
            await ws.send(frame)
            status = await _next_op(ws, "status")
            assert status["level"] == 2, (frame[:40], status)
            assert len(status["message"]) <= 500
        await ws.send('{"op": "getParameters", "id": "after", "parameterNames": []}')
        reply = await _next_op(ws, "parameterValues")
        assert reply["id"] == "after"
        assert "safety.params.scales" in {p["name"] for p in reply["parameters"]}
    assert run.view.refusals.count == len(frames)  # counted; the first ten logged
    lines = [line for line in _rosout(run.record) if line.startswith("refused from foxglove")]
    assert len(lines) == 10, lines
    assert any("further refusals are counted, not logged" in line for line in _rosout(run.record))


@pytest.mark.asyncio
async def test_many_subscription_ids_on_one_channel_make_one_frame_per_message(
    tmp_path: Path,
) -> None:
    async with (
        _running(tmp_path) as run,
        connect(run.server.url, subprotocols=PROTOCOL, max_queue=None) as ws,
    ):
        advertised = await _next_op(ws, "advertise")
        while not any(c["topic"] == topics.SCAN for c in advertised["channels"]):
            advertised = await _next_op(ws, "advertise")
        scan = next(c["id"] for c in advertised["channels"] if c["topic"] == topics.SCAN)
        subscriptions = [{"id": i, "channelId": scan} for i in range(10_000)]
        await ws.send(json.dumps({"op": "subscribe", "subscriptions": subscriptions}))
        status = await _next_op(ws, "status")
        assert "subscriptions refused" in status["message"]
        assert "already subscribed as 0" in status["message"]
        assert "and 9996 more" in status["message"]
        frames: dict[int, set[int]] = {}
        with anyio.fail_after(CEILING):
            while sum(len(ids) for ids in frames.values()) < 5:
                frame = await ws.recv()
                if isinstance(frame, bytes) and frame[0] == 0x01:
                    sub, stamp = struct.unpack_from("<IQ", frame, 1)
                    frames.setdefault(stamp, set()).add(sub)
    assert all(ids == {0} for ids in frames.values()), frames


@pytest.mark.asyncio
async def test_a_client_that_never_reads_its_replies_is_disconnected(tmp_path: Path) -> None:
    request = '{"op": "getParameters", "id": "r", "parameterNames": []}'
    sent = 0
    async with _running(tmp_path) as run:
        # max_queue: the client library stops reading the socket at once
        async with connect(run.server.url, subprotocols=PROTOCOL, max_queue=1) as ws:

            async def flood() -> None:
                nonlocal sent
                while sent < 400_000:  # ~1 kB of replies each: 400 MB unbounded
                    await ws.send(request)
                    sent += 1

            with anyio.fail_after(CEILING), pytest.raises(ConnectionClosed):
                await flood()
        assert run.server.disconnected == 1
        assert sent > CONTROL_BACKLOG
        assert run.view.refusals.count == 1
        # the server still serves the others
        async with connect(run.server.url, subprotocols=PROTOCOL) as other:
            assert (await _next_op(other, "serverInfo"))["name"] == "otonav"
    (line,) = [line for line in _rosout(run.record) if "disconnected" in line]
    assert f"{CONTROL_BACKLOG} replies unread" in line
