"""Embedding otonav in an asyncio service, on the service's own event loop.

Two shapes, one entry point each:

- :func:`open_live_stack`: a live robot on the host's (stock) loop in real-time mode:
  the world is stepped to follow the wall clock (times ``scale``). The host subscribes
  to topics (async iterators of typed messages), publishes goals and commands, reads
  the graph and its statistics; the stack closes cleanly, its recording finished, when
  the ``async with`` exits or the host task is cancelled.

      async with open_live_stack(record_to=Path("live.mcap")) as live:
          await live.publish_goal(4.0, 1.5)
          async with live.subscribe("/odom", Odometry) as odom:
              async for message in odom:
                  ...

- :func:`run_scenario_async`: a fast simulation on request. The scenario runs on its
  own virtual-time loop in a worker thread (at most ``limiter.total`` at once) while
  the host's loop keeps serving; it returns the verdict with its artifact paths.
  Cancelling the awaiting task stops the simulation and waits until its recording is
  finished (an indexed, readable file) before the cancellation propagates.

Blocking work on the host's loop: physics runs inside the real-time clock's advances.
A pacer task consults the clock every half ``max_step_batch`` of wall time, so the
world follows the wall clock in small batches (5 steps of 2 ms between the bridge's
100 Hz wakes, at most 25) even while every actor sleeps; no advance steps more than
``max_step_batch`` (0.05 s of sim time: 25 MuJoCo steps, well under a millisecond for
the shipped robot). After the host's loop stalls for longer than that, the stack does
not catch up in one long burst: sim time *slips* (it falls behind the wall clock by the
excess, counted in :attr:`LiveStack.slip_s`), as a simulator running below real time
does. The other work on the host's loop is the actors' own (a lidar scan ~0.1 ms, an
MCAP chunk compressed every 64 KiB when recording).
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import threading
import weakref
from collections.abc import AsyncIterator, Callable, Sequence
from contextlib import asynccontextmanager
from pathlib import Path
from types import TracebackType
from typing import Any, Generic, TypeVar

import anyio
import anyio.to_thread

from otonav.actors import topics
from otonav.actors.recorder import Recorder
from otonav.hal import RobotHardwareInterface
from otonav.msgs import Header, Message, Point, Pose, PoseStamped, Time
from otonav.record.writer import RecordingWriter
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
    RealTimeClock,
    Reliability,
    Subscription,
    System,
    TimeSource,
)
from otonav.scenario import ScenarioConfig, Verdict, run_scenario
from otonav.scenario.run import effective_stack
from otonav.scenario.validate import check_goal
from otonav.stack import StackConfig, build_actors, build_world
from otonav.stack.rosout import attach_rosout

__all__ = (
    "DEFAULT_MAX_RUNS",
    "HOST_QOS",
    "LiveStack",
    "LiveSubscription",
    "PacedClock",
    "check_run",
    "default_limiter",
    "open_live_stack",
    "run_scenario_async",
)

M = TypeVar("M")
_T = TypeVar("_T")

#: What a host subscription requests by default: best-effort, keep the newest 10. A slow
#: host (a web client) then drops its oldest messages and never holds the robot back.
HOST_QOS = QoS(Reliability.BEST_EFFORT, depth=10)

#: Simulations run at once through :func:`run_scenario_async` with the default limiter.
DEFAULT_MAX_RUNS = 2

_HOST = "host"


# -- real-time clock with a bounded catch-up ---------------------------------------------


class PacedClock(RealTimeClock):
    """:class:`~otonav.runtime.RealTimeClock` whose advances step at most
    ``max_step_batch`` seconds of sim time each.

    Run :meth:`pace` alongside (the live stack does): it consults the clock every half
    batch of wall time, so the world follows the wall clock in small steps even while
    every actor sleeps. A longer gap then means the loop was held up (a stalled host, a
    slow callback): the excess is dropped rather than stepped in one burst, sim time
    slips behind the wall clock by it (:attr:`slip_s`) and follows it again from there.
    """

    def __init__(
        self, source: TimeSource, *, scale: float = 1.0, max_step_batch: float = 0.05
    ) -> None:
        super().__init__(source, scale=scale)
        if not max_step_batch > 0:
            raise ValueError(f"max_step_batch must be > 0 s, got {max_step_batch!r}")
        self.max_batch_ticks = max(1, math.floor(max_step_batch * self._rate + 1e-9))
        self.slipped_ticks = 0

    @property
    def slip_s(self) -> float:
        """Sim seconds dropped so far (how far sim time fell behind the scaled wall)."""
        return self.slipped_ticks / self._rate

    async def pace(self) -> None:
        """Step the world to the wall clock every half batch (wall time), forever."""
        period = self.max_batch_ticks / self._rate / self.scale / 2
        while True:
            await anyio.sleep(period)
            self._follow_wall()

    def _follow_wall(self) -> None:
        wall = self._wall()
        assert self._wall0 is not None
        ticks_per_wall_s = self.scale * self._rate
        target = math.floor((wall - self._wall0) * ticks_per_wall_s + 1e-9)
        excess = target - self._ticks - self.max_batch_ticks
        if excess > 0:
            # Slip: from now on the wall clock maps to sim time `excess` ticks later.
            self._wall0 += excess / ticks_per_wall_s
            self.slipped_ticks += excess
            target -= excess
        self._advance_to(target)

    async def sleep_until(self, sim_time: float) -> None:
        goal = math.ceil(sim_time * self._rate - 1e-9)
        while True:
            await anyio.sleep_until(self.to_loop_time(sim_time))
            self._follow_wall()
            if self._ticks >= goal:
                return
            if goal - self._ticks <= 1:
                # The timer fired a hair early: the world still reaches the asked instant.
                self._advance_to(goal)
                return
            # Sim time slipped while we slept: the instant is later on the wall clock now.


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

    def __init__(
        self,
        system: System,
        hal: RobotHardwareInterface,
        clock: PacedClock,
        writer: RecordingWriter | None,
    ) -> None:
        self._system = system
        self._hal = hal
        self._clock = clock
        self._writer = writer
        self._task: asyncio.Task[None] | None = None
        self._subscriptions: list[LiveSubscription[Any]] = []
        self._publishers: dict[tuple[str, type[Any], QoS], Publisher[Any]] = {}
        self._leaving: list[Subscription[Any]] = []
        self._closing = False
        self._closed = False
        self._close_done: asyncio.Future[None] | None = None
        self._failure: BaseException | None = None

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
        """Sim seconds dropped because the host's loop was held up (see :class:`PacedClock`)."""
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

    def subscribe(self, topic: str, msg_type: type[M], qos: QoS = HOST_QOS) -> LiveSubscription[M]:
        """A mailbox on ``topic`` for the host; QoS and type are checked like a port's
        (a mismatch raises here, naming both ends). Close it (or use ``async with``)
        when done: a reliable one left unread would hold its publishers back."""
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
        pacer = asyncio.get_running_loop().create_task(self._clock.pace(), name="otonav-live-pacer")
        try:
            await self._system.run()
        except Exception as exc:
            self._failure = exc
        finally:
            pacer.cancel()
            for sub in tuple(self._subscriptions):
                sub.close()
            await asyncio.wait((pacer,))

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
        world. Idempotent. If the host cancels the caller meanwhile, the close still
        completes before the cancellation propagates."""
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
                if self._writer is not None:
                    self._writer.finish()
            finally:
                self._hal.close()
                self._close_done.set_result(None)
        if cancelled:
            raise asyncio.CancelledError


@asynccontextmanager
async def open_live_stack(
    stack: StackConfig = StackConfig(),
    *,
    scale: float = 1.0,
    record_to: Path | None = None,
    goal: tuple[float, float] | None = None,
    navigator: bool = True,
    extra_actors: Sequence[Actor] = (),
    max_step_batch: float = 0.05,
) -> AsyncIterator[LiveStack]:
    """Bring the robot stack up on the running (stock asyncio) loop in real-time mode,
    the world stepped to follow the wall clock times ``scale``; yield a
    :class:`LiveStack`. With ``record_to`` every topic goes to that MCAP file, finished
    on every exit. ``goal``: an initial goal for the navigator (or publish one later).

    On exit (normal, an exception, or the host's cancellation) the stack stops and the
    recording is finished. If an actor crashed and stopped the stack while the body ran
    normally, its :class:`~otonav.runtime.ActorCrashedError` is raised on exit.
    """
    hal = build_world(stack)
    live: LiveStack | None = None
    try:
        writer = RecordingWriter(record_to) if record_to is not None else None
        try:
            clock = PacedClock(hal, scale=scale, max_step_batch=max_step_batch)
            actors: list[Actor] = [Recorder(writer)] if writer is not None else []
            actors += [*build_actors(stack, hal, navigator=navigator, goal=goal), *extra_actors]
            system = System(actors, clock=clock)
            attach_rosout(system)
        except BaseException:
            if writer is not None:
                writer.finish()
            raise
        live = LiveStack(system, hal, clock, writer)
        live._start()
        yield live
    finally:
        if live is not None:
            await live.close()
        else:
            hal.close()
    if live.failure is not None:
        raise live.failure


# -- simulations on request ----------------------------------------------------------------

_limiters: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, anyio.CapacityLimiter] = (
    weakref.WeakKeyDictionary()
)


def default_limiter() -> anyio.CapacityLimiter:
    """The running loop's shared limiter for :func:`run_scenario_async`
    (:data:`DEFAULT_MAX_RUNS` at once; set ``.total`` to change it)."""
    loop = asyncio.get_running_loop()
    limiter = _limiters.get(loop)
    if limiter is None:
        limiter = anyio.CapacityLimiter(DEFAULT_MAX_RUNS)
        _limiters[loop] = limiter
    return limiter


_OnStart = Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None]


class _RunControl:
    """Cancels a run on its own loop, from the host's thread, whenever it is asked."""

    def __init__(self, on_start: _OnStart | None) -> None:
        self._lock = threading.Lock()
        self._user_on_start = on_start
        self._loop: asyncio.AbstractEventLoop | None = None
        self._task: asyncio.Task[None] | None = None
        self.cancel_requested = False

    def on_start(self, loop: asyncio.AbstractEventLoop, task: asyncio.Task[None]) -> None:
        with self._lock:
            self._loop, self._task = loop, task
            cancel = self.cancel_requested
        if self._user_on_start is not None:
            self._user_on_start(loop, task)
        if cancel:
            task.cancel()  # we are on the run's loop

    def cancel(self) -> None:
        with self._lock:
            self.cancel_requested = True
            loop, task = self._loop, self._task
        if loop is not None and task is not None:
            with contextlib.suppress(RuntimeError):  # the run's loop already closed
                loop.call_soon_threadsafe(task.cancel)


def check_run(
    scenario: ScenarioConfig, stack: StackConfig = StackConfig(), *, source: str = "scenario"
) -> None:
    """Raise what :func:`run_scenario_async` (and the CLI) would reject before running:
    an unknown or broken scene (:class:`~otonav.hal.mujoco.SceneError`), a goal outside
    the arena or on an obstacle (:class:`~otonav.stack.files.ConfigFileError`). Builds
    the world once (milliseconds): call it from a worker thread on a busy loop."""
    stack = effective_stack(scenario, stack)
    hal = build_world(
        stack,
        extra_obstacles=[b.to_obstacle() for b in scenario.obstacles],
        start=scenario.start.as_tuple(),
    )
    try:
        check_goal(scenario, stack.world.scene, hal.obstacles(), hal.walls(), source=source)
    finally:
        hal.close()


async def run_scenario_async(
    scenario: ScenarioConfig = ScenarioConfig(),
    stack: StackConfig = StackConfig(),
    *,
    out_dir: Path | None,
    record: bool = True,
    plot: bool = True,
    wall_ceiling: float | None = 300.0,
    extra_actors: tuple[Actor, ...] = (),
    limiter: anyio.CapacityLimiter | None = None,
    on_start: _OnStart | None = None,
    source: str = "scenario",
) -> Verdict:
    """:func:`~otonav.scenario.run_scenario` in a worker thread, on its own virtual-time
    loop, while the caller's loop keeps serving. Returns the same verdict (and
    byte-identical recording) as the CLI for the same scenario and config.

    ``limiter``: at most ``limiter.total`` runs at once (default: :func:`default_limiter`,
    2 per loop); a run waits for a slot before it starts. ``on_start(loop, task)`` is
    called in the worker thread as the run starts. ``source`` names the scenario in
    configuration errors (:class:`~otonav.stack.files.ConfigFileError`, raised before
    anything runs), as the CLI does.

    Cancelling the caller (``task.cancel()`` or an anyio cancel scope) cancels the
    simulation on its loop and waits for it to end, so its ``recording.mcap`` is
    finished and indexed when the cancellation reaches the caller. A run cancelled
    while still waiting for a slot never starts and leaves nothing.
    """
    control = _RunControl(on_start)

    def work() -> Verdict | None:
        try:
            return run_scenario(
                scenario,
                stack,
                out_dir=out_dir,
                record=record,
                plot=plot,
                wall_ceiling=wall_ceiling,
                extra_actors=extra_actors,
                on_start=control.on_start,
                source=source,
            )
        except asyncio.CancelledError:
            if control.cancel_requested:
                return None
            raise

    async with limiter if limiter is not None else default_limiter():
        # The thread runs in a task of its own that nothing cancels: the caller's
        # cancellation is turned into the simulation's, then waited out.
        worker = asyncio.get_running_loop().create_task(
            anyio.to_thread.run_sync(work), name=f"otonav-run:{scenario.name}"
        )
        try:
            verdict = await asyncio.shield(worker)
        except asyncio.CancelledError:
            if worker.cancelled():
                raise
            control.cancel()
            await _wait_done(worker)
            if not worker.cancelled():
                worker.exception()  # retrieved: a run cancelled late may have failed
            raise
    if verdict is None:  # pragma: no cover - only when cancelled, handled above
        raise asyncio.CancelledError
    return verdict


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
