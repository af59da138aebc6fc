"""Every reach into asyncio's and anyio's private names, in one module.

The virtual-time loop (:mod:`otonav.runtime._loop`) needs what asyncio does not publish:
its iteration (``BaseEventLoop._run_once``), its ready queue and timer heap, the timer
handles' fields, the thresholds for purging cancelled timers; the runners pre-load
anyio's asyncio backend (``anyio._backends._asyncio``) outside their timed span. Nothing
else in otonav touches a private name of either library (``tests/static/
test_private_reaches.py`` walks the code), and each assumption made here is pinned by a
test in ``tests/unit/runtime/test_asyncio_compat.py`` that fails when a new CPython or
anyio changes it, on every CPython CI runs (ADR 0049, 0055).

What it offers instead, to the rest of the runtime:

- :class:`SteppedSelectorLoop`: asyncio's ``SelectorEventLoop`` whose iteration is
  re-implemented (asyncio's steps in asyncio's order, repeated while callbacks are
  ready: ADR 0027) with one hook, :meth:`~SteppedSelectorLoop.select_idle`, called
  where asyncio would block in ``select``, and public readers of its state
  (:meth:`~SteppedSelectorLoop.has_ready`, :meth:`~SteppedSelectorLoop.next_deadline`,
  :meth:`~SteppedSelectorLoop.deadline_after`, ``clock_resolution``);
- the timer handle that breaks deadline ties in FIFO order;
- :func:`preload_anyio_backend`.
"""

from __future__ import annotations

import asyncio
import contextlib
import contextvars
import heapq
import importlib
import math
import selectors
from asyncio import base_events
from collections.abc import Callable
from typing import Any, TypeVarTuple

_Ts = TypeVarTuple("_Ts")

# -- anyio --------------------------------------------------------------------------------

ANYIO_ASYNCIO_BACKEND = "anyio._backends._asyncio"
"""The module anyio imports when the first task group, event or sleep runs on asyncio."""


def preload_anyio_backend() -> None:
    """Import anyio's asyncio backend now (12-110 ms in a fresh process), so that a run's
    timed span does not pay it (ADR 0027, 0036). A reorganised anyio: the run pays."""
    with contextlib.suppress(ImportError):
        importlib.import_module(ANYIO_ASYNCIO_BACKEND)


# -- asyncio: constants -------------------------------------------------------------------

MIN_SCHEDULED_TIMER_HANDLES: int = getattr(base_events, "_MIN_SCHEDULED_TIMER_HANDLES", 100)
"""asyncio purges cancelled timers all at once above this many scheduled timers..."""
MIN_CANCELLED_TIMER_HANDLES_FRACTION: float = getattr(
    base_events, "_MIN_CANCELLED_TIMER_HANDLES_FRACTION", 0.5
)
"""...when more than this fraction of them is cancelled."""


# -- asyncio: timer handles ---------------------------------------------------------------

_INLINE_INIT = {*asyncio.Handle.__slots__, *asyncio.TimerHandle.__slots__} == {
    "_callback", "_args", "_cancelled", "_loop", "_source_traceback", "_repr",
    "__weakref__", "_context", "_scheduled", "_when",
}  # fmt: skip
"""The handle attributes :class:`FifoTimerHandle` sets itself are all there are (the
CPython it was written against); on any other, asyncio's own __init__ runs."""


class FifoTimerHandle(asyncio.TimerHandle):
    """A timer that breaks deadline ties by scheduling order (FIFO): asyncio's heap
    alone wakes equal deadlines in scrambled order (notes: virtual time, pitfall 2)."""

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
        if isinstance(other, FifoTimerHandle):
            mine: float = self._when
            theirs: float = other._when
            return mine < theirs or (mine == theirs and self._seq < other._seq)
        return NotImplemented


def _resolve(future: asyncio.Future[None]) -> None:
    """A wake-up: ``future`` gets its result (None), unless it is done (cancelled)."""
    if not future.done():
        future.set_result(None)


