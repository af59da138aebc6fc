"""The virtual-time asyncio loop: the world is the clock.

``loop.time()`` is simulated time, kept as an integer tick count (a float
time stalls once the tick is below its resolution: ADR 0001). When no callback is
ready, the loop asks its :class:`~otonav.runtime.timesource.TimeSource` to advance to
the earliest due timer and runs what woke. Equal deadlines wake in FIFO order
(asyncio's heap alone scrambles them). It also watches for the two ways a simulation
hangs: a deadlock (nothing can ever wake) and a livelock (sim time runs on, the run
never ends: a wall-clock ceiling).

The hook is the selector: asyncio's ``_run_once`` calls ``select(timeout)`` exactly
once per iteration with the time to the next timer, or 0 when callbacks are ready;
that is where real waiting would happen, so that is where time jumps instead.

The loop also runs its own ``_run_once`` (asyncio's steps, in asyncio's order): after
the ready callbacks ran, the callbacks they made ready run in the same call, pass after
pass, until the instant has settled. A timer that wakes a task is two passes (the timer
sets a future, the future schedules the task); asyncio paid a full iteration with a
selector call for each (ADR 0027). Debug mode runs asyncio's own iteration.
"""

from __future__ import annotations

import asyncio
import contextlib
import contextvars
import heapq
import math
import selectors
import time
from asyncio import base_events
from collections.abc import Callable, Coroutine, Generator
from concurrent.futures import Executor
from typing import Any, TypeVar, TypeVarTuple

from otonav.runtime.errors import DeadlockError, TimeSourceError, WallClockCeilingError
from otonav.runtime.timesource import FrozenSource, JumpSource, TimeSource, tick_rate
from otonav.runtime.watchdog import LoopWatchdog

_T = TypeVar("_T")
_Ts = TypeVarTuple("_Ts")
_Watcher = Callable[[], bool]


_INLINE_INIT = {*asyncio.Handle.__slots__, *asyncio.TimerHandle.__slots__} == {
    "_callback", "_args", "_cancelled", "_loop", "_source_traceback", "_repr",
    "__weakref__", "_context", "_scheduled", "_when",
}  # fmt: skip
"""The handle attributes :class:`_FifoTimerHandle` sets itself are all there are (the
CPython it was written against); on any other, asyncio's own __init__ runs."""


class _FifoTimerHandle(asyncio.TimerHandle):
    """A timer that breaks deadline ties by scheduling order (FIFO)."""

    __slots__ = ("_seq",)

    def __init__(
        self,
        when: float,
        callback: Callable[..., object],
        args: tuple[Any, ...],
        loop: asyncio.AbstractEventLoop,
        context: contextvars.Context | None,
        seq: int,
    ) -> None:
        if not _INLINE_INIT or loop.get_debug():
            super().__init__(when, callback, args, loop, context)
        else:
            # asyncio's Handle + TimerHandle __init__ without debug mode, inline: the same
            # attributes (two Python calls less per timer; a wake sets one timer).
            self._context = contextvars.copy_context() if context is None else context
            self._loop = loop
            self._callback = callback
            self._args = args
            self._cancelled = False
            self._repr = None
            self._source_traceback = None
            self._when = when
            self._scheduled = False
        self._seq = seq

    def __lt__(self, other: object) -> bool:
        if isinstance(other, _FifoTimerHandle):
            mine: float = self._when
            theirs: float = other._when
            return mine < theirs or (mine == theirs and self._seq < other._seq)
        return NotImplemented


class _VirtualSelector:
    """Wraps the real selector; ``select`` advances virtual time instead of waiting."""

    def __init__(self, inner: selectors.BaseSelector) -> None:
        self._inner = inner
        self.loop: VirtualTimeLoop | None = None

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)

    def select(self, timeout: float | None = None) -> list[tuple[selectors.SelectorKey, int]]:
        loop = self.loop
        assert loop is not None
        return loop._idle_select(self._inner, timeout)

    # Registrations change whether a poll can return anything (VirtualTimeLoop._poll).
    def register(self, fileobj: Any, events: int, data: Any = None) -> selectors.SelectorKey:
        key = self._inner.register(fileobj, events, data)
        if self.loop is not None:
            self.loop._update_poll()
        return key

    def unregister(self, fileobj: Any) -> selectors.SelectorKey:
        key = self._inner.unregister(fileobj)
        if self.loop is not None:
            self.loop._update_poll()
        return key


