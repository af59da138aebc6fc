"""A live robot on the host's loop: :func:`open_live_stack`."""

from __future__ import annotations

import asyncio
import math
from collections.abc import AsyncIterator, Sequence
from contextlib import asynccontextmanager
from pathlib import Path
from types import TracebackType
from typing import Any, Generic, TypeVar

from otonav.actors import topics
from otonav.embed._wait import _wait_done
from otonav.foxglove.view import FoxgloveServer, LiveView, LiveViewOptions
from otonav.hal import RobotHardwareInterface
from otonav.limits import check_scale
from otonav.msgs import Header, Message, Point, Pose, PoseStamped, Time
from otonav.record.writer import RecordingWriter
from otonav.runtime import (
    DEFAULT_QOS,
    LATCHED_QOS,
    MAX_STEP_BATCH,
    Actor,
    Clock,
    Durability,
    Graph,
    MailboxStatistics,
    Publisher,
    QoS,
    RealTimeClock,
    Reliability,
    Subscription,
    System,
)
from otonav.stack import StackConfig, build_actors, build_world
from otonav.stack.robot import robot_frames
from otonav.stack.session import StackSession

M = TypeVar("M")

#: The profile for a host that must never hold the robot back: best-effort, keep the
#: newest 10; a slow host (a web client) drops its oldest messages. Pass it for sensor
#: topics (/odom, /scan: their publishers are best-effort). Not the default: a host
#: subscription defaults to reliable, as ``System.subscribe`` and ROS 2 do (ADR 0056).
HOST_QOS = QoS(Reliability.BEST_EFFORT, depth=10)

_HOST = "host"


# -- host subscriptions -------------------------------------------------------------------


class LiveSubscription(Generic[M]):
    """A host's mailbox on one topic: an async iterator of typed messages that ends
    (``StopAsyncIteration``) once closed, by :meth:`close`, its ``async with``, or the
    stack closing. Cancelling a task waiting in ``__anext__`` loses no message."""

    def __init__(self, live: LiveStack, subscription: Subscription[M]) -> None:
        self._live = live
        self._sub = subscription
        self._recv: asyncio.Task[M] | None = None
        self._closed = False

    @property
    def topic(self) -> str:
        return self._sub.topic

    @property
    def closed(self) -> bool:
        return self._closed

    def statistics(self) -> MailboxStatistics:
        return self._sub.statistics()

    def try_recv(self) -> M | None:
        """The oldest waiting message, or None (also once closed)."""
        if self._closed or self._recv is not None:
            return None
        return self._sub.try_recv()

    def take_latest(self) -> M | None:
        """The newest waiting message, dropping older ones, or None."""
        if self._closed or self._recv is not None:
            return None
        return self._sub.take_latest()

    def __aiter__(self) -> LiveSubscription[M]:
        return self

    async def __anext__(self) -> M:
        if self._closed:
            raise StopAsyncIteration
        if self._recv is None:
            message = self._sub.try_recv()
            if message is not None:
                return message
            # One receive in flight, kept across a cancelled wait: nothing is lost.
            self._recv = asyncio.get_running_loop().create_task(
                self._sub.recv(), name=f"otonav-host-recv:{self._sub.topic}"
            )
        recv = self._recv
        try:
            message = await asyncio.shield(recv)
        except asyncio.CancelledError:
            task = asyncio.current_task()
            cancelling = task.cancelling() if task is not None else 0
            if self._closed and recv.cancelled() and not cancelling:
                raise StopAsyncIteration from None
            raise
        self._recv = None
        return message

    def close(self) -> None:
        """Stop receiving; the iterator ends and the mailbox leaves the topic."""
        if self._closed:
            return
        self._closed = True
        if self._recv is not None:
            self._recv.cancel()
        # Drained, it never holds a publisher back (reliable backpressure) again.
        while self._sub.try_recv() is not None:
            pass
        self._live._forget(self._sub)

    async def __aenter__(self) -> LiveSubscription[M]:
        return self

    async def __aexit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()


# -- the live stack -----------------------------------------------------------------------