_NO_CONTEXT = contextvars.Context()
"""The context of every :class:`WakeTimer` (its ``_run`` runs no code of its own in one)."""


class WakeTimer(FifoTimerHandle):
    """A timer whose callback is :func:`_resolve` of one future (a sleep's wake-up), run
    without a context switch or a callback frame (~0.4 us a wake, ADR 0058): setting a
    future's result runs nothing; it schedules the future's callbacks, each in the
    context it was added with. A timer still, in every other respect (repr, cancel,
    debug mode)."""

    __slots__ = ()

    def _run(self) -> None:
        future = self._args[0]
        if not future.done():
            future.set_result(None)


# -- asyncio: the loop --------------------------------------------------------------------


class _HookedSelector:
    """Wraps the real selector; ``select`` asks the loop's :meth:`select_idle` (the
    path asyncio's own iteration takes, in debug mode)."""

    def __init__(self, inner: selectors.BaseSelector) -> None:
        self.inner = inner
        self.loop: SteppedSelectorLoop | None = None

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)

    def select(self, timeout: float | None = None) -> list[tuple[selectors.SelectorKey, int]]:
        loop = self.loop
        assert loop is not None
        return loop.select_idle(self.inner, timeout)

    # Registrations change whether a poll can return anything (SteppedSelectorLoop.polls).
    def register(self, fileobj: Any, events: int, data: Any = None) -> selectors.SelectorKey:
        key = self.inner.register(fileobj, events, data)
        if self.loop is not None:
            self.loop._update_poll()
        return key

    def unregister(self, fileobj: Any) -> selectors.SelectorKey:
        key = self.inner.unregister(fileobj)
        if self.loop is not None:
            self.loop._update_poll()
        return key