class VirtualTimeLoop(asyncio.SelectorEventLoop):
    """An asyncio loop whose ``time()`` is the simulated time of ``source``.

    ``wall_ceiling``: seconds of wall time after which the run is cancelled with
    :class:`WallClockCeilingError` (``None``: no ceiling). ``deadlock_grace``: wall seconds
    the loop waits for outside I/O when nothing else can wake it before raising
    :class:`DeadlockError` (``None``: wait forever, e.g. when a host thread drives it).
    ``hold_grace``: wall seconds a callback may hold the loop without yielding, once the
    ceiling has passed or a stop was asked for (:meth:`expect_progress`), before a
    watchdog thread interrupts it (``otonav.runtime.watchdog``).
    """

    def __init__(
        self,
        source: TimeSource | None = None,
        *,
        wall_ceiling: float | None = None,
        deadlock_grace: float | None = 0.5,
        hold_grace: float = 2.0,
    ) -> None:
        selector = _VirtualSelector(selectors.DefaultSelector())
        super().__init__(selector)  # type: ignore[arg-type]
        selector.loop = self
        self._source: TimeSource = source if source is not None else JumpSource()
        self._rate = tick_rate(self._source.tick)
        self._base = 0.0
        self._ticks = 0
        # The loop advances to the first tick at or after a deadline; the resolution lets
        # a timer whose deadline is float noise above a tick fire at that tick. It must
        # stay well above the float spacing of large times (a year in: ~4e-9 s).
        self._clock_resolution = 0.25 / self._rate
        self._seq = 0
        self._holds = 0
        self._watchers: list[_Watcher] = []
        self._wall_ceiling = wall_ceiling
        self._wall_start = time.monotonic()
        self._deadlock_grace = deadlock_grace
        self._owner: asyncio.Future[Any] | None = None
        self._failure: BaseException | None = None
        self._fail_stop_at = 0.0
        self.wakes = 0  # time jumps taken, for benchmarks and introspection
        self.beats = 0  # loop passes run: the watchdog's sign of progress
        self.waiting = False  # in the selector (time jumps, I/O waits): not held
        self._hold_grace = hold_grace
        self._watchdog: LoopWatchdog | None = None
        self.held_by: str | None = None
        """What held the loop when the watchdog last had to interrupt it."""
        self._poll = False
        self._update_poll()
        # asyncio's thresholds for dropping all cancelled timers at once.
        self._min_scheduled: int = getattr(base_events, "_MIN_SCHEDULED_TIMER_HANDLES", 100)
        self._min_cancelled_fraction: float = getattr(
            base_events, "_MIN_CANCELLED_TIMER_HANDLES_FRACTION", 0.5
        )

    # -- time ---------------------------------------------------------------------------

    def time(self) -> float:
        return self._base + self._ticks / self._rate

    def _time_at(self, ticks: int) -> float:
        return self._base + ticks / self._rate

    @property
    def source(self) -> TimeSource:
        return self._source

    @property
    def ticks(self) -> int:
        """Ticks advanced since the current source was attached."""
        return self._ticks

    def attach_source(self, source: TimeSource) -> None:
        """Let ``source`` drive time from now on; time continues, never goes back."""
        self._base = self.time()
        self._ticks = 0
        self._source = source
        self._rate = tick_rate(source.tick)
        self._clock_resolution = 0.25 / self._rate

    def call_at(
        self,
        when: float,
        callback: Callable[[*_Ts], object],
        *args: *_Ts,
        context: contextvars.Context | None = None,
    ) -> asyncio.TimerHandle:
        self._check_closed()  # type: ignore[attr-defined]
        self._seq += 1
        timer = _FifoTimerHandle(when, callback, args, self, context, self._seq)
        heapq.heappush(self._scheduled, timer)  # type: ignore[attr-defined]
        timer._scheduled = True
        return timer

    # -- watchers: predicates evaluated whenever the system is idle at an instant -------

    def add_idle_watcher(self, watcher: _Watcher) -> Callable[[], None]:
        """Call ``watcher()`` each time the loop is idle, before time moves on; it is
        dropped once it returns True. Returns a function that removes it."""
        self._watchers.append(watcher)

        def remove() -> None:
            if watcher in self._watchers:
                self._watchers.remove(watcher)

        return remove

    def _run_watchers(self) -> None:
        if not self._watchers:
            return
        # Iterate a snapshot in registration order: deterministic, and safe if a watcher
        # registers or removes others.
        for watcher in tuple(self._watchers):
            try:
                done = watcher()
            except Exception as exc:
                # Never let it escape the selector (it would leave the loop mid-step):
                # the run fails with it. (until() hands its own to the awaiting task.)
                done = True
                self._fail(exc)
            if done and watcher in self._watchers:
                self._watchers.remove(watcher)

    # -- blocking work: the one way to run it while sim time holds still ----------------

    def run_in_executor(
        self, executor: Executor | None, func: Callable[[*_Ts], _T], *args: *_Ts
    ) -> asyncio.Future[_T]:
        future = super().run_in_executor(executor, func, *args)
        self._holds += 1
        future.add_done_callback(self._release_hold)
        return future

    def _release_hold(self, _future: asyncio.Future[Any]) -> None:
        self._holds -= 1

    async def shutdown_default_executor(self, *args: Any) -> None:
        self._holds += 1
        try:
            await super().shutdown_default_executor(*args)
        finally:
            self._holds -= 1

    # -- the idle path ------------------------------------------------------------------

    def _idle_select(
        self, inner: selectors.BaseSelector, timeout: float | None
    ) -> list[tuple[selectors.SelectorKey, int]]:
        if self._wall_ceiling is not None:
            self._check_wall_ceiling()
        if timeout == 0:
            # Callbacks are ready. Poll for I/O only if something besides the loop's
            # self-pipe is registered: call_soon_threadsafe appends to the ready queue
            # itself, the pipe only wakes a blocked select (and is drained whenever the
            # loop does wait). Saves an epoll syscall on ~3 of 4 loop iterations.
            if self._must_poll(inner):
                return inner.select(0)
            return []
        # Nothing is ready: the system has settled at this instant.
        if self._watchers:
            self._run_watchers()
            if self._ready:  # type: ignore[attr-defined]
                return inner.select(0)
        if self._must_poll(inner):
            events = inner.select(0)
            if events:
                return events
        elif self._ready:  # type: ignore[attr-defined]
            # Nothing to poll: a thread's call_soon_threadsafe has already queued its
            # callback. (Skipping the epoll per time jump took the virtual wake from
            # 1.54x to 1.42x the stock loop's due timer: benchmarks/runtime_bench.py.)
            return []
        if self._holds:
            # A thread is doing sanctioned blocking work: hold sim time, wait for it.
            return inner.select(0.05)
        if timeout is None:
            return self._wait_or_deadlock(inner)
        self._advance_to_deadline(self._scheduled[0]._when)  # type: ignore[attr-defined]
        return []

    def _advance_to_deadline(self, when: float) -> None:
        """Advance at least one tick (``when`` is ahead of now: asyncio passed a timeout
        > 0), and on to the first tick at which asyncio will consider ``when`` due.

        Always moving on matters: anyio re-arms a deadline timer that fired within the
        clock resolution but before its deadline; staying put would livelock.
        """
        target = max(self._ticks + 1, math.ceil((when - self._base) * self._rate - 1.0))
        while self._time_at(target) + self._clock_resolution <= when:
            target += 1
        try:
            self._source.advance(target - self._ticks)
        except Exception as exc:
            # Not out of the selector: fail the run with it, freeze the world and let
            # time run on so the run's cleanup (on_stop, the recording) still gets it.
            error = TimeSourceError(self.time(), exc)
            error.__cause__ = exc
            self._source = FrozenSource(self._source)
            self._source.advance(target - self._ticks)
            self._fail(error)
        self._ticks = target
        self.wakes += 1

    def _must_poll(self, _inner: selectors.BaseSelector) -> bool:
        """Whether select(0) can return anything: an fd besides the self-pipe, or signal
        handlers (their signals arrive as bytes on the self-pipe). Kept up to date by
        (un)registrations and signal handlers instead of asked each iteration (asking:
        ~1.7 % of a stack run)."""
        return self._poll

    def _update_poll(self) -> None:
        selector = self._selector  # type: ignore[attr-defined]
        fds = len(selector._inner.get_map()) if isinstance(selector, _VirtualSelector) else 0
        self._poll = fds > 1 or bool(getattr(self, "_signal_handlers", None))

    def add_signal_handler(self, sig: int, callback: Callable[[*_Ts], object], *args: *_Ts) -> None:
        super().add_signal_handler(sig, callback, *args)
        self._update_poll()

    def remove_signal_handler(self, sig: int) -> bool:
        removed = super().remove_signal_handler(sig)
        self._update_poll()
        return removed

    # -- one iteration ------------------------------------------------------------------

    def _drop_cancelled_timers(self) -> None:
        """asyncio's first step: drop cancelled timers (all, when they are many)."""
        this: Any = self  # asyncio's private attributes, untyped
        scheduled: list[Any] = this._scheduled
        count = len(scheduled)
        if (
            count > this._min_scheduled
            and this._timer_cancelled_count / count > this._min_cancelled_fraction
        ):
            kept = []
            for handle in scheduled:
                if handle._cancelled:
                    handle._scheduled = False
                else:
                    kept.append(handle)
            heapq.heapify(kept)
            this._scheduled = kept
            this._timer_cancelled_count = 0
        else:
            while scheduled and scheduled[0]._cancelled:
                this._timer_cancelled_count -= 1
                heapq.heappop(scheduled)._scheduled = False

    def _run_once(self) -> None:
        """One asyncio iteration (module docstring): asyncio's steps in asyncio's order,
        repeated while callbacks are ready, so the order of every callback is the one
        asyncio's iterations give. The selector is asked only when waiting (time jumps
        there) or when something can be polled."""
        this: Any = self  # asyncio's private attributes, untyped
        self.beats += 1
        if this._debug:
            self.waiting = True  # a debug loop: the watchdog only catches a held selector
            super()._run_once()  # type: ignore[misc]
            return
        ready = this._ready
        inner = this._selector._inner
        self._drop_cancelled_timers()
        scheduled: list[Any] = this._scheduled
        if ready or this._stopping:
            if self._poll:
                this._process_events(inner.select(0))
        else:
            timeout = max(0.0, scheduled[0]._when - self.time()) if scheduled else None
            self.waiting = True
            events = self._idle_select(inner, timeout)
            self.waiting = False
            this._process_events(events)
        passes = 0
        while True:
            self.beats += 1
            # Due timers join the ready queue, then the callbacks ready now run (not the
            # ones they make ready: those are the next pass, as in asyncio).
            end_time = self.time() + self._clock_resolution
            while scheduled and scheduled[0]._when < end_time:
                handle = heapq.heappop(scheduled)
                handle._scheduled = False
                ready.append(handle)
            for _ in range(len(ready)):
                handle = ready.popleft()
                if not handle._cancelled:
                    handle._run()
            handle = None  # break cycles when an exception occurs (as asyncio does)
            if not ready or this._stopping:
                return
            # The next pass starts as asyncio's next iteration would.
            passes += 1
            if not passes & 255 and self._wall_ceiling is not None:
                self._check_wall_ceiling()  # a task that never waits on time
            self._drop_cancelled_timers()
            scheduled = this._scheduled
            if self._poll:
                this._process_events(inner.select(0))

    def _wait_or_deadlock(
        self, inner: selectors.BaseSelector
    ) -> list[tuple[selectors.SelectorKey, int]]:
        # Only the loop's self-pipe registered means no outside I/O can wake us either.
        has_io = len(inner.get_map()) > 1
        if has_io or self._deadlock_grace is None:
            return inner.select(0.05)
        events = inner.select(self._deadlock_grace)
        if events or self._ready:  # type: ignore[attr-defined]
            return events
        self._fail(
            DeadlockError(
                f"deadlock at sim time {self.time():.6f} s: no timer is scheduled, no "
                "callback is ready, no I/O or thread can wake the loop (every task waits on "
                "something only another waiting task could provide)"
            )
        )
        return []

    def _check_wall_ceiling(self) -> None:
        assert self._wall_ceiling is not None
        elapsed = time.monotonic() - self._wall_start
        if elapsed > self._wall_ceiling:
            self._fail(
                WallClockCeilingError(
                    f"run exceeded its wall-clock ceiling of {self._wall_ceiling:g} s "
                    f"(sim time reached {self.time():.3f} s): a hang or livelock, "
                    "e.g. a wait whose predicate never becomes true while actors keep ticking"
                )
            )

    def fail_threadsafe(self, error: BaseException) -> None:
        """From any thread: fail the run with ``error`` (as the ceiling does)."""
        with contextlib.suppress(RuntimeError):  # the loop has closed: the run is over
            self.call_soon_threadsafe(self._fail, error)

    def expect_progress(self, why: str) -> None:
        """From any thread or a signal handler: a stop was asked for (``why`` names it,
        e.g. "SIGTERM"). If a callback then holds the loop for ``hold_grace`` wall
        seconds, the watchdog interrupts it (the cancellation itself is the caller's)."""
        if self._watchdog is not None:
            self._watchdog.expect_progress(why)

    def _fail(self, error: BaseException) -> None:
        """Cancel the run with ``error``; if it has not ended 2 wall seconds later (its
        cleanup hangs too), stop the loop."""
        if self._failure is None:
            self._failure = error
            self._fail_stop_at = time.monotonic() + 2.0
            if self._owner is not None and not self._owner.done():
                self._owner.cancel(msg=str(error))
                return
        if time.monotonic() >= self._fail_stop_at:
            self.stop()

    def run_until_complete(  # type: ignore[override]
        self,
        future: Coroutine[Any, Any, _T] | Generator[Any, None, _T] | asyncio.Future[_T],
    ) -> _T | None:
        owner: asyncio.Future[_T] = asyncio.ensure_future(future, loop=self)  # type: ignore[arg-type]
        self._owner = owner
        self._wall_start = time.monotonic()
        watchdog = self._watchdog = LoopWatchdog(self, self._wall_ceiling, self._hold_grace)
        watchdog.start()
        try:
            result = super().run_until_complete(owner)
        except BaseException as exc:
            failure = self._failure
            if failure is None:
                raise
            # Whatever the run turned the cancellation into, the cause is the failure.
            if failure.__cause__ is not None:  # it names its own cause
                raise failure  # noqa: B904
            raise failure from (None if isinstance(exc, asyncio.CancelledError) else exc)
        finally:
            watchdog.stop()
            self._owner = None
            failure, self._failure = self._failure, None
        if failure is not None:  # the run swallowed its cancellation and returned
            raise failure
        return result


def virtual_loop_factory(
    source: TimeSource | None = None,
    *,
    wall_ceiling: float | None = None,
    deadlock_grace: float | None = 0.5,
) -> Callable[[], VirtualTimeLoop]:
    """A zero-argument loop factory for ``asyncio.Runner``, ``anyio.run`` and pytest.

    Each call makes a fresh loop (a new world gets a new loop: time never goes back).
    """

    def factory() -> VirtualTimeLoop:
        return VirtualTimeLoop(
            source if source is not None else JumpSource(),
            wall_ceiling=wall_ceiling,
            deadlock_grace=deadlock_grace,
        )

    return factory


async def run_blocking(func: Callable[..., _T], *args: Any) -> _T:
    """Run blocking ``func(*args)`` in a worker thread. On the virtual-time loop sim time
    holds still until it returns; on a real-time loop the world keeps following the wall
    clock. (``anyio.to_thread.run_sync`` is invisible to the loop: sim time would race.)"""
    loop = asyncio.get_running_loop()
    return await loop.run_in_executor(None, func, *args)
