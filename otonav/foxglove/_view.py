"""Live view: every topic served over the Foxglove WebSocket protocol while the stack
runs, with the recordings' ROS 2 schemas and CDR payloads (so Foxglove's 3D panel draws
the robot, its scan and /tf live), stamped with sim time.

Two parts (docs/adr/0031-live-view-over-foxglove-sdk.md, amended by 0032):

- :class:`FoxgloveServer` serves the protocol (:mod:`otonav.foxglove._protocol`,
  on ``websockets``: the optional extra ``otonav[foxglove]``), under both its names,
  ``foxglove.sdk.v1`` and ``foxglove.websocket.v1``. The server runs on its own thread;
  handing it a message queues a frame and returns, and each client has a bounded
  backlog that drops (and counts) its oldest data message when the client does not keep
  up. Neither the loop nor the robot ever waits for a client.
- :class:`LiveView` is an actor that taps every topic (like the recorder, but lossy):
  each tap is a best-effort mailbox that keeps the newest ``depth`` messages with their
  publish instants and counts what it drops; every ``period`` s of sim time the actor
  encodes what came in, for the channels some client subscribed to only, hands it to
  the server and broadcasts the sim time. Latched topics (/tf_static, /goal) are sent
  again to each client that subscribes to them, since the protocol has no latching.

It also acts (docs/adr/0044): clients may publish (``clientPublish``) on the topics of
the server's ``client_publish`` (``/goal`` by default: Foxglove's Publish panel or
3D panel sends a goal), in CDR or JSON, each message decoded and checked against the
topic's type on the server's thread and published from the loop's; and, once
:meth:`LiveView.serve_parameters` is given the system's actors, read and set
parameters (``parameters``, :mod:`otonav.stack._live_parameters`). Every change, and
every refusal, is logged on /rosout, so the recording shows it.
"""

from __future__ import annotations

import asyncio
import contextlib
import threading
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import anyio
from pydantic import ValidationError

from otonav.actors import _topics as topics
from otonav.msgs import Log, Message, Time
from otonav.record.cdr import decode, encode
from otonav.runtime import Actor, Bus, Durability, Output, QoS, Reliability, run_blocking
from otonav.runtime._mailbox import Endpoint, Publisher, Subscription, Topic
from otonav.stack._door import Refusals, refusal
from otonav.stack._live_parameters import ActorParameters, ParameterError

if TYPE_CHECKING:
    from otonav.foxglove._protocol import FoxgloveServer

_EARLY_CHANGES = 64
"""``setParameters`` requests kept while the stack starts (applied as it does)."""

# Matches every publisher (ROS 2 rules): tapping a topic never makes wiring fail.
_TAP_QOS = QoS(Reliability.BEST_EFFORT, depth=1)


class _Tap(Subscription[Any]):
    """A lossy mailbox that keeps (publish instant, message), newest ``keep``."""

    __slots__ = ("_keep", "_now", "_stamped")

    def __init__(self, topic: Topic[Any], endpoint: Endpoint, keep: int, now: Any) -> None:
        super().__init__(topic.name, topic.msg_type, _TAP_QOS, endpoint)
        self._keep = keep
        self._now = now
        self._stamped: deque[tuple[float, Any]] = deque()

    def _offer(self, message: Any) -> bool:
        stamped = self._stamped
        if len(stamped) >= self._keep:
            stamped.popleft()
            self.dropped += 1
        stamped.append((self._now(), message))
        self.received += 1
        return True

    def _full(self) -> bool:
        return False

    def take_all(self) -> deque[tuple[float, Any]]:
        taken, self._stamped = self._stamped, deque()
        self.taken += len(taken)
        return taken

    def statistics(self) -> Any:
        stats = super().statistics()
        return stats._replace(queued=len(self._stamped), depth=self._keep)


class LiveViewStatistics(NamedTuple):
    """Counters of a live view."""

    sent: int
    """Messages handed to the server (for channels some client subscribed to)."""
    dropped: int
    """Messages the taps dropped because the live view fell behind (never the robot)."""
    clients: int
    """Clients subscribed to at least one channel now."""
    clients_seen: int
    client_dropped: int = 0
    """Messages the server dropped for clients that did not keep up (backlog full)."""


@dataclass(slots=True)
class _TopicState:
    topic: Topic[Any]
    tap: _Tap
    channel: Any
    latched: bool
    sent: int = 0


