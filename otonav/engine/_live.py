"""A live robot stack on the running loop: :func:`open_live_stack`, the one way to hold
a stack open and talk to it (a host service on its stock loop in real time; a pytest test
on its virtual-time loop, through ``otonav.testing.running_stack``)."""

from __future__ import annotations

import asyncio
import math
from collections.abc import AsyncIterator, Sequence
from contextlib import asynccontextmanager
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Any, Generic, TypeVar

import anyio

from otonav.actors import _topics as topics
from otonav.engine._extras import open_extras
from otonav.hal import BoxObstacle, RobotHardwareInterface
from otonav.msgs import Header, Message, Point, Pose, PoseStamped, Time
from otonav.record._writer import RecordingWriter
from otonav.runtime import (
    DEFAULT_QOS,
    LATCHED_QOS,
    Actor,
    Clock,
    Durability,
    Graph,
    MailboxStatistics,
    Publisher,
    QoS,
    RealTime,
    Reliability,
    Subscription,
    System,
    TimeMode,
)
from otonav.runtime._clock import reset_current_clock, set_current_clock
from otonav.stack import StackConfig, build_actors, build_world
from otonav.stack._session import StackSession

if TYPE_CHECKING:
    from otonav.foxglove import FoxgloveServer

M = TypeVar("M")

#: The profile for a host that must never hold the robot back: best-effort, keep the
#: newest 10; a slow host (a web client) drops its oldest messages. Pass it for sensor
#: topics (/odom, /scan: their publishers are best-effort). Not the default: a host
#: subscription defaults to reliable, as ``System.subscribe`` and ROS 2 do (ADR 0056).
HOST_QOS = QoS(Reliability.BEST_EFFORT, depth=10)

_HOST = "host"


