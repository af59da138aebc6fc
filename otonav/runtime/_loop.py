"""The virtual-time asyncio loop: the world is the clock.

``loop.time()`` is simulated time, kept as an integer tick count (a float
time stalls once the tick is below its resolution: ADR 0001). When no callback is
ready, the loop asks its :class:`~otonav.runtime._timesource.TimeSource` to advance to
the earliest due timer and runs what woke. Equal deadlines wake in FIFO order
(asyncio's heap alone scrambles them). It also watches for the two ways a simulation
hangs: a deadlock (nothing can ever wake) and a livelock (sim time runs on, the run
never ends: a wall-clock ceiling).

asyncio's iteration, re-implemented so that the instant settles in one call, and every
other reach into asyncio's private state live in :mod:`otonav.runtime._asyncio_compat`
(:class:`~otonav.runtime._asyncio_compat.SteppedSelectorLoop`): this loop is its
``select_idle`` hook, called where asyncio would wait in ``select``. That is where real
waiting would happen, so that is where time jumps instead.
"""

from __future__ import annotations

import asyncio
import contextlib
import math
import selectors
import time
from collections.abc import Callable, Coroutine, Generator
from concurrent.futures import Executor
from typing import Any, TypeVar, TypeVarTuple

from otonav.runtime._asyncio_compat import SteppedSelectorLoop
from otonav.runtime._errors import DeadlockError, WallClockCeilingError
from otonav.runtime._stepper import Stepper, Watcher
from otonav.runtime._timesource import JumpSource, TimeSource
from otonav.runtime._watchdog import LoopWatchdog

_T = TypeVar("_T")
_Ts = TypeVarTuple("_Ts")

DEADLOCK_GRACE = 0.5
"""Wall seconds with no timer due and no I/O before a virtual-time loop reports a
deadlock (the default of the loop, its factory and ``@pytest.mark.sim``)."""


