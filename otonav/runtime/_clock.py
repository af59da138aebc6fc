"""Sim time as actors see it, in both modes: one contract, two implementations.

Actors never read the wall clock and never pick a mode: they ask their :class:`Clock`
for ``now()`` and sleep until a sim time (as trio's tasks ask its one ``Clock`` ABC).
In virtual mode the loop's time *is* sim time (:class:`VirtualClock`); in real-time
mode a stock loop runs on the wall clock and the world is stepped to follow it,
optionally scaled, at most :data:`MAX_STEP_BATCH` at once (:class:`RealTimeClock`).
What is stepped is the world's :class:`~otonav.runtime._timesource.TimeSource`, a
separate contract (the world's side, not the actors'). ADR 0055 lists the time types.
"""

from __future__ import annotations

import asyncio
import contextvars
import math
from abc import ABC, abstractmethod
from collections.abc import Callable

import anyio

from otonav.runtime._loop import VirtualTimeLoop
from otonav.runtime._stepper import Stepper
from otonav.runtime._timesource import TimeSource

_current: contextvars.ContextVar[Clock] = contextvars.ContextVar("otonav_clock")


class Clock(ABC):
    """Sim time for actors and waits."""

    @abstractmethod
    def now(self) -> float:
        """Current sim time, seconds."""

    @abstractmethod
    def to_loop_time(self, sim_time: float) -> float:
        """The running loop's ``time()`` at which sim time reaches ``sim_time`` (for
        anyio cancel-scope deadlines)."""

    @abstractmethod
    def watch(self, check: Callable[[], bool]) -> Callable[[], None]:
        """Evaluate ``check()`` as sim time advances until it returns True.
        Returns a function that stops watching."""

    @property
    def resolution(self) -> float:
        """The smallest step sim time moves by, s (one tick of the world); 0 if unknown."""
        return 0.0

    def reached(self, sim_time: float) -> bool:
        """Whether sim time has reached ``sim_time`` (to within one tick)."""
        return self.now() + self.resolution >= sim_time

    async def sleep_until(self, sim_time: float) -> None:
        """Sleep until sim time reaches ``sim_time``."""
        await anyio.sleep_until(self.to_loop_time(sim_time))

    async def sleep(self, seconds: float) -> None:
        """Sleep ``seconds`` of sim time."""
        await self.sleep_until(self.now() + seconds)

    def rate(self, hz: float) -> Rate:
        """A drift-free periodic timer at ``hz`` (like ``rclpy`` ``Rate``)."""
        return Rate(self, hz)

    def add_failure_listener(self, listener: Callable[[BaseException], None]) -> None:
        """Call ``listener(error)`` when the world fails inside this clock (a System
        listens and stops with it). A clock whose world fails elsewhere (the virtual
        loop's, which cancels the run itself) has nothing to report: the default."""
        del listener


class Rate:
    """Wakes at ``start + k / hz`` for k = 1, 2, ...: no drift, however long each
    iteration takes, and identical instants in every run."""

    __slots__ = ("_clock", "_k", "_start", "period")

    def __init__(self, clock: Clock, hz: float) -> None:
        if not hz > 0:
            raise ValueError(f"rate must be > 0 Hz, got {hz!r}")
        self._clock = clock
        self.period = 1.0 / hz
        self._start = clock.now()
        self._k = 0

    async def sleep(self) -> None:
        """Sleep until the next period boundary (skipping any already past)."""
        now = self._clock.now()
        self._k = max(self._k + 1, math.floor((now - self._start) / self.period + 1e-9) + 1)
        await self._clock.sleep_until(self._start + self._k * self.period)


class VirtualClock(Clock):
    """Sim time on a :class:`VirtualTimeLoop`: the loop's time is sim time."""

    def __init__(self, loop: VirtualTimeLoop) -> None:
        self._loop = loop

    @property
    def resolution(self) -> float:
        return self._loop.source.tick

    def now(self) -> float:
        # The loop's time(), read where it keeps it: one call, not two (every actor and
        # every recorded message asks; ADR 0058).
        return self._loop._now

    def to_loop_time(self, sim_time: float) -> float:
        return sim_time

    def watch(self, check: Callable[[], bool]) -> Callable[[], None]:
        return self._loop.add_idle_watcher(check)

    async def sleep_until(self, sim_time: float) -> None:
        # A timer at exactly ``sim_time``: no float drift from ``now + delay``, and none
        # of anyio.sleep_until's backend lookup (10k calls were 1.2 % of a profiled run).
        # Cancellation (anyio cancel scopes included) cancels the future as usual.
        loop = self._loop
        if sim_time <= loop.time():
            await asyncio.sleep(0)
            return
        future: asyncio.Future[None] = asyncio.Future(loop=loop)  # create_future's, inline
        handle = loop.wake_at(sim_time, future)  # a timer that sets its result
        try:
            await future
        except BaseException:
            handle.cancel()  # woken otherwise (cancelled): the timer must not fire
            raise
        # Woken by the timer: it has run, nothing to cancel (a cancel call per wake less).


REAL_TIME_SCALE = 1.0
"""Sim seconds per wall second unless told: real time (:class:`RealTimeClock`, and so
:class:`~otonav.runtime.RealTime`)."""
MAX_STEP_BATCH = 0.05
"""s of sim time: the most a real-time run steps at once after the loop was held up (the
excess slips): 25 MuJoCo steps of 2 ms, well under a millisecond for the shipped robot.
The default of :class:`RealTimeClock`, and so of every real-time runner (CLI, embedding,
``running_stack``)."""