async def _wait_done(future: asyncio.Future[Any]) -> bool:
    """Wait until ``future`` is done whatever cancels the caller meanwhile (anyio cancel
    scopes are shielded, asyncio's ``task.cancel()`` is absorbed). Returns True when the
    caller was cancelled while waiting; the caller re-raises then."""
    cancelled = False
    with anyio.CancelScope(shield=True):
        while not future.done():
            try:
                await asyncio.wait((future,))
            except asyncio.CancelledError:
                cancelled = True
    return cancelled


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
    """A robot stack running on the current loop, in the session's time mode (see the
    module docstring). Made by :func:`open_live_stack`."""

    def __init__(self, session: StackSession) -> None:
        self._session = session
        self._system = session.system
        self._hal = session.hal
        self._writer = session.writer
        self._task: asyncio.Task[None] | None = None
        self._subscriptions: list[LiveSubscription[Any]] = []
        self._publishers: dict[tuple[str, type[Any], QoS], Publisher[Any]] = {}
        self._closing = False
        self._close_done: asyncio.Future[None] | None = None
        self._failure: BaseException | None = None
        self._started = asyncio.Event()
        self.foxglove: FoxgloveServer | None = None
        """The Foxglove live view's server (``foxglove.enabled``), else None."""
        self.ros2: Actor | None = None
        """The ROS 2 bridge (``ros2.enabled``), else None."""

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
        return self._session.clock

    @property
    def slip_s(self) -> float:
        """Sim seconds dropped because the host's loop was held up (real time: see
        :class:`~otonav.runtime.RealTimeClock`; 0 in virtual time, which never slips)."""
        clock = self._session.realtime_clock
        return 0.0 if clock is None else clock.slip_s

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
        return self._session.clock.now()

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
            header=Header(stamp=Time.from_seconds(self.now()), frame_id=frame_id),
            pose=Pose(position=Point(x=float(x), y=float(y))),
        )
        await self.publish(topics.GOAL, goal, LATCHED_QOS)

    # -- lifecycle

    def _check_open(self) -> None:
        if self._closing:
            raise RuntimeError("the live stack is closed")

    async def _start(self) -> None:
        """Run the stack in a task of its own; return once it is up (its actors started,
        the world the loop's time source in virtual time) or failed to start."""
        self._task = asyncio.get_running_loop().create_task(self._run(), name="otonav-live")
        await self._started.wait()

    async def _run(self) -> None:
        # Its own task: the host's code is not inside the system's cancel scope, so a
        # crashing actor stops the stack, not the host.
        if self._closing:
            return
        try:
            # The session runs the pacer; close() tears it down once this task ended.
            async with self._session.running(close=False) as system:
                self._started.set()
                await system.wait_finished()
        except Exception as exc:
            self._failure = exc
        finally:
            self._started.set()
            for sub in tuple(self._subscriptions):
                sub.close()

    def _forget(self, sub: Subscription[Any]) -> None:
        self._subscriptions = [s for s in self._subscriptions if s._sub is not sub]
        self._system.bus.unsubscribe(sub)

    async def close(self) -> None:
        """Stop every actor (each ``on_stop`` runs), finish the recording, release the
        world, in the one teardown order of :mod:`otonav.stack._session`. Idempotent.
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
            try:
                self._session.close()
            finally:
                self._close_done.set_result(None)
        if cancelled:
            raise asyncio.CancelledError


@asynccontextmanager
async def open_live_stack(
    stack: StackConfig = StackConfig(),
    *,
    time: TimeMode = RealTime(),
    record_to: Path | RecordingWriter | None = None,
    goal: tuple[float, float] | None = None,
    extra_actors: Sequence[Actor] = (),
    extra_obstacles: Sequence[BoxObstacle] = (),
) -> AsyncIterator[LiveStack]:
    """Bring the robot stack up on the running loop and yield a :class:`LiveStack`.
    ``time=RealTime(scale)`` (the default, scale 1): the world stepped to follow the wall
    clock, on any loop (a host service's). ``time=Virtual()``: the world becomes the
    running :class:`~otonav.runtime.VirtualTimeLoop`'s time source (a test marked
    ``@pytest.mark.sim``; ``otonav.testing.running_stack`` is this with virtual time as its
    default). ``extra_obstacles``: boxes added to the world. With ``record_to`` every
    topic goes to that MCAP file, finished on every exit (or to that writer, e.g. a
    size-capped :class:`~otonav.record._rotating.RotatingRecordingWriter`). ``goal``: an
    initial goal for the navigator (or publish one later). Which planner runs, and whether the
    safety layer does, is the stack config's (``nav.planner``, ``safety.enabled``).

    On exit (normal, an exception, or the host's cancellation) the stack stops and the
    recording is finished. If an actor crashed and stopped the stack while the body ran
    normally, its :class:`~otonav.runtime.ActorCrashedError` is raised on exit.

    The stack config's optional sections run too, made as every entry point makes them
    (:func:`otonav.engine.open_extras`): ``foxglove.enabled`` serves every topic and the
    actors' parameters to Foxglove over WebSocket (``live.foxglove`` is the server);
    ``ros2.enabled`` mirrors every topic on DDS as a ROS 2 node does and takes the
    section's ``inputs`` in (the ``otonav[ros2]`` extra; ADR 0047): ``live.ros2`` is the
    bridge. Both stop on exit. One that cannot start raises
    :class:`~otonav.engine.ExtrasError` (one line) before anything runs.
    """
    extras = open_extras(stack)
    try:
        hal = build_world(stack, extra_obstacles=extra_obstacles)
    except BaseException:
        extras.close()
        raise
    live: LiveStack | None = None
    try:
        try:
            actors = [*build_actors(stack, hal, goal=goal), *extra_actors, *extras.actors]
        except BaseException:
            hal.close()
            extras.close()
            raise
        try:  # the session owns the world from here (it closes it if it fails)
            session = StackSession(hal, actors, time=time, record_to=record_to)
        except BaseException:
            extras.close()
            raise
        session.add_cleanup(extras.close)
        extras.serve_parameters(session.system)
        live = LiveStack(session)
        live.foxglove = extras.foxglove
        live.ros2 = extras.ros2
        await live._start()
        # The host's code (a test's until(), next_message()) asks the stack's clock, as an
        # actor would; the stack's task set it in its own context only.
        token = set_current_clock(session.clock)
        try:
            yield live
        finally:
            reset_current_clock(token)
    finally:
        if live is not None:
            await live.close()
    if live.failure is not None:
        raise live.failure
