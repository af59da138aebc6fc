"""Hang protection: the deadlock detector and the wall-clock ceiling."""

from __future__ import annotations

import asyncio

import anyio
import pytest

from otonav.runtime import (
    DeadlockError,
    VirtualTimeLoop,
    WallClockCeilingError,
    until,
    virtual_loop_factory,
)

pytestmark = pytest.mark.unit


def test_deadlock_is_reported_instead_of_hanging() -> None:
    async def main() -> None:
        event = anyio.Event()
        await anyio.sleep(3.0)
        await event.wait()  # nobody will ever set it

    with pytest.raises(DeadlockError, match=r"deadlock at sim time 3\.0"):
        anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(deadlock_grace=0.05)})


def test_wall_ceiling_cancels_a_livelock() -> None:
    """A predicate that never holds while an actor keeps ticking: sim time runs on
    forever; the wall ceiling stops it and says so."""

    async def busy() -> None:
        while True:
            await asyncio.sleep(0.001)

    async def main() -> None:
        async with anyio.create_task_group() as tg:
            tg.start_soon(busy)
            await until(lambda: False, within=1e12)

    with pytest.raises(WallClockCeilingError, match=r"wall-clock ceiling of 0\.3 s"):
        anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(wall_ceiling=0.3)})


def test_a_waiting_thread_is_not_a_deadlock() -> None:
    from otonav.runtime import run_blocking

    def slow() -> int:
        import threading

        threading.Event().wait(0.2)  # longer than the deadlock grace
        return 7

    async def main() -> int:
        return await run_blocking(slow)

    assert (
        anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(deadlock_grace=0.05)})
        == 7
    )


def test_a_failure_is_raised_once_and_never_leaks_into_the_next_run() -> None:
    loop = VirtualTimeLoop(deadlock_grace=0.05)

    async def converts_its_cancellation() -> None:
        try:
            await asyncio.Event().wait()  # deadlock
        except asyncio.CancelledError:
            raise ValueError("converted") from None

    async def fine() -> str:
        await asyncio.sleep(1.0)
        return "ok"

    try:
        with pytest.raises(DeadlockError) as err:
            loop.run_until_complete(converts_its_cancellation())
        assert isinstance(err.value.__cause__, ValueError)
        assert loop.run_until_complete(fine()) == "ok"
    finally:
        loop.close()


def test_wall_ceiling_fires_on_a_callback_that_never_yields() -> None:
    """The loop never reaches its own ceiling check; the watchdog thread does, names
    the task (an actor's is ``actor:NAME``) and where it was computing (issue 27)."""

    async def hog() -> None:
        await asyncio.sleep(1.0)
        spins = 0
        while True:
            spins += 1

    async def main() -> None:
        await asyncio.get_running_loop().create_task(hog(), name="actor:hog")

    factory = lambda: VirtualTimeLoop(wall_ceiling=0.3, hold_grace=0.2)  # noqa: E731
    with (
        pytest.raises(WallClockCeilingError, match=r"sim time reached 1\.000 s\): actor 'hog'"),
        asyncio.Runner(loop_factory=factory) as runner,
    ):
        runner.run(main())