class LiveStack:
    """A robot stack running on the host's loop in real-time mode (see the module
    docstring). Made by :func:`open_live_stack`."""

    def __init__(self, session: StackSession, clock: RealTimeClock) -> None:
        self._session = session
        self._system = session.system
        self._hal = session.hal
        self._clock = clock
        self._writer = session.writer
        self._task: asyncio.Task[None] | None = None
        self._subscriptions: list[LiveSubscription[Any]] = []
        self._publishers: dict[tuple[str, type[Any], QoS], Publisher[Any]] = {}
        self._leaving: list[Subscription[Any]] = []
        self._closing = False
        self._closed = False
        self._close_done: asyncio.Future[None] | None = None
        self._failure: BaseException | None = None
        self.foxglove: FoxgloveServer | None = None
        self.ros2: Actor | None = None
        """The ROS 2 bridge (``open_live_stack(ros2=True)``), else None."""
        """The Foxglove live view's server, when asked for (``foxglove=True``)."""

    # -- what a host reads

    @property
    def system(self) -> System:
        return self._system

    @property
    def hal(self) -> RobotHardwareInterface:
        """The robot's hardware interface (simulated: ground truth is here)."""
        return self._hal

    @property
    def clock(self) -> Clock:
        """Sim time of the stack (pass ``clock=live.clock`` to ``until``/``next_message``)."""
        return self._clock

    @property
    def slip_s(self) -> float:
        """Sim seconds dropped because the host's loop was held up (see
        :class:`~otonav.runtime.RealTimeClock`)."""
        return self._clock.slip_s

    @property
    def recording(self) -> Path | None:
        return self._writer.path if self._writer is not None else None

    @property
    def running(self) -> bool:
        """True until the stack is closed or an actor stopped it by crashing."""
        return self._task is not None and not self._task.done() and not self._closing

    @property
    def failure(self) -> BaseException | None:
        """Why the stack stopped on its own (an actor crash), if it did."""
        return self._failure

    def now(self) -> float:
        """Current sim time, s."""
        return self._clock.now()

    def graph(self) -> Graph:
        """Actors, topics, types, QoS and live statistics (drops, queue depths)."""
        return self._system.graph()

    # -- subscribing and publishing

    def subscribe(
        self, topic: str, msg_type: type[M], qos: QoS = DEFAULT_QOS
    ) -> LiveSubscription[M]:
        """A mailbox on ``topic`` for the host; QoS and type are checked like a port's
        (a mismatch raises here, naming both ends). ``qos`` defaults to reliable, as
        everywhere (ADR 0056): a best-effort sensor topic wants :data:`HOST_QOS`. Close
        it (or use ``async with``) when done: a reliable one left unread would hold its
        publishers back."""
        self._check_open()
        sub = self._system.subscribe(topic, msg_type, qos, name=_HOST)
        live = LiveSubscription(self, sub)
        self._subscriptions.append(live)
        return live

    def publisher(self, topic: str, msg_type: type[M], qos: QoS | None = None) -> Publisher[M]:
        """The host's publisher on ``topic`` (one per topic, type and QoS). ``qos=None``:
        reliable, and transient-local (latched) when a subscriber asks for it, as on
        /goal."""
        self._check_open()
        if qos is None:
            existing = self._system.bus.topics.get(topic)
            latched = existing is not None and any(
                s.qos.durability is Durability.TRANSIENT_LOCAL for s in existing.subscriptions
            )
            qos = LATCHED_QOS if latched else DEFAULT_QOS
        key = (topic, msg_type, qos)
        publisher = self._publishers.get(key)
        if publisher is None:
            publisher = self._system.publisher(topic, msg_type, qos, name=_HOST)
            self._publishers[key] = publisher
        return publisher

    async def publish(self, topic: str, message: Message, qos: QoS | None = None) -> None:
        """Publish ``message`` on ``topic`` (waits only on a full reliable mailbox)."""
        await self.publisher(topic, type(message), qos).publish(message)

    async def publish_goal(self, x: float, y: float, *, frame_id: str = "odom") -> None:
        """Send the navigator to ``(x, y)`` (m, odom frame) on /goal (latched)."""
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ValueError(f"goal must be finite, got ({x!r}, {y!r})")
        goal = PoseStamped(
            header=Header(stamp=Time.from_seconds(self._clock.now()), frame_id=frame_id),
            pose=Pose(position=Point(x=float(x), y=float(y))),
        )
        await self.publish(topics.GOAL, goal, LATCHED_QOS)

    # -- lifecycle

    def _check_open(self) -> None:
        if self._closing:
            raise RuntimeError("the live stack is closed")

    def _start(self) -> None:
        self._task = asyncio.get_running_loop().create_task(self._run(), name="otonav-live")

    async def _run(self) -> None:
        # Its own task: the host's code is not inside the system's cancel scope, so a
        # crashing actor stops the stack, not the host.
        if self._closing:
            return
        try:
            # The session runs the pacer; close() tears it down once this task ended.
            await self._session.run(close=False)
        except Exception as exc:
            self._failure = exc
        finally:
            for sub in tuple(self._subscriptions):
                sub.close()

    def _forget(self, sub: Subscription[Any]) -> None:
        self._subscriptions = [s for s in self._subscriptions if s._sub is not sub]
        self._leaving.append(sub)
        self._unsubscribe_when_safe()

    def _unsubscribe_when_safe(self) -> None:
        for sub in self._leaving:
            self._system.bus.unsubscribe(sub)
        self._leaving = []

    async def close(self) -> None:
        """Stop every actor (each ``on_stop`` runs), finish the recording, release the
        world, in the one teardown order of :mod:`otonav.stack.session`. Idempotent.
        If the host cancels the caller meanwhile, the close still completes before the
        cancellation propagates."""
        if self._close_done is not None:  # closed, or being closed by another task
            if await _wait_done(self._close_done):
                raise asyncio.CancelledError
            return
        self._close_done = asyncio.get_running_loop().create_future()
        self._closing = True
        for sub in tuple(self._subscriptions):
            sub.close()
        self._system.stop()
        cancelled = False
        try:
            if self._task is not None:
                cancelled = await _wait_done(self._task)
        finally:
            self._closed = True
            try:
                self._session.close()
            finally:
                self._close_done.set_result(None)
        if cancelled:
            raise asyncio.CancelledError