class VirtualTimeLoop(SteppedSelectorLoop):
    """An asyncio loop whose ``time()`` is the simulated time of ``source``.

    ``wall_ceiling``: seconds of wall time after which the run is cancelled with
    :class:`WallClockCeilingError` (``None``: no ceiling). ``deadlock_grace``: wall seconds
    the loop waits for outside I/O when nothing else can wake it before raising
    :class:`DeadlockError` (``None``: wait forever, e.g. when a host thread drives it).
    ``hold_grace``: wall seconds a callback may hold the loop without yielding, once the
    ceiling has passed or a stop was asked for (:meth:`expect_progress`), before a
    watchdog thread interrupts it (``otonav.runtime._watchdog``).
    """

    def __init__(
        self,
        source: TimeSource | None = None,
        *,
        wall_ceiling: float | None = None,
        deadlock_grace: float | None = DEADLOCK_GRACE,
        hold_grace: float = 2.0,
    ) -> None:
        super().__init__()
        # The world's stepping, freezing and watchers, shared with the real-time clock.
        self._stepper = Stepper(source if source is not None else JumpSource(), self._fail)
        self._base = 0.0
        self._now = 0.0  # time(), kept with _base and the ticks (read ~9 times an instant)
        # The loop advances to the first tick at or after a deadline; the resolution lets
        # a timer whose deadline is float noise above a tick fire at that tick. It must
        # stay well above the float spacing of large times (a year in: ~4e-9 s).
        self.clock_resolution = 0.25 / self._stepper.rate
        self._holds = 0
        self._wall_ceiling = wall_ceiling
        self._wall_start = time.monotonic()
        self._deadlock_grace = deadlock_grace
        self._owner: asyncio.Future[Any] | None = None
        self._failure: BaseException | None = None
        self._fail_stop_at = 0.0
        self.wakes = 0  # time jumps taken, for benchmarks and introspection
        self._hold_grace = hold_grace
        self._watchdog: LoopWatchdog | None = None
        self.held_by: str | None = None
        """What held the loop when the watchdog last had to interrupt it."""

    # -- time ---------------------------------------------------------------------------

    def time(self) -> float:
        # _base + ticks / rate, computed when they change (the same float).
        return self._now

    @property
    def source(self) -> TimeSource:
        return self._stepper.source

    @property
    def ticks(self) -> int:
        """Ticks advanced since the current source was attached."""
        return self._stepper.ticks

    def attach_source(self, source: TimeSource) -> None:
        """Let ``source`` drive time from now on; time continues, never goes back."""
        self._base = self.time()
        self._stepper.attach(source)
        self._now = self._base
        self.clock_resolution = 0.25 / self._stepper.rate

    # -- watchers: predicates evaluated whenever the system is idle at an instant -------

    def add_idle_watcher(self, watcher: Watcher) -> Callable[[], None]:
        """Call ``watcher()`` each time the loop is idle, before time moves on; it is
        dropped once it returns True (one that raises fails the run: it never escapes
        the selector mid-step). Returns a function that removes it."""
        return self._stepper.watch(watcher)

    def has_idle_watchers(self, other_than: Watcher | None = None) -> bool:
        """Whether an idle watcher besides ``other_than`` is registered."""
        return any(w is not other_than for w in self._stepper.watchers)

    # -- blocking work: the one way to run it while sim time holds still ----------------

    def run_in_executor(
        self, executor: Executor | None, func: Callable[[*_Ts], _T], *args: *_Ts
    ) -> asyncio.Future[_T]:
        future = super().run_in_executor(executor, func, *args)
        self._holds += 1
        future.add_done_callback(self._release_hold)
        return future

    @property
    def holding(self) -> bool:
        """Whether sim time holds still for blocking work in a thread (:func:`run_blocking`)."""
        return self._holds > 0

    def _release_hold(self, _future: asyncio.Future[Any]) -> None:
        self._holds -= 1

    async def shutdown_default_executor(self, *args: Any) -> None:
        self._holds += 1
        try:
            await super().shutdown_default_executor(*args)
        finally:
            self._holds -= 1

    # -- the idle path ------------------------------------------------------------------

    def select_idle(
        self, inner: selectors.BaseSelector, timeout: float | None
    ) -> list[tuple[selectors.SelectorKey, int]]:
        if self._wall_ceiling is not None:
            self._check_wall_ceiling()
        if timeout == 0:
            # Callbacks are ready. Poll for I/O only if something besides the loop's
            # self-pipe is registered: call_soon_threadsafe appends to the ready queue
            # itself, the pipe only wakes a blocked select (and is drained whenever the
            # loop does wait). Saves an epoll syscall on ~3 of 4 loop iterations.
            if self.polls:
                return inner.select(0)
            return []
        # Nothing is ready: the system has settled at this instant.
        if self._stepper.watchers:
            self._stepper.run_watchers()
            if self.has_ready():
                return inner.select(0)
        if self.polls:
            events = inner.select(0)
            if events:
                return events
        elif self.has_ready():
            # Nothing to poll: a thread's call_soon_threadsafe has already queued its
            # callback. (Skipping the epoll per time jump took the virtual wake from
            # 1.54x to 1.42x the stock loop's due timer: benchmarks/runtime_bench.py.)
            return []
        if self._holds:
            # A thread is doing sanctioned blocking work: hold sim time, wait for it.
            return inner.select(0.05)
        if timeout is None:
            return self._wait_or_deadlock(inner)
        deadline = self.next_deadline()
        assert deadline is not None  # asyncio passed a timeout: a timer is scheduled
        self._advance_to_deadline(deadline)
        return []

    def _advance_to_deadline(self, when: float) -> None:
        """Advance at least one tick (``when`` is ahead of now: asyncio passed a timeout
        > 0), and on to the first tick at which asyncio will consider ``when`` due.

        Always moving on matters: anyio re-arms a deadline timer that fired within the
        clock resolution but before its deadline; staying put would livelock.
        """
        stepper, base, resolution = self._stepper, self._base, self.clock_resolution
        rate = stepper.rate
        target = max(stepper.ticks + 1, math.ceil((when - base) * rate - 1.0))
        while base + target / rate + resolution <= when:  # the time at target, inline
            target += 1
        # A world that raises is not let out of the selector: the run fails with it, the
        # world is frozen and time runs on so the cleanup (on_stop, the recording) runs.
        stepper.step_to(target, self._now)
        self._now = base + target / rate
        self.wakes += 1

    def iteration_check(self) -> None:
        if self._wall_ceiling is not None:
            self._check_wall_ceiling()  # a task that never waits on time

    def _wait_or_deadlock(
        self, inner: selectors.BaseSelector
    ) -> list[tuple[selectors.SelectorKey, int]]:
        # Only the loop's self-pipe registered means no outside I/O can wake us either.
        has_io = self.has_io()
        if has_io or self._deadlock_grace is None:
            return inner.select(0.05)
        events = inner.select(self._deadlock_grace)
        if events or self.has_ready():
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

    def check_ceiling_threadsafe(self) -> None:
        """From any thread: check the wall-clock ceiling at the loop's next pass."""
        with contextlib.suppress(RuntimeError):  # the loop has closed
            self.call_soon_threadsafe(self.iteration_check)

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
    deadlock_grace: float | None = DEADLOCK_GRACE,
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