class LiveView(Actor):
    """Serves every topic of its system through ``server`` (see the module docstring)."""

    rosout = Output(topics.ROSOUT, Log, topics.ROSOUT_QOS)

    def __init__(
        self,
        server: FoxgloveServer,
        *,
        depth: int = 64,
        period: float = 0.02,
        name: str = "foxglove",
    ) -> None:
        """``depth``: messages each topic's tap keeps between two flushes before dropping
        its oldest; ``period``: s of sim time between flushes (50 Hz at 1x)."""
        super().__init__(name)
        self.server = server
        self.depth, self.period = depth, period
        self._topics: dict[str, _TopicState] = {}
        self.sent_bytes = 0
        self._client_publishers: dict[str, Publisher[Any]] = {}
        self._loop: asyncio.AbstractEventLoop | None = None
        self._parameters: ActorParameters | None = None
        # Changes asked before the loop runs (served while the stack starts), applied as
        # the live view starts; the lock orders them against on_start taking the loop.
        self._early_changes: list[tuple[list[tuple[str, Any]], Any]] = []
        self._early_lock = threading.Lock()
        self.client_messages = 0
        """Messages clients published that were taken."""
        self.refusals = Refusals(lambda text: self._log(Log.WARN, text))
        """What clients sent that the door refused (``otonav.stack._door``), malformed
        frames, and clients disconnected for going over a bound, by client."""
        server.refusal_sink = self._refuse

    def on_wired(self, bus: Bus) -> None:
        for topic in list(bus.topics.values()):
            self._tap(topic)
        bus.add_topic_listener(self._tap)
        for name in self.server.client_publish:
            used = bus.topics.get(name)
            if used is None:
                continue  # nobody uses it in this system: refused when a client sends
            # What its own publishers offer (a latched /goal stays latched), else what
            # serves every subscriber (reliable; transient-local if one asks for it).
            latched = any(
                e.qos.durability is Durability.TRANSIENT_LOCAL for e in used.subscriptions
            )
            qos = (
                used.publishers[0].qos
                if used.publishers
                else QoS(depth=1, durability=Durability.TRANSIENT_LOCAL)
                if latched
                else QoS()
            )
            endpoint = Endpoint(self.name, f"client{name}")
            self._client_publishers[name] = bus.publisher(
                name, used.msg_type, qos, endpoint=endpoint
            )

    # -- acting: client messages and parameters (called on the server's thread) ---------

    def _take_client_message(self, channel: Any, payload: bytes) -> str | None:
        """Publish a client's message once it passed the door; else why not (a status)."""
        problem = self._client_message_problem(channel, payload)
        if problem is not None:
            self._refuse(f"foxglove client {channel.client}", problem)
        return problem

    def _client_message_problem(self, channel: Any, payload: bytes) -> str | None:
        publisher = self._client_publishers.get(channel.topic)
        loop = self._loop
        if publisher is None:
            allowed = ", ".join(sorted(self._client_publishers)) or "none"
            return f"{channel.topic}: clients may not publish here (allowed: {allowed})"
        kind: type[Message] = publisher.msg_type
        if channel.schema_name and channel.schema_name not in (
            kind.ros_type,
            kind.ros_type.replace("/msg/", "/"),
        ):
            return f"{channel.topic}: is {kind.ros_type}, not {channel.schema_name}"
        try:
            message = (
                kind.model_validate_json(payload)
                if channel.encoding == "json"
                else decode(kind, payload)
            )
        except (ValidationError, ValueError, IndexError, OverflowError, RecursionError) as exc:
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            return f"{channel.topic}: not a {kind.ros_type} in {channel.encoding} ({first})"
        problem = refusal(message)
        if problem is not None:
            return f"{channel.topic}: {problem}"
        if loop is None or loop.is_closed():
            return f"{channel.topic}: not taken (the stack is not running)"
        loop.call_soon_threadsafe(self._publish_client, publisher, message, channel.client)
        return None

    def _refuse(self, source: str, text: str) -> None:
        """Count and log a refusal (on the loop's thread once it runs; any thread)."""
        loop = self._loop
        if loop is None:
            self.refusals.refuse(source, text, log=False)  # nothing runs yet: no /rosout
            return
        with contextlib.suppress(RuntimeError):  # the loop has closed: the run is over
            loop.call_soon_threadsafe(self.refusals.refuse, source, text)

    def _publish_client(self, publisher: Publisher[Any], message: Message, client: int) -> None:
        try:
            publisher.publish_nowait(message)
            self.client_messages += 1
        except anyio.WouldBlock:  # counted and logged as refusals are: a flood stays bounded
            self.refusals.refuse(f"foxglove client {client}", f"{publisher.topic}: full, dropped")

    def serve_parameters(self, actors: Iterable[Actor]) -> ActorParameters:
        """Serve the parameters of ``actors`` (the system's) to clients; the table served.
        May be called before the system runs: a change asked meanwhile is applied as the
        live view starts, at the start's sim time."""
        self._parameters = table = ActorParameters(actors)
        self.server.parameter_sink = self
        return table

    def get_parameters(self, names: list[str]) -> list[dict[str, Any]]:
        table = self._parameters
        values = table.values() if table is not None else {}
        wanted = names or list(values)
        return [{"name": n, "value": values[n]} for n in wanted if n in values]

    def set_parameters(self, changes: list[tuple[str, Any]], reply: Any) -> None:
        with self._early_lock:
            loop = self._loop
            if loop is None:  # the stack is starting: applied by on_start
                if len(self._early_changes) >= _EARLY_CHANGES:
                    reply([], "parameters: too many changes while the stack starts")
                    return
                self._early_changes.append((changes, reply))
                return
        if loop.is_closed():
            reply([], "parameters: the stack is not running")
            return
        loop.call_soon_threadsafe(self._apply_parameters, changes, reply)

    def _apply_parameters(self, changes: list[tuple[str, Any]], reply: Any) -> None:
        table = self._parameters
        assert table is not None
        errors: list[str] = []
        for name, value in changes:
            try:
                old, new = table.set(name, value)
            except ParameterError as exc:
                errors.append(str(exc))
                self.refusals.refuse("a foxglove client's parameters", str(exc))
                continue
            self._log(Log.INFO, f"parameter {name}: {old!r} -> {new!r} (set by a client)")
        reply(self.get_parameters([name for name, _ in changes]), "; ".join(errors) or None)

    def _log(self, level: int, text: str) -> None:
        log = Log(stamp=Time.from_seconds(self._now()), level=level, name=self.name, msg=text)
        # /rosout full: the line is lost, the robot is not held
        with contextlib.suppress(anyio.WouldBlock):
            self.rosout.publish_nowait(log)

    def _now(self) -> float:
        # Until the System hands out clocks, time is the start (0).
        clock = self._otonav_clock
        return clock.now() if clock is not None else 0.0

    def _tap(self, topic: Topic[Any]) -> None:
        if topic.name in self._topics:
            return
        tap = _Tap(topic, Endpoint(self.name, topic.name), self.depth, self._now)
        topic.subscriptions.append(tap)
        latched = any(p.qos.durability is Durability.TRANSIENT_LOCAL for p in topic.publishers)
        channel = self.server.channel(topic.name, topic.msg_type)
        self._topics[topic.name] = _TopicState(topic, tap, channel, latched)
        for publisher in topic.publishers:  # history a transient-local publisher kept
            for message in publisher._history or ():
                tap._offer(message)

    async def on_start(self) -> None:
        with self._early_lock:
            self._loop = asyncio.get_running_loop()
            early, self._early_changes = self._early_changes, []
        for changes, reply in early:
            self._apply_parameters(changes, reply)
        self.server.client_sink = self._take_client_message
        wait = self.server.config.wait_for_subscriber
        if wait is not None:  # a worker thread waits; sim time holds still (run_blocking)
            await run_blocking(self.server.wait_for_subscriptions, self.server.awaited, wait)

    async def run(self) -> None:
        rate = self.clock.rate(1.0 / self.period)
        while True:
            await rate.sleep()
            self.flush()

    def flush(self) -> None:
        """Hand everything tapped since the last flush to the server."""
        server = self.server
        if server.closed:
            return
        for state in self._topics.values():
            taken = state.tap.take_all()
            if not taken:
                continue
            if not state.latched:
                # A latched topic's publisher may arrive after the tap: look again.
                state.latched = any(
                    p.qos.durability is Durability.TRANSIENT_LOCAL for p in state.topic.publishers
                )
            channel = state.channel
            if not (state.latched or channel.has_sinks()):
                continue  # nobody watches: do not even encode
            for instant, message in taken:
                data = encode(message)
                stamp = round(instant * 1e9)
                channel.log(data, log_time=stamp)
                state.sent += 1
                self.sent_bytes += len(data)
                if state.latched:
                    server.latch(channel, data, stamp)
        server.broadcast_time(self._now())

    async def on_stop(self) -> None:
        self.flush()

    def statistics(self) -> LiveViewStatistics:
        server = self.server
        return LiveViewStatistics(
            sent=sum(s.sent for s in self._topics.values()),
            dropped=sum(s.tap.dropped for s in self._topics.values()),
            clients=len(server.subscriptions),
            clients_seen=len(server.clients_seen),
            client_dropped=server.dropped,
        )

    def topic_statistics(self) -> dict[str, tuple[int, int]]:
        """topic -> (messages sent, messages dropped by its tap)."""
        return {name: (s.sent, s.tap.dropped) for name, s in self._topics.items()}
