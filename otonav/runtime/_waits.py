"""Conditional waits on sim time: ``await until(...)`` and ``await next_message(...)``.

Both are evaluated as sim time advances (on the virtual loop: each time the system is
idle at an instant, before time moves on), never by polling the wall clock, and fail
with :class:`~otonav.runtime._errors.SimTimeoutError` naming the sim time, the budget
and the last observed value.
"""

from __future__ import annotations

import asyncio
import inspect
from collections.abc import Callable
from typing import TypeVar

import anyio

from otonav.runtime._clock import Clock, current_clock
from otonav.runtime._errors import SimTimeoutError
from otonav.runtime._mailbox import Subscription

_M = TypeVar("_M")
_MISSING = object()


async def until(
    predicate: Callable[[], object],
    *,
    within: float,
    observe: Callable[[], object] | None = None,
    what: str | None = None,
    clock: Clock | None = None,
) -> None:
    """Wait until ``predicate()`` is truthy, at most ``within`` seconds of sim time.

    ``observe`` gives the value to report on timeout (default: the predicate's last
    result); ``what`` names the condition in the error.
    """
    clock = clock or current_clock()
    budget = within
    deadline = clock.now() + budget
    last: object = _MISSING

    def check() -> bool:
        nonlocal last
        result = predicate()
        last = observe() if observe is not None else result
        return bool(result)

    if check():
        return
    done = asyncio.get_running_loop().create_future()

    def watcher() -> bool:
        if done.done():
            return True
        try:
            if not check():
                return False
        except Exception as exc:
            # Raised where time moves (the loop's idle path, or a real-time clock's
            # advance inside someone's now()): hand it to the task awaiting until().
            # A predicate that reads a real-time clock can move time and so run this
            # watcher again inside itself: the inner call may have settled ``done``.
            if not done.done():
                done.set_exception(exc)
            return True
        if not done.done():
            done.set_result(None)
        return True

    unwatch = clock.watch(watcher)
    try:
        # The budget is sim time. A real-time clock maps it to loop time with an offset
        # that moves when sim time slips behind the wall clock, so a deadline that fired
        # before sim time got there is set again (virtual time: it is exact, once).
        while not done.done():
            with anyio.CancelScope(deadline=clock.to_loop_time(deadline)):
                await asyncio.wait((done,))  # (never cancels ``done`` itself)
            if done.done() or clock.reached(deadline):
                break
        if done.done():
            done.result()  # raises what the predicate raised
            return
        if not check():
            raise SimTimeoutError(
                what or _named(predicate),
                clock.now(),
                budget,
                last,
            )
    finally:
        unwatch()
        if not done.done():
            done.cancel()


async def next_message(
    subscription: Subscription[_M],
    predicate: Callable[[_M], object] = lambda _m: True,
    *,
    within: float,
    what: str | None = None,
    clock: Clock | None = None,
) -> _M:
    """The next message on ``subscription`` for which ``predicate`` holds, within
    ``within`` seconds of sim time."""
    clock = clock or current_clock()
    last: object = "no message"
    deadline = clock.now() + within
    while True:
        # A loop-time deadline set again if it fired before sim time got there (see until).
        with anyio.CancelScope(deadline=clock.to_loop_time(deadline)):
            while True:
                message = await subscription.recv()
                last = message
                if predicate(message):
                    return message
        if clock.reached(deadline):
            break
    raise SimTimeoutError(
        what or f"a matching message on '{subscription.topic}'", clock.now(), within, last
    )


def _named(predicate: Callable[[], object]) -> str:
    """What a timeout names: a function's name, or a lambda's own expression
    (``lambda: odom.x > 1.0`` is "odom.x > 1.0")."""
    name = str(getattr(predicate, "__name__", "condition"))
    if name != "<lambda>":
        return name
    try:
        source = inspect.getsource(predicate)
    except (OSError, TypeError):
        return name
    body = source.partition("lambda")[2].partition(":")[2].strip()
    depth, end = 0, len(body)
    for i, char in enumerate(body):  # up to the bracket or comma that ends the lambda
        depth += (char in "([{") - (char in ")]}")
        if depth < 0 or (depth == 0 and char == ","):
            end = i
            break
    return " ".join(body[:end].split()) or name
