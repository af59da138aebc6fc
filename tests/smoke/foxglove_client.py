"""A real Foxglove WebSocket client for the tests (the ``websockets`` package), run in
its own thread with its own event loop, so it talks to the server over TCP while the
stack runs (in virtual time, on the test's thread)."""

from __future__ import annotations

import asyncio
import json
import struct
import threading
from dataclasses import dataclass, field
from typing import Any

from mcap.records import Schema
from mcap_ros2.decoder import DecoderFactory
from websockets.asyncio.client import ClientConnection, connect
from websockets.exceptions import ConnectionClosed
from websockets.typing import Subprotocol

#: The protocol's name in its specification, which clients of the @foxglove/ws-protocol
#: library, roslibjs-foxglove and older Lichtblick offer alone (issue 15: the suite
#: connects with it). Our server also accepts the current name, foxglove.sdk.v1 (ADR 32).
SUBPROTOCOLS = [Subprotocol("foxglove.websocket.v1")]
CEILING = 30.0
"""Wall seconds after which a wait is a hang (never a timing assertion)."""

_MESSAGE_DATA = 0x01
_TIME = 0x02
_HEAD = struct.Struct("<BIQ")


@dataclass
class Channel:
    id: int
    topic: str
    encoding: str
    schema_name: str
    schema_encoding: str
    schema: str

    def decode(self, payload: bytes) -> Any:
        """The message, decoded by mcap_ros2's generic decoder from the advertised schema."""
        schema = Schema(
            id=1, name=self.schema_name, encoding=self.schema_encoding, data=self.schema.encode()
        )
        decoder = DecoderFactory().decoder_for(self.encoding, schema)
        assert decoder is not None, f"no decoder for {self.schema_name} in {self.encoding}"
        return decoder(payload)


@dataclass
class FoxgloveClient:
    """Connects, collects advertisements until ``expect`` are all advertised, subscribes to
    ``subscribe`` (every channel when None), then reads (or, ``read=False``, never reads
    again) until :meth:`stop`."""

    url: str
    expect: set[str]
    subscribe: set[str] | None = None
    read: bool = True
    server_info: dict[str, Any] = field(default_factory=dict)
    subprotocol: str | None = None
    channels: dict[str, Channel] = field(default_factory=dict)
    received: dict[str, list[tuple[int, bytes]]] = field(default_factory=dict)
    """topic -> [(log time ns, payload)] in arrival order."""
    times: list[int] = field(default_factory=list)
    """Server time broadcasts (sim ns)."""
    error: BaseException | None = None

    def __post_init__(self) -> None:
        self._arrived = threading.Condition()
        self.subscribed = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="foxglove-client", daemon=True)

    def start(self) -> FoxgloveClient:
        self._thread.start()
        if not self.subscribed.wait(CEILING):
            self.stop()
            raise AssertionError(f"client never subscribed (error: {self.error!r})")
        if self.error is not None:  # e.g. the connection was refused
            self._thread.join(CEILING)
            raise self.error
        return self

    def wait_for(self, topic: str, count: int) -> int:
        """Block until ``count`` messages of ``topic`` arrived (the server sends from its
        own threads: the run can end before they are all through); returns how many."""
        with self._arrived:
            self._arrived.wait_for(lambda: len(self.received.get(topic, ())) >= count, CEILING)
            return len(self.received.get(topic, ()))

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(CEILING)
        assert not self._thread.is_alive(), "the client thread hangs"
        if self.error is not None:
            raise self.error

    def _run(self) -> None:
        try:
            asyncio.run(self._main())
        except BaseException as exc:
            self.error = exc
            self.subscribed.set()

    async def _main(self) -> None:
        async with connect(
            self.url, subprotocols=SUBPROTOCOLS, max_size=None, close_timeout=1
        ) as ws:
            self.subprotocol = ws.subprotocol
            await asyncio.wait_for(self._advertisements(ws), CEILING)
            wanted = [
                c for topic, c in sorted(self.channels.items())
                if self.subscribe is None or topic in self.subscribe
            ]  # fmt: skip
            subs = [{"id": i, "channelId": c.id} for i, c in enumerate(wanted)]
            await ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))
            by_id = {i: c.topic for i, c in enumerate(wanted)}
            self.subscribed.set()
            if not self.read:
                await asyncio.to_thread(self._stop.wait)
                return
            while not self._stop.is_set():
                try:
                    frame = await asyncio.wait_for(ws.recv(), 0.2)
                except TimeoutError:
                    continue
                except ConnectionClosed:
                    return
                if isinstance(frame, bytes):
                    self._binary(frame, by_id)
                else:
                    self._text(frame)

    async def _advertisements(self, ws: ClientConnection) -> None:
        while not self.expect <= set(self.channels):
            frame = await ws.recv()
            if isinstance(frame, str):
                self._text(frame)

    def _text(self, frame: str) -> None:
        message = json.loads(frame)
        if message["op"] == "serverInfo":
            self.server_info = message
        elif message["op"] == "advertise":
            for c in message["channels"]:
                self.channels[c["topic"]] = Channel(
                    c["id"],
                    c["topic"],
                    c["encoding"],
                    c["schemaName"],
                    c.get("schemaEncoding", ""),
                    c["schema"],
                )

    def _binary(self, frame: bytes, by_id: dict[int, str]) -> None:
        if frame[0] == _MESSAGE_DATA:
            _op, sub, log_time = _HEAD.unpack_from(frame)
            with self._arrived:
                self.received.setdefault(by_id[sub], []).append((log_time, frame[_HEAD.size :]))
                self._arrived.notify_all()
        elif frame[0] == _TIME:
            (stamp,) = struct.unpack_from("<Q", frame, 1)
            self.times.append(stamp)