def _foxglove_server(foxglove: bool | LiveViewOptions) -> FoxgloveServer | None:
    if foxglove is False:
        return None
    return FoxgloveServer(foxglove if isinstance(foxglove, LiveViewOptions) else LiveViewOptions())


@asynccontextmanager
async def open_live_stack(
    stack: StackConfig = StackConfig(),
    *,
    scale: float = 1.0,
    record_to: Path | RecordingWriter | None = None,
    goal: tuple[float, float] | None = None,
    navigator: bool = True,
    extra_actors: Sequence[Actor] = (),
    max_step_batch: float = MAX_STEP_BATCH,
    foxglove: bool | LiveViewOptions = False,
    ros2: bool = False,
) -> AsyncIterator[LiveStack]:
    """Bring the robot stack up on the running (stock asyncio) loop in real-time mode,
    the world stepped to follow the wall clock times ``scale``; yield a
    :class:`LiveStack`. With ``record_to`` every topic goes to that MCAP file, finished
    on every exit (or to that writer, e.g. a size-capped
    :class:`~otonav.record.rotating.RotatingRecordingWriter`). ``goal``: an initial
    goal for the navigator (or publish one later). Which planner runs, and whether the
    safety layer does, is the stack config's (``nav.planner``, ``safety.enabled``);
    ``navigator=False`` is the deprecated spelling of ``nav.planner: external``.

    On exit (normal, an exception, or the host's cancellation) the stack stops and the
    recording is finished. If an actor crashed and stopped the stack while the body ran
    normally, its :class:`~otonav.runtime.ActorCrashedError` is raised on exit.
    A ``scale`` outside [0.01, 100] raises ``ValueError`` (``otonav.limits``).

    ``foxglove=True`` (or :class:`~otonav.foxglove.view.LiveViewOptions`) also serves
    every topic to Foxglove over WebSocket (127.0.0.1:8765 by default; ``live.foxglove``
    is the server, stopped on exit).

    ``ros2=True`` (or ``ros2.enabled`` in ``stack``) also mirrors every topic on DDS as a
    ROS 2 node does and takes the section's ``inputs`` in (the ``otonav[ros2]`` extra;
    ADR 0047): ``live.ros2`` is the bridge.
    """
    problem = check_scale(scale, "scale")
    if problem is not None:
        raise ValueError(problem)
    server = _foxglove_server(foxglove)
    try:
        hal = build_world(stack)
    except BaseException:
        if server is not None:
            server.close()
        raise
    live: LiveStack | None = None
    try:
        try:
            actors = [*build_actors(stack, hal, navigator=navigator, goal=goal), *extra_actors]
            if server is not None:
                actors.append(LiveView(server))
            bridge = None
            if ros2 or stack.ros2.enabled:
                from otonav.ros2 import bridge_for

                bridge = bridge_for(stack.ros2, base_frame=robot_frames(stack.robot).base)
                actors.append(bridge)
        except BaseException:
            hal.close()
            if server is not None:
                server.close()
            raise
        try:  # the session owns the world from here (it closes it if it fails)
            session = StackSession(
                hal, actors, realtime=scale, record_to=record_to, max_step_batch=max_step_batch
            )
        except BaseException:
            if server is not None:
                server.close()
            raise
        clock = session.realtime_clock
        assert clock is not None
        if server is not None:
            session.add_cleanup(server.close)
        live = LiveStack(session, clock)
        live.foxglove = server
        live.ros2 = bridge
        live._start()
        yield live
    finally:
        if live is not None:
            await live.close()
    if live.failure is not None:
        raise live.failure
