"""Each assumption ``otonav.runtime._asyncio_compat`` makes about asyncio's and anyio's
private names, pinned: these fail on a CPython or anyio that changed one, before a run
silently misbehaves (the loop would scramble callbacks, or stall)."""

from __future__ import annotations

import asyncio
import contextvars
import importlib
import importlib.util
import selectors
import sys
from asyncio import base_events
from collections import deque
from typing import Any

import pytest

from otonav.runtime import VirtualTimeLoop
from otonav.runtime import _asyncio_compat as compat

pytestmark = pytest.mark.unit


def test_asyncio_still_has_the_cancelled_timer_thresholds_the_loop_copies() -> None:
    # getattr() falls back to CPython 3.11's values: the names must still be there.
    module: Any = base_events
    assert module._MIN_SCHEDULED_TIMER_HANDLES == compat.MIN_SCHEDULED_TIMER_HANDLES
    assert (
        module._MIN_CANCELLED_TIMER_HANDLES_FRACTION == compat.MIN_CANCELLED_TIMER_HANDLES_FRACTION
    )


def test_anyios_asyncio_backend_is_the_module_the_runners_preload() -> None:
    assert importlib.util.find_spec(compat.ANYIO_ASYNCIO_BACKEND) is not None
    compat.preload_anyio_backend()
    backend = sys.modules[compat.ANYIO_ASYNCIO_BACKEND]
    # It is the module anyio runs asyncio with (what the preload saves a run).
    assert hasattr(backend, "backend_class")


def test_a_timer_handle_built_inline_is_asyncios_own() -> None:
    """FifoTimerHandle sets asyncio's Handle/TimerHandle attributes itself (no debug
    mode): the same values as asyncio's __init__ gives, for every slot."""
    assert compat._INLINE_INIT  # the CPython the tests run on: the inline path is the one used
    loop = VirtualTimeLoop()
    try:
        context = contextvars.copy_context()
        inline = compat.FifoTimerHandle(2.5, print, ("x",), loop, context, 7)
        stock = asyncio.TimerHandle(2.5, print, ("x",), loop, context)
        slots = {*asyncio.Handle.__slots__, *asyncio.TimerHandle.__slots__} - {"__weakref__"}
        assert {s: getattr(inline, s) for s in slots} == {s: getattr(stock, s) for s in slots}
        assert inline._seq == 7
        # Without a context, each gets a copy of the current one, as asyncio does.
        fresh = compat.FifoTimerHandle(1.0, print, (), loop, None, 8)
        assert isinstance(fresh._context, contextvars.Context)
        assert fresh._context is not context
    finally:
        loop.close()


def test_a_stock_loop_keeps_the_private_state_the_iteration_reads() -> None:
    loop: Any = asyncio.SelectorEventLoop()
    try:
        assert isinstance(loop._ready, deque)
        assert isinstance(loop._scheduled, list)
        assert loop._stopping is False
        assert loop._timer_cancelled_count == 0
        assert isinstance(loop._clock_resolution, float)
        assert isinstance(loop._debug, bool)
        assert callable(loop._process_events)
        assert callable(loop._check_closed)
        assert callable(getattr(base_events.BaseEventLoop, "_run_once", None))
        assert callable(asyncio.Handle._run)
        assert isinstance(loop._selector, selectors.BaseSelector)
        if sys.platform != "win32":
            assert isinstance(loop._signal_handlers, dict)
        # A cancelled scheduled timer is counted: _drop_cancelled_timers relies on it.
        handle = loop.call_later(10.0, int)
        handle.cancel()
        assert loop._timer_cancelled_count == 1
    finally:
        loop.close()


def test_asyncio_asks_its_selector_once_per_iteration_with_the_time_to_the_next_timer() -> None:
    """The hook of debug mode (and of SteppedSelectorLoop's own iteration): asyncio waits
    in ``self._selector.select(timeout)``, timeout 0 when callbacks are ready."""
    calls: list[float | None] = []

    class Spy(selectors.DefaultSelector):
        def select(self, timeout: float | None = None) -> Any:
            calls.append(timeout)
            return super().select(0)

    loop: Any = asyncio.SelectorEventLoop(Spy())
    try:
        loop.call_at(loop.time() + 30.0, int)
        loop.call_soon(int)
        loop._run_once()
        assert calls == [0]
        loop._run_once()
        assert calls[1] is not None
        assert 29.0 < calls[1] <= 30.0
    finally:
        loop.close()


def test_asyncio_runs_a_timer_due_within_its_clock_resolution() -> None:
    """The virtual loop sets ``_clock_resolution`` to half a tick so a deadline that is
    float noise above a tick fires at that tick: asyncio must read it so."""
    loop: Any = asyncio.SelectorEventLoop()
    try:
        fired: list[bool] = []
        loop._clock_resolution = 5.0
        loop.call_at(loop.time() + 2.0, fired.append, True)
        loop._run_once()
        assert fired == [True]
    finally:
        loop.close()


def test_the_stepped_loop_reports_asyncios_state_through_public_readers() -> None:
    loop = compat.SteppedSelectorLoop()
    try:
        assert not loop.has_ready()
        assert loop.next_deadline() is None
        assert not loop.has_io()
        assert not loop.polls
        first = loop.call_at(5.0, int)
        loop.call_at(3.0, int)
        loop.call_at(7.0, int)
        assert loop.next_deadline() == 3.0
        assert loop.deadline_after(first) == 3.0  # not the root: the earliest of all
        loop.call_soon(int)
        assert loop.has_ready()
        loop.clock_resolution = 0.125
        assert loop._clock_resolution == 0.125
    finally:
        loop.close()


def test_equal_deadlines_fire_in_scheduling_order_on_the_stepped_loop() -> None:
    async def main() -> list[int]:
        order: list[int] = []
        loop = asyncio.get_running_loop()
        when = loop.time() + 0.01
        for k in range(40):
            loop.call_at(when, order.append, k)
        await asyncio.sleep(0.05)
        return order

    with asyncio.Runner(loop_factory=compat.SteppedSelectorLoop) as runner:
        assert runner.run(main()) == list(range(40))


@pytest.mark.parametrize("debug", [False, True], ids=["fast", "asyncio-debug"])
def test_a_wake_timer_resolves_its_future_in_timer_order(debug: bool) -> None:
    """wake_at (a sleep's wake-up, ADR 0058) is a timer like call_at's: ordered with the
    others by deadline then scheduling order, its future resolved when due, a future
    already done (cancelled) left alone, cancellable before it fires."""
    from otonav.runtime import VirtualTimeLoop

    loop = VirtualTimeLoop()
    log: list[str] = []

    async def main() -> None:
        first: asyncio.Future[None] = loop.create_future()
        first.add_done_callback(lambda f: log.append(f"first {f.cancelled()}"))
        gone: asyncio.Future[None] = loop.create_future()
        never: asyncio.Future[None] = loop.create_future()
        loop.call_at(2.0, log.append, "call_at before")
        loop.wake_at(2.0, first)
        loop.call_at(2.0, log.append, "call_at after")
        loop.wake_at(1.0, gone)
        gone.cancel()
        loop.wake_at(3.0, never).cancel()
        assert "WakeTimer" in repr(loop.wake_at(5.0, loop.create_future()))
        await first
        log.append(f"woke at {loop.time():g}")
        await asyncio.sleep(2)
        assert not never.done()

    loop.set_debug(debug)
    try:
        loop.run_until_complete(main())
    finally:
        loop.close()
    assert log == ["call_at before", "call_at after", "first False", "woke at 2"]
