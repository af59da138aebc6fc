"""Errors raised where time moves reach whoever waits for them (issue 16, item 2).

An ``until()`` predicate and the time source's ``advance()`` run inside the loop's
selector (virtual time) or inside whichever ``now()`` call steps the world (real time).
An exception there must reach the task awaiting ``until()``, or fail the run as a time
source error; never escape the selector, never crash an innocent actor.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable

import anyio
import pytest

from otonav.runtime import (
    Actor,
    Clock,
    JumpSource,
    RealTimeClock,
    System,
    TimeSourceError,
    VirtualTimeLoop,
    until,
    virtual_loop_factory,
)

pytestmark = pytest.mark.unit


class Broken(JumpSource):
    """A world that fails once it is stepped past ``at`` seconds."""

    def __init__(self, at: float, tick: float = 0.002) -> None:
        super().__init__(tick)
        self.at_ticks = round(at / tick)

    def advance(self, n: int) -> None:
        if self.ticks + n > self.at_ticks:
            raise FloatingPointError("the physics diverged (qacc is NaN)")
        super().advance(n)


class Ticker(Actor):
    """An innocent actor that reads the time 100 times a second."""

    def __init__(self) -> None:
        super().__init__("ticker")
        self.seen = 0.0

    async def run(self) -> None:
        rate = self.clock.rate(100.0)
        while True:
            await rate.sleep()
            self.seen = self.clock.now()


def _late_failure(clock_now: Callable[[], float], after: float) -> Callable[[], bool]:
    def predicate() -> bool:
        if clock_now() > after:
            raise KeyError("the predicate itself is broken")
        return False

    return predicate


def test_a_failing_predicate_reaches_the_awaiting_task_in_virtual_time() -> None:
    async def tick() -> None:
        while True:
            await anyio.sleep(0.1)  # instants at which the predicate is evaluated

    async def main() -> str:
        loop = asyncio.get_running_loop()
        async with anyio.create_task_group() as tg:
            tg.start_soon(tick)
            try:
                await until(_late_failure(loop.time, 0.45), within=5.0)
            except KeyError:
                return f"caught at {loop.time():.3f}"
            finally:
                tg.cancel_scope.cancel()
        return "not raised"

    result = anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    assert result.startswith("caught at 0.5")


def test_a_failing_predicate_reaches_the_awaiting_task_in_real_time() -> None:
    ticker = Ticker()

    async def main() -> str:
        clock = RealTimeClock(JumpSource(0.002), scale=20.0)
        async with System([ticker], clock=clock) as system:
            try:
                with anyio.fail_after(30):  # a hang guard only; this takes ~15 ms
                    await until(_late_failure(clock.now, 0.2), within=5.0, clock=clock)
            except KeyError:
                return "caught"
            finally:
                crashes = [e for e in system.events if e.kind == "crashed"]
                assert not crashes, crashes
        return "not raised"

    assert anyio.run(main) == "caught"


class MovesTimeWhenRead(Clock):
    """A clock whose reading can move time and run the watchers, as
    :meth:`RealTimeClock.now` does when the wall clock has moved on: a predicate that
    reads it re-enters its own ``until()`` watcher."""

    def __init__(self) -> None:
        self.t = 0.0
        self.watchers: list[Callable[[], bool]] = []

    def now(self) -> float:
        return self.t

    def to_loop_time(self, sim_time: float) -> float:
        return asyncio.get_running_loop().time() + 3600.0  # the test ends long before

    def watch(self, check: Callable[[], bool]) -> Callable[[], None]:
        self.watchers.append(check)
        return lambda: self.watchers.remove(check) if check in self.watchers else None

    def advance(self) -> None:
        self.t += 0.01
        for watcher in tuple(self.watchers):
            if watcher() and watcher in self.watchers:
                self.watchers.remove(watcher)


def test_a_predicate_that_moves_time_and_fails_reaches_the_waiter_once() -> None:
    # Seen under load in real time: the predicate read the clock, the clock stepped the
    # world and ran the same watcher inside it, which failed first; the outer call then
    # set the settled future again (InvalidStateError out of the clock's advance).
    clock = MovesTimeWhenRead()
    calls = 0

    def predicate() -> bool:
        nonlocal calls
        calls += 1
        if calls == 1:
            return False  # until()'s first look, before it watches
        if calls == 2:
            clock.advance()  # reading the clock moved time: the watcher runs inside
        raise KeyError("the predicate itself is broken")

    async def main() -> tuple[str, BaseException | None]:
        waiter = asyncio.ensure_future(until(predicate, within=5.0, clock=clock))
        await asyncio.sleep(0)  # until() is watching now
        try:
            clock.advance()
        except BaseException as exc:  # what escaped into whoever moved time
            escaped: BaseException | None = exc
        else:
            escaped = None
        try:
            await waiter
        except KeyError:
            return "caught", escaped
        return "not raised", escaped

    assert asyncio.run(main()) == ("caught", None)
    assert calls == 3


def test_a_failing_advance_fails_the_virtual_run_as_a_time_source_error() -> None:
    """The error reaches run_until_complete as a TimeSourceError (cause: the world's
    exception); the run's cleanup still runs in sim time."""
    cleaned_up_at: list[float] = []

    async def main() -> None:
        loop = asyncio.get_running_loop()
        assert isinstance(loop, VirtualTimeLoop)
        loop.attach_source(Broken(at=1.0))
        try:
            for _ in range(50):
                await anyio.sleep(0.1)
        finally:
            with anyio.CancelScope(shield=True):
                await anyio.sleep(0.1)  # cleanup that needs sim time still gets it
                cleaned_up_at.append(loop.time())

    with pytest.raises(TimeSourceError, match=r"advance\(\) raised at sim time 1\.000") as info:
        anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    assert isinstance(info.value.__cause__, FloatingPointError)
    assert cleaned_up_at == [pytest.approx(1.2)]  # failed in the step to 1.1, then +0.1


def test_a_failing_advance_in_real_time_stops_the_system_not_an_actor() -> None:
    """It used to crash whichever actor happened to call now(): 'ticker' was blamed."""
    ticker = Ticker()

    async def main() -> None:
        clock = RealTimeClock(Broken(at=0.1), scale=20.0)
        async with System([ticker], clock=clock):
            with anyio.fail_after(30):  # hang guard; the stop comes at ~5 ms wall
                await anyio.sleep_forever()

    with pytest.raises(TimeSourceError) as info:
        anyio.run(main)
    assert isinstance(info.value.__cause__, FloatingPointError)
    assert "ticker" not in str(info.value)