class RealTimeClock(Clock):
    """Sim time on any loop, paced to the wall clock times ``scale``.

    The world is stepped lazily to follow the wall clock: whenever anyone asks for the
    time or wakes from a sleep, ``source`` is advanced to the tick the wall clock has
    reached. Watchers are evaluated after each advance.

    ``max_step_batch`` (s of sim time, default :data:`MAX_STEP_BATCH`; None: no cap)
    caps one advance: after the loop was held up (a stalled host, a slow callback) the
    excess is dropped instead of stepped in one burst; sim time slips behind the wall
    clock by it (:attr:`slip_s`) and follows it again from there, as a simulator running
    below real time does. Run :meth:`pace` alongside (a
    :class:`~otonav.stack._session.StackSession` does) to step the world in small batches
    even while every actor sleeps.
    """

    def __init__(
        self,
        source: TimeSource,
        *,
        scale: float = REAL_TIME_SCALE,
        max_step_batch: float | None = MAX_STEP_BATCH,
    ) -> None:
        if not (scale > 0 and math.isfinite(scale)):
            raise ValueError(f"real-time scale must be a finite number > 0, got {scale!r}")
        if max_step_batch is not None and not max_step_batch > 0:
            raise ValueError(f"max_step_batch must be > 0 s, got {max_step_batch!r}")
        self._stepper = Stepper(source, self._failed)
        self._rate = self._stepper.rate
        self.scale = scale
        self._wall0: float | None = None
        self._failure_listeners: list[Callable[[BaseException], None]] = []
        self.failure: BaseException | None = None
        self.max_batch_ticks = (
            max(1, math.floor(max_step_batch * self._rate + 1e-9)) if max_step_batch else None
        )
        self.slipped_ticks = 0

    @property
    def resolution(self) -> float:
        return 1.0 / self._rate

    @property
    def slip_s(self) -> float:
        """Sim seconds dropped so far (how far sim time fell behind the scaled wall)."""
        return self.slipped_ticks / self._rate

    def _wall(self) -> float:
        loop = asyncio.get_running_loop()
        if self._wall0 is None:
            self._wall0 = loop.time()
        return loop.time()

    @property
    def source(self) -> TimeSource:
        """What is stepped (a :class:`FrozenSource` once the world's advance raised)."""
        return self._stepper.source

    def add_failure_listener(self, listener: Callable[[BaseException], None]) -> None:
        """Call ``listener(error)`` when the world's ``advance()`` (a
        :class:`TimeSourceError`) or a watcher raises. A System listens and stops with
        it; without listeners the error is raised to whoever asked for the time."""
        self._failure_listeners.append(listener)

    def _failed(self, error: BaseException) -> None:
        if self.failure is None:
            self.failure = error
        if not self._failure_listeners:
            raise error
        for listener in tuple(self._failure_listeners):
            listener(error)

    def _advance_to(self, ticks: int) -> None:
        stepper = self._stepper
        if ticks > stepper.ticks:
            stepper.step_to(ticks, stepper.ticks / self._rate)
            stepper.run_watchers()

    def _follow_wall(self) -> None:
        wall = self._wall()
        assert self._wall0 is not None
        ticks_per_wall_s = self.scale * self._rate
        target = math.floor((wall - self._wall0) * ticks_per_wall_s + 1e-9)
        if self.max_batch_ticks is not None:
            excess = target - self._stepper.ticks - self.max_batch_ticks
            if excess > 0:
                # Slip: from now on the wall clock maps to sim time `excess` ticks later.
                self._wall0 += excess / ticks_per_wall_s
                self.slipped_ticks += excess
                target -= excess
        self._advance_to(target)

    async def pace(self) -> None:
        """Step the world to the wall clock every half batch of wall time, forever
        (needs ``max_step_batch``)."""
        if self.max_batch_ticks is None:
            raise ValueError("pace() needs a RealTimeClock with max_step_batch")
        period = self.max_batch_ticks / self._rate / self.scale / 2
        while True:
            await anyio.sleep(period)
            self._follow_wall()

    def now(self) -> float:
        self._follow_wall()
        return self._stepper.ticks / self._rate

    def to_loop_time(self, sim_time: float) -> float:
        self._wall()
        assert self._wall0 is not None
        return self._wall0 + sim_time / self.scale

    async def sleep_until(self, sim_time: float) -> None:
        goal = math.ceil(sim_time * self._rate - 1e-9)
        while True:
            await anyio.sleep_until(self.to_loop_time(sim_time))
            self._follow_wall()
            if self._stepper.ticks >= goal:
                return
            if goal - self._stepper.ticks <= 1:
                # The timer fired a hair early: the world still reaches the asked instant.
                self._advance_to(goal)
                return
            # Sim time slipped while we slept: the instant is later on the wall clock now.

    def watch(self, check: Callable[[], bool]) -> Callable[[], None]:
        return self._stepper.watch(check)


def current_clock() -> Clock:
    """The clock of the running system; on a virtual-time loop with no system, that
    loop's clock."""
    clock = _current.get(None)
    if clock is not None:
        return clock
    loop = asyncio.get_running_loop()
    if isinstance(loop, VirtualTimeLoop):
        return VirtualClock(loop)
    raise RuntimeError(
        "no otonav clock here: run inside a System (which sets one), on a VirtualTimeLoop, "
        "or pass clock= explicitly"
    )


def set_current_clock(clock: Clock) -> contextvars.Token[Clock]:
    """Make ``clock`` the clock of this context (the System does this for its actors)."""
    return _current.set(clock)


def reset_current_clock(token: contextvars.Token[Clock]) -> None:
    """Undo :func:`set_current_clock`."""
    _current.reset(token)
