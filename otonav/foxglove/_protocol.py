"""The Foxglove WebSocket server (protocol v1) on ``websockets``, in its own thread:
:class:`FoxgloveServer`, which the live view (:mod:`otonav.foxglove._view`) feeds. The only
module that imports ``websockets`` (an import-linter contract), and only when a server
starts (``otonav.foxglove.FoxgloveServer`` imports it on first use).

It speaks the part of the protocol a live view needs (docs/adr/0032, 0044):
``serverInfo`` with the ``time`` capability, ``advertise`` of channels (topic, ``cdr``
encoding, ``ros2msg`` schema), ``subscribe``/``unsubscribe`` from clients, binary
message data and time frames; ``clientPublish`` (clients ``advertise`` their own channels
and send binary ``clientMessageData``; unless ``client_publish`` is empty);
``getParameters``/``setParameters`` answered by ``parameterValues``.
The handshake accepts the protocol under both its names:
``foxglove.sdk.v1`` (what foxglove-sdk's servers accept, and current Foxglove apps offer)
and ``foxglove.websocket.v1`` (the specification's name, which the @foxglove/ws-protocol
client library, roslibjs-foxglove and Lichtblick before its December 2025 change offer
alone); the wire format is the same. foxglove-sdk 0.30.3, which served the live view
before, accepts only the first: clients that offer only the second got a 400.

Threads: the stack calls :meth:`Channel.log` and :meth:`FoxgloveServer.broadcast_time`
from its own thread. Each appends a ready frame to every subscribed client's queue
under one lock and returns: nothing waits for a socket. The server's thread
runs an asyncio loop with one writer task per client that sends what is queued. A
client that does not read stops its writer (the socket's buffer is full); its queue
then keeps the newest ``backlog`` data frames, dropping (and counting) the oldest.
Control messages (serverInfo, advertisements, status) are never dropped.

Bounded per client (issue 41, docs/adr/0074): at most :data:`CONTROL_BACKLOG` unread
control messages, then the client is disconnected (close code 1008, with the reason);
one subscription per channel (a second id for it is refused, as foxglove-sdk's servers
do), so each message is one frame per client whatever a client asks, and one status
answers a whole subscribe request; at most :data:`MAX_ADVERTISED` client channels and
:data:`MAX_CHANGES` parameters per ``setParameters``. A malformed frame (ids that are not
uint32, a non-object, deep JSON, a binary frame under 5 bytes) is answered by a status and
reported to ``refusal_sink``; none ends the connection.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import struct
import threading
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from websockets.asyncio.server import Server, ServerConnection, serve
from websockets.exceptions import ConnectionClosed
from websockets.typing import Subprotocol

from otonav.actors import _topics as topics
from otonav.foxglove._errors import LiveViewError
from otonav.msgs import Message
from otonav.record._schemas import schema_for
from otonav.stack._config import FoxgloveConfig

SUBPROTOCOLS = (Subprotocol("foxglove.sdk.v1"), Subprotocol("foxglove.websocket.v1"))
"""What the handshake accepts: the protocol's current name, then its original one."""

_MESSAGE_DATA = struct.Struct("<BIQ")  # opcode 0x01, subscription id, log time ns
_TIME = struct.Struct("<BQ")  # opcode 0x02, time ns
_CLIENT_DATA = struct.Struct("<BI")  # opcode 0x01, client channel id; then the payload

CONTROL_BACKLOG = 1024
"""Replies (status, parameter values, advertisements) queued for a client that does not
read them before it is disconnected: a client sending bad requests and never reading
the answers grew the queue without bound (issue 41: 146 -> 425 MB and rising)."""
MAX_ADVERTISED = 64
"""Channels one client may advertise (clientPublish): a few topics are ever taken."""
MAX_CHANGES = 64
"""Parameters one ``setParameters`` may change: each is validated and applied on the
stack's thread, which must not do work that grows with what a client asks."""
MAX_STATUS_CHARS = 500
"""A status message quotes at most this much of what the client sent."""
_UINT32 = 1 << 32
_CLOSE_TIMEOUT = 2.0
"""Wall seconds a disconnected client has to answer the close before its socket is cut."""