class SteppedSelectorLoop(asyncio.SelectorEventLoop):
    """asyncio's selector loop, its iteration re-implemented around one hook.

    :meth:`select_idle` is called once per iteration where asyncio would wait in
    ``select`` (nothing is ready): a subclass advances time there instead of waiting.
    After the ready callbacks ran, the callbacks they made ready run in the same call,
    pass after pass, until the instant has settled (a timer that wakes a task is two
    passes; asyncio paid a full iteration with a selector call for each: ADR 0027).
    Debug mode runs asyncio's own iteration (the hook is then reached through the
    selector). ``beats`` counts passes (a watchdog's sign of progress); ``waiting`` is
    True while in the hook.

    Timers wait in a heap of ``(when, seq, handle)`` tuples (``_timers``), compared in C,
    instead of asyncio's heap of handles, compared by a Python ``__lt__`` (~8 calls a
    timer: ADR 0058); (when, seq) is the order :class:`FifoTimerHandle` gives, so timers
    fall due in the same order. In debug mode timers go to asyncio's own heap, which
    asyncio's iteration reads; each iteration adopts what the other mode left.
    """

    def __init__(self) -> None:
        selector = _HookedSelector(selectors.DefaultSelector())
        super().__init__(selector)  # type: ignore[arg-type]
        selector.loop = self
        self._hooked = selector
        self._seq = 0
        self._timers: list[tuple[float, int, FifoTimerHandle]] = []
        self._poll = False
        self.beats = 0
        self.waiting = False
        self._update_poll()

    # -- the hook -----------------------------------------------------------------------

    def select_idle(
        self, inner: selectors.BaseSelector, timeout: float | None
    ) -> list[tuple[selectors.SelectorKey, int]]:
        """Where asyncio would wait up to ``timeout`` (None: forever; 0: callbacks are
        ready) for I/O on ``inner``. Default: wait, as asyncio does."""
        return inner.select(timeout)

    def iteration_check(self) -> None:
        """Called every 256 passes of one long iteration (a task that never waits)."""

    # -- public readers of asyncio's state ----------------------------------------------

    @property
    def clock_resolution(self) -> float:
        """A timer fires when its deadline is below ``time() + clock_resolution``."""
        resolution: float = self._clock_resolution
        return resolution

    @clock_resolution.setter
    def clock_resolution(self, value: float) -> None:
        self._clock_resolution = value

    def has_ready(self) -> bool:
        """Whether callbacks are queued to run (a thread's ``call_soon_threadsafe``
        included)."""
        return bool(self._ready)  # type: ignore[attr-defined]

    def next_deadline(self) -> float | None:
        """The earliest scheduled timer's deadline (a cancelled one included), or None."""
        if not self._scheduled:  # type: ignore[attr-defined]  # (not in debug mode)
            return self._timers[0][0] if self._timers else None
        heads = self._earliest_timers()
        return heads[0][0] if heads else None

    def deadline_after(self, timer: asyncio.TimerHandle | None) -> float:
        """The earliest deadline among the other timers when ``timer`` is the earliest
        (else, or with None, the earliest of all); ``inf`` if none."""
        heads = self._earliest_timers()
        if not heads:
            return math.inf
        if heads[0][2] is timer:
            return heads[1][0] if len(heads) > 1 else math.inf
        return heads[0][0]

    def _earliest_timers(self) -> list[tuple[float, int, FifoTimerHandle]]:
        """The two earliest timers (and maybe more), earliest first, from both heaps
        (ours, and asyncio's while debug mode runs): each heap's two earliest are among
        its first three entries (the root and its children)."""
        scheduled: list[FifoTimerHandle] = self._scheduled  # type: ignore[attr-defined]
        heads = self._timers[:3]
        if scheduled:
            heads += [(h._when, h._seq, h) for h in scheduled[:3]]
        heads.sort()
        return heads

    def has_io(self) -> bool:
        """Whether anything besides the loop's self-pipe is registered for I/O."""
        return len(self._hooked.inner.get_map()) > 1

    @property
    def polls(self) -> bool:
        """Whether a select(0) can return anything: an fd besides the self-pipe, or
        signal handlers (their signals arrive as bytes on the self-pipe). Kept up to
        date by (un)registrations and signal handlers instead of asked each iteration
        (asking: ~1.7 % of a stack run)."""
        return self._poll

    def _update_poll(self) -> None:
        hooked = getattr(self, "_hooked", None)
        fds = len(hooked.inner.get_map()) if hooked is not None else 0
        self._poll = fds > 1 or bool(getattr(self, "_signal_handlers", None))

    def add_signal_handler(self, sig: int, callback: Callable[[*_Ts], object], *args: *_Ts) -> None:
        super().add_signal_handler(sig, callback, *args)
        self._update_poll()

    def remove_signal_handler(self, sig: int) -> bool:
        removed = super().remove_signal_handler(sig)
        self._update_poll()
        return removed

    # -- timers -------------------------------------------------------------------------

    def call_at(
        self,
        when: float,
        callback: Callable[[*_Ts], object],
        *args: *_Ts,
        context: contextvars.Context | None = None,
    ) -> asyncio.TimerHandle:
        self._check_closed()  # type: ignore[attr-defined]
        self._seq += 1
        seq = self._seq
        timer = FifoTimerHandle(when, callback, args, self, context, seq)
        return self._push_timer(when, seq, timer)

    def wake_at(self, when: float, future: asyncio.Future[None]) -> asyncio.TimerHandle:
        """``call_at(when, ...)`` of a callback that gives ``future`` its result (None)
        unless it is done: a sleep's wake-up, scheduled and ordered as any timer."""
        self._check_closed()  # type: ignore[attr-defined]
        self._seq += 1
        seq = self._seq
        timer = WakeTimer(when, _resolve, (future,), self, _NO_CONTEXT, seq)
        return self._push_timer(when, seq, timer)

    def _push_timer(self, when: float, seq: int, timer: FifoTimerHandle) -> asyncio.TimerHandle:
        """Put ``timer`` in our heap (asyncio's in debug mode) and mark it scheduled."""
        if self._debug:  # type: ignore[attr-defined]
            heapq.heappush(self._scheduled, timer)  # type: ignore[attr-defined]
        else:
            heapq.heappush(self._timers, (when, seq, timer))
        timer._scheduled = True
        return timer

    def _adopt_debug_timers(self) -> None:
        """Move the timers debug mode put in asyncio's heap into ours."""
        this: Any = self
        for handle in this._scheduled:
            heapq.heappush(self._timers, (handle._when, handle._seq, handle))
        this._scheduled.clear()

    def _hand_timers_to_asyncio(self) -> None:
        """Move our timers into asyncio's heap (debug mode runs asyncio's iteration)."""
        this: Any = self
        for _when, _seq, handle in self._timers:
            heapq.heappush(this._scheduled, handle)
        self._timers.clear()

    def close(self) -> None:
        super().close()
        self._timers.clear()  # as asyncio clears its own heap

    # -- one iteration ------------------------------------------------------------------

    def _drop_cancelled_timers(self) -> None:
        """asyncio's first step: drop cancelled timers (all, when they are many)."""
        this: Any = self  # asyncio's private attributes, untyped
        timers = self._timers
        count = len(timers)
        if (
            count > MIN_SCHEDULED_TIMER_HANDLES
            and this._timer_cancelled_count / count > MIN_CANCELLED_TIMER_HANDLES_FRACTION
        ):
            kept = []
            for entry in timers:
                if entry[2]._cancelled:
                    entry[2]._scheduled = False
                else:
                    kept.append(entry)
            heapq.heapify(kept)
            self._timers = kept
            this._timer_cancelled_count = 0
        else:
            while timers and timers[0][2]._cancelled:
                this._timer_cancelled_count -= 1
                heapq.heappop(timers)[2]._scheduled = False

    def _run_once(self) -> None:
        """One asyncio iteration (class docstring): asyncio's steps in asyncio's order,
        repeated while callbacks are ready, so the order of every callback is the one
        asyncio's iterations give. The selector is asked only when waiting (the hook)
        or when something can be polled."""
        this: Any = self  # asyncio's private attributes, untyped
        self.beats += 1
        if this._debug:
            self.waiting = True  # a debug loop: the watchdog only catches a held selector
            if self._timers:
                self._hand_timers_to_asyncio()
            super()._run_once()  # type: ignore[misc]
            return
        if this._scheduled:  # left by debug mode
            self._adopt_debug_timers()
        ready = this._ready
        inner = self._hooked.inner
        if this._timer_cancelled_count:  # else there is nothing to drop (a call less)
            self._drop_cancelled_timers()
        timers = self._timers
        if ready or this._stopping:
            if self._poll:
                this._process_events(inner.select(0))
        else:
            timeout = max(0.0, timers[0][0] - self.time()) if timers else None
            self.waiting = True
            events = self.select_idle(inner, timeout)
            self.waiting = False
            if events:  # (a time jump returns none: a call less per instant)
                this._process_events(events)
        passes = 0
        while True:
            self.beats += 1
            # Due timers join the ready queue, then the callbacks ready now run (not the
            # ones they make ready: those are the next pass, as in asyncio).
            end_time = self.time() + this._clock_resolution
            while timers and timers[0][0] < end_time:
                timer = heapq.heappop(timers)[2]
                timer._scheduled = False
                ready.append(timer)
            for _ in range(len(ready)):
                handle = ready.popleft()
                if not handle._cancelled:
                    handle._run()
            handle = None  # break cycles when an exception occurs (as asyncio does)
            if not ready or this._stopping:
                return
            # The next pass starts as asyncio's next iteration would.
            passes += 1
            if not passes & 255:
                self.iteration_check()
            if this._timer_cancelled_count:
                self._drop_cancelled_timers()
                timers = self._timers
            if self._poll:
                this._process_events(inner.select(0))