@dataclass(frozen=True, slots=True)
class ClientChannel:
    """A channel a client advertised (``clientPublish``)."""

    client: int
    id: int
    topic: str
    encoding: str
    schema_name: str


@dataclass(eq=False)
class _Client:
    id: int
    connection: ServerConnection
    wake: asyncio.Event
    control: deque[str] = field(default_factory=deque)
    data: deque[bytes] = field(default_factory=deque)
    subscriptions: dict[int, int] = field(default_factory=dict)
    """subscription id -> channel id."""
    advertised: dict[int, ClientChannel] = field(default_factory=dict)
    """client channel id -> what the client said it publishes there."""
    by_channel: dict[int, int] = field(default_factory=dict)
    """channel id -> its subscription id (one per channel: a second is refused)."""
    dropped: int = 0
    waking: bool = False
    closing: str | None = None
    """Why the server is disconnecting this client (it went over a bound)."""


class Channel:
    """One advertised topic. :meth:`log` hands a message to every client subscribed."""

    __slots__ = ("_id", "_server", "definition", "schema_name", "topic")

    def __init__(
        self, server: FoxgloveServer, channel_id: int, topic: str, schema: tuple[str, str]
    ) -> None:
        self._server = server
        self._id = channel_id
        self.topic = topic
        self.schema_name, self.definition = schema

    def id(self) -> int:
        return self._id

    def has_sinks(self) -> bool:
        """Whether some client subscribed to this channel now."""
        return self._id in self._server._subscribed_channels

    def log(self, data: bytes, *, log_time: int) -> None:
        """Queue ``data`` (CDR) stamped ``log_time`` (ns) for every subscribed client."""
        self._server._log(self._id, data, log_time)

    def advertisement(self) -> dict[str, Any]:
        return {
            "id": self._id,
            "topic": self.topic,
            "encoding": "cdr",
            "schemaName": self.schema_name,
            "schema": self.definition,
            "schemaEncoding": "ros2msg",
        }


class FoxgloveServer:
    """A Foxglove WebSocket server on ``config.host:config.port`` (the stack config's
    ``foxglove`` section; port 0: any free one), serving from its own thread once made
    (:meth:`close` stops it), with ``backlog`` data messages queued per client before its
    oldest is dropped, and clients publishing on the ``client_publish`` topics (none:
    they only watch); ``subscriptions``: how many channel subscriptions a
    ``config.wait_for_subscriber`` waits for. Raises
    :class:`~otonav.foxglove.LiveViewError` when the address cannot be bound. The live
    view sets its sinks: ``client_sink(channel, payload)`` takes a client's message (None,
    or one line why not), ``parameter_sink`` answers ``getParameters``/``setParameters``
    (``get_parameters(names)``, ``set_parameters(changes, reply)``), ``refusal_sink(source,
    text)`` hears of malformed frames and disconnected clients; all on the server's thread."""

    def __init__(
        self,
        config: FoxgloveConfig | None = None,
        *,
        backlog: int = 256,
        client_publish: tuple[str, ...] = (topics.GOAL,),
        subscriptions: int = 1,
    ) -> None:
        self.config = options = config if config is not None else FoxgloveConfig()
        self.backlog, self.client_publish, self.awaited = backlog, client_publish, subscriptions
        self.capabilities = ["time", "clientPublish", "parameters"]
        if not client_publish:
            self.capabilities.remove("clientPublish")
        self.client_sink: Callable[[ClientChannel, bytes], str | None] | None = None
        self.parameter_sink: Any = None
        self.refusal_sink: Callable[[str, str], None] = lambda source, text: None
        self._lock = threading.Lock()
        self._changed = threading.Condition(self._lock)
        self._clients: dict[int, _Client] = {}
        self._channels: dict[int, Channel] = {}
        self._by_topic: dict[str, Channel] = {}
        self._latched: dict[int, tuple[bytes, int]] = {}
        self._subscribed_channels: dict[int, int] = {}
        """channel id -> how many subscriptions it has now."""
        self._subscribed_total = 0
        self.clients_seen: set[int] = set()
        """Clients that subscribed to some channel (all so far)."""
        self._next_client = 1
        self._next_channel = 1
        self.dropped = 0
        """Data frames dropped for clients that did not keep up (all clients so far)."""
        self.disconnected = 0
        """Clients the server disconnected for going over a bound (all so far)."""
        self.closed = False
        self._loop = asyncio.new_event_loop()
        self._server: Server | None = None
        self._ready = threading.Event()
        self._error: BaseException | None = None
        self._thread = threading.Thread(
            target=self._run,
            args=(options.host, options.port),
            name="foxglove-server",
            daemon=True,
        )
        self._thread.start()
        self._ready.wait()
        if isinstance(self._error, OSError):
            self._thread.join()
            errno = self._error.errno
            raise LiveViewError(
                f"foxglove server on {options.host}:{options.port}: cannot start "
                f"({os.strerror(errno) if errno else self._error}); pick another "
                "--foxglove-port (0: any free one)"
            ) from None
        if self._error is not None:
            self._thread.join()
            raise self._error
        assert self._server is not None
        self.port: int = self._server.sockets[0].getsockname()[1]
        """The bound port (the one picked when ``config.port`` was 0)."""

    @property
    def url(self) -> str:
        return f"ws://{self.config.host}:{self.port}"

    @property
    def subscriptions(self) -> dict[int, set[int]]:
        """client id -> the channel ids it subscribes to now."""
        with self._lock:
            return {
                c.id: set(c.subscriptions.values())
                for c in self._clients.values()
                if c.subscriptions
            }

    def wait_for_subscriptions(self, count: int = 1, timeout: float | None = None) -> bool:
        """Block (a thread, never the loop) until clients made ``count`` channel
        subscriptions in all since the server started; False on timeout."""
        with self._changed:
            return self._changed.wait_for(lambda: self._subscribed_total >= count, timeout)

    # -- the stack's side (any thread) ---------------------------------------------------

    def channel(self, topic: str, msg_type: type[Message]) -> Channel:
        """The channel of ``topic``, advertised to every client when first made and to
        each that connects."""
        channel = self._by_topic.get(topic)
        if channel is not None:
            return channel
        with self._lock:
            channel = Channel(self, self._next_channel, topic, schema_for(msg_type))
            self._by_topic[topic] = channel
            self._next_channel += 1
            self._channels[channel.id()] = channel
            message = json.dumps({"op": "advertise", "channels": [channel.advertisement()]})
            for client in self._clients.values():
                self._queue_control(client, message)
        return channel

    def latch(self, channel: Channel, data: bytes, log_time: int) -> None:
        """Remember the newest message of a latched topic, for clients that subscribe later
        (the protocol has no latching)."""
        self._latched[channel.id()] = (data, log_time)

    def broadcast_time(self, sim_time: float) -> None:
        if self.closed:
            return
        frame = _TIME.pack(0x02, round(sim_time * 1e9))
        with self._lock:
            for client in self._clients.values():
                self._queue_data(client, frame)

    def _log(self, channel_id: int, data: bytes, log_time: int) -> None:
        with self._lock:
            if channel_id not in self._subscribed_channels:
                return
            for client in self._clients.values():
                subscription = client.by_channel.get(channel_id)
                if subscription is not None:
                    self._queue_data(
                        client, _MESSAGE_DATA.pack(0x01, subscription, log_time) + data
                    )

    def _queue_data(self, client: _Client, frame: bytes) -> None:  # under the lock
        if client.closing is not None:
            return
        if len(client.data) >= self.backlog:
            client.data.popleft()
            client.dropped += 1
            self.dropped += 1
        client.data.append(frame)
        self._wake(client)

    def _queue_control(self, client: _Client, message: str) -> None:  # under the lock
        if client.closing is not None:
            return
        if len(client.control) >= CONTROL_BACKLOG:
            self._disconnect(
                client,
                f"{CONTROL_BACKLOG} replies unread (status, parameter values): read them",
            )
            return
        client.control.append(message)
        self._wake(client)

    def _disconnect(self, client: _Client, reason: str) -> None:  # under the lock
        """Close ``client``'s connection with ``reason`` (code 1008, policy violation);
        it gets nothing more queued."""
        client.closing = reason
        client.control.clear()
        client.data.clear()
        self.disconnected += 1

        with contextlib.suppress(RuntimeError):  # the server has stopped: it is gone
            self._loop.call_soon_threadsafe(self._close_client, client, reason)

    def _close_client(self, client: _Client, reason: str) -> None:  # the server's thread
        self.refusal_sink(f"foxglove client {client.id}", f"disconnected: {reason}")

        async def close() -> None:
            try:  # a client that does not read may never answer the close: abort it then
                await asyncio.wait_for(client.connection.close(1008, reason), _CLOSE_TIMEOUT)
            except (TimeoutError, ConnectionClosed):
                client.connection.transport.abort()

        self._loop.create_task(close())

    def _wake(self, client: _Client) -> None:  # under the lock
        if not client.waking:
            client.waking = True
            self._loop.call_soon_threadsafe(client.wake.set)

    def close(self) -> None:
        """Disconnect every client and stop the thread. Idempotent."""
        self.closed = True
        if self._thread.is_alive():
            self._loop.call_soon_threadsafe(self._stop)
            self._thread.join()

    # -- the server's thread --------------------------------------------------------------

    def _run(self, host: str, port: int) -> None:
        asyncio.set_event_loop(self._loop)

        async def start() -> Server:
            return await serve(
                self._connection,
                host,
                port,
                subprotocols=list(SUBPROTOCOLS),
                compression=None,
                max_size=1 << 20,
            )

        try:
            self._server = self._loop.run_until_complete(start())
        except BaseException as exc:  # e.g. the address is in use
            self._error = exc
            self._ready.set()
            self._loop.close()
            return
        self._ready.set()
        try:
            self._loop.run_forever()
        finally:
            self._loop.run_until_complete(self._loop.shutdown_asyncgens())
            self._loop.close()

    def _stop(self) -> None:
        assert self._server is not None
        self._server.close()

        async def stop() -> None:
            assert self._server is not None
            await self._server.wait_closed()
            self._loop.stop()

        self._loop.create_task(stop())

    async def _connection(self, connection: ServerConnection) -> None:
        with self._lock:
            client = _Client(self._next_client, connection, asyncio.Event())
            self._next_client += 1
            self._clients[client.id] = client
            info = {
                "op": "serverInfo",
                "name": "otonav",
                "capabilities": self.capabilities,
                # what clients may publish in (clientPublish)
                "supportedEncodings": ["cdr", "json"] if self.client_publish else [],
                "metadata": {},
            }
            self._queue_control(client, json.dumps(info))
            channels = [c.advertisement() for c in self._channels.values()]
            self._queue_control(client, json.dumps({"op": "advertise", "channels": channels}))
        writer = asyncio.create_task(self._write(client))
        try:
            async for message in connection:
                self._handle(client, message)
        except ConnectionClosed:
            pass
        finally:
            writer.cancel()
            with self._lock:
                del self._clients[client.id]
                for channel_id in client.subscriptions.values():
                    self._unsubscribed(channel_id)

    async def _write(self, client: _Client) -> None:
        lock, connection = self._lock, client.connection
        try:
            while True:
                await client.wake.wait()
                with lock:
                    client.wake.clear()
                    client.waking = False
                while True:
                    with lock:
                        frame: str | bytes | None = (
                            client.control.popleft()
                            if client.control
                            else client.data.popleft()
                            if client.data
                            else None
                        )
                    if frame is None:
                        break
                    await connection.send(frame)
        except ConnectionClosed:
            pass

    def _handle(self, client: _Client, raw: str | bytes) -> None:
        """One frame from a client; anything malformed is answered by a status (an
        error escaping here would end the client's connection with a traceback)."""
        try:
            if isinstance(raw, bytes):
                self._client_data(client, raw)
                return
            message = json.loads(raw)
            if not isinstance(message, dict):
                raise TypeError(f"expected a JSON object, not {type(message).__name__}")
            op = message["op"]
            if op in ("advertise", "unadvertise") and self.client_publish:
                self._client_advertise(client, op, message)
            elif op in ("getParameters", "setParameters"):
                self._parameter_op(client, op, message)
            elif op == "subscribe":
                self._subscribe_all(client, _list(message, "subscriptions"))
            elif op == "unsubscribe":
                for sub_id in _list(message, "subscriptionIds"):
                    self._unsubscribe(client, _uint32(sub_id, "subscription id"))
            else:
                self._status(client, 1, f"unsupported operation {op!r}: this server only serves")
        except (ValueError, KeyError, TypeError, AttributeError, RecursionError) as exc:
            text = f"bad message ({type(exc).__name__}: {exc})"
            self._status(client, 2, text)
            self.refusal_sink(f"foxglove client {client.id}", text[:MAX_STATUS_CHARS])

    def _client_advertise(self, client: _Client, op: str, message: dict[str, Any]) -> None:
        if op == "unadvertise":
            for channel_id in _list(message, "channelIds"):
                client.advertised.pop(_uint32(channel_id, "channel id"), None)
            return
        for c in _list(message, "channels"):
            channel_id, topic = _uint32(c["id"], "channel id"), _text(c["topic"], "topic")
            encoding = _text(c["encoding"], "encoding")
            if encoding not in ("cdr", "json"):
                self._status(client, 2, f"channel {topic}: encoding {encoding!r}: use cdr or json")
                continue
            if channel_id not in client.advertised and len(client.advertised) >= MAX_ADVERTISED:
                self._status(client, 2, f"channel {topic}: at most {MAX_ADVERTISED} advertised")
                continue
            schema = _text(c.get("schemaName", ""), "schemaName")
            client.advertised[channel_id] = ClientChannel(
                client.id, channel_id, topic, encoding, schema
            )

    def _client_data(self, client: _Client, raw: bytes) -> None:
        if len(raw) < _CLIENT_DATA.size:
            raise ValueError(
                f"a binary message of {len(raw)} bytes: expected opcode 0x01, a channel id "
                "(uint32) and the payload"
            )
        opcode, channel_id = _CLIENT_DATA.unpack_from(raw)
        channel = client.advertised.get(channel_id)
        if opcode != 0x01 or channel is None or not self.client_publish:
            self._status(client, 2, f"client message on unadvertised channel {channel_id}")
            return
        sink = self.client_sink
        problem = (
            f"{channel.topic}: not taken yet (the stack is starting)"
            if sink is None
            else sink(channel, raw[_CLIENT_DATA.size :])
        )
        if problem is not None:
            self._status(client, 2, problem)

    def _parameter_op(self, client: _Client, op: str, message: dict[str, Any]) -> None:
        sink = self.parameter_sink
        request_id = message.get("id")

        def reply(values: list[dict[str, Any]], error: str | None) -> None:
            if error is not None:
                self._status(client, 2, error)
            answer: dict[str, Any] = {"op": "parameterValues", "parameters": values}
            if request_id is not None:
                answer["id"] = request_id
            with self._lock:
                if client.id in self._clients:
                    self._queue_control(client, json.dumps(answer))

        if op == "getParameters":
            names = [_text(n, "parameter name") for n in _list(message, "parameterNames")]
            reply([] if sink is None else list(sink.get_parameters(names)), None)
        else:
            asked = _list(message, "parameters")
            if len(asked) > MAX_CHANGES:  # each is applied on the stack's thread
                raise ValueError(f"{len(asked)} parameters in one request: at most {MAX_CHANGES}")
            changes = [(_text(p["name"], "parameter name"), p.get("value")) for p in asked]
            if sink is None:
                reply([], "parameters: not served yet (the stack is starting)")
            else:
                sink.set_parameters(changes, reply)

    def _subscribe_all(self, client: _Client, subscriptions: list[Any]) -> None:
        """Subscribe to each ``{"id", "channelId"}``: one subscription per channel (as
        foxglove-sdk's servers do), so a message is one frame per client whatever a
        client asks; what is refused is answered by one status for the whole request."""
        asked = [
            (_uint32(sub["id"], "subscription id"), _uint32(sub["channelId"], "channel id"))
            for sub in subscriptions
        ]  # all checked before any is taken
        problems: list[str] = []
        with self._lock:
            for sub_id, channel_id in asked:
                problem = (
                    "the id is in use"
                    if sub_id in client.subscriptions
                    else "no such channel"
                    if channel_id not in self._channels
                    else f"already subscribed as {client.by_channel[channel_id]}"
                    if channel_id in client.by_channel
                    else None
                )
                if problem is not None:
                    problems.append(f"{sub_id} (channel {channel_id}): {problem}")
                    continue
                client.subscriptions[sub_id] = channel_id
                client.by_channel[channel_id] = sub_id
                self._subscribed_channels[channel_id] = (
                    self._subscribed_channels.get(channel_id, 0) + 1
                )
                self.clients_seen.add(client.id)
                self._subscribed_total += 1
                self._changed.notify_all()
                latched = self._latched.get(channel_id)
                if latched is not None:  # a latched topic's newest message, to this client
                    data, log_time = latched
                    self._queue_data(client, _MESSAGE_DATA.pack(0x01, sub_id, log_time) + data)
            if problems:
                more = f" and {len(problems) - 3} more" if len(problems) > 3 else ""
                text = f"subscriptions refused: {'; '.join(problems[:3])}{more}"
                self._queue_control(client, _status(2, text))

    def _unsubscribe(self, client: _Client, sub_id: int) -> None:
        with self._lock:
            channel_id = client.subscriptions.pop(sub_id, None)
            if channel_id is None:
                return
            del client.by_channel[channel_id]
            self._unsubscribed(channel_id)

    def _unsubscribed(self, channel_id: int) -> None:  # under the lock
        left = self._subscribed_channels[channel_id] - 1
        if left:
            self._subscribed_channels[channel_id] = left
        else:
            del self._subscribed_channels[channel_id]

    def _status(self, client: _Client, level: int, text: str) -> None:
        with self._lock:
            self._queue_control(client, _status(level, text))


def _status(level: int, text: str) -> str:
    if len(text) > MAX_STATUS_CHARS:
        text = text[: MAX_STATUS_CHARS - 1] + "…"
    return json.dumps({"op": "status", "level": level, "message": text})


def _list(message: dict[str, Any], key: str) -> list[Any]:
    value = message[key]
    if not isinstance(value, list):
        raise TypeError(f"{key}: expected a list, not {type(value).__name__}")
    return value


def _uint32(value: Any, what: str) -> int:
    """``value`` as the protocol's ids are: an integer in [0, 2**32)."""
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < _UINT32:
        raise ValueError(f"{what} {str(value)[:40]}: expected an integer in [0, 2**32)")
    return value


def _text(value: Any, what: str) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{what}: expected a string, not {type(value).__name__}")
    return value
