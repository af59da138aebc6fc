"""The virtual-time loop: time jumps, timeouts at the right sim time, FIFO ties, and the
four ways to run it (anyio.run, asyncio.Runner, pytest-asyncio, the anyio plugin)."""

from __future__ import annotations

import asyncio
import hashlib
import time

import anyio
import pytest

from otonav.runtime import JumpSource, VirtualTimeLoop, run_blocking, virtual_loop_factory

pytestmark = pytest.mark.unit

ONE_YEAR = 365 * 24 * 3600.0


def test_sleeps_of_an_hour_and_a_year_jump_instead_of_waiting() -> None:
    async def main() -> tuple[float, float]:
        await anyio.sleep(3600)
        after_hour = anyio.current_time()
        await anyio.sleep(ONE_YEAR)
        return after_hour, anyio.current_time()

    wall = time.perf_counter()
    after_hour, after_year = anyio.run(
        main, backend="asyncio", backend_options={"loop_factory": virtual_loop_factory()}
    )
    wall = time.perf_counter() - wall
    assert after_hour == pytest.approx(3600.0, abs=1e-6)
    assert after_year == pytest.approx(3600.0 + ONE_YEAR, abs=1e-3)
    assert wall < 5.0  # a hang ceiling: the jump itself takes milliseconds


def test_fail_after_fires_at_the_right_sim_time() -> None:
    async def main() -> float:
        with pytest.raises(TimeoutError):
            with anyio.fail_after(2.5):
                await anyio.sleep(10)
        return anyio.current_time()

    fired = anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    assert fired == pytest.approx(2.5, abs=1e-6)


def test_asyncio_timeout_under_asyncio_runner() -> None:
    async def main() -> float:
        loop = asyncio.get_running_loop()
        with pytest.raises(TimeoutError):
            async with asyncio.timeout(7.25):
                await asyncio.sleep(100)
        return loop.time()

    with asyncio.Runner(loop_factory=virtual_loop_factory()) as runner:
        assert runner.run(main()) == pytest.approx(7.25, abs=1e-6)


def test_time_is_integer_ticks_of_the_source() -> None:
    source = JumpSource(tick=0.002)

    async def main() -> None:
        for _ in range(50_000):
            await asyncio.sleep(0.002)

    with asyncio.Runner(loop_factory=virtual_loop_factory(source)) as runner:
        runner.run(main())
        loop = runner.get_loop()
        assert isinstance(loop, VirtualTimeLoop)
        # 50,000 float additions of 0.002 drift; the tick count does not.
        assert source.ticks == 50_000
        assert loop.time() == 50_000 * 0.002


def test_equal_deadlines_wake_in_fifo_order() -> None:
    order: list[int] = []

    async def sleeper(i: int) -> None:
        await anyio.sleep(1.0)
        order.append(i)

    async def main() -> None:
        async with anyio.create_task_group() as tg:
            for i in range(40):
                tg.start_soon(sleeper, i)

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    assert order == list(range(40))


def _trace_program() -> str:
    """Many actors with equal and unequal periods; the trace hash must be identical."""
    trace: list[tuple[float, int, int]] = []

    async def ticker(i: int, period: float) -> None:
        for k in range(30):
            await anyio.sleep(period)
            trace.append((round(anyio.current_time(), 9), i, k))

    async def main() -> None:
        async with anyio.create_task_group() as tg:
            for i in range(24):
                tg.start_soon(ticker, i, (0.01, 0.02, 0.03)[i % 3])

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(JumpSource(0.001))})
    return hashlib.sha256(repr(trace).encode()).hexdigest()


def test_same_program_gives_identical_event_trace() -> None:
    assert _trace_program() == _trace_program()


def test_run_blocking_holds_sim_time_still() -> None:
    def blocking() -> str:
        # Real blocking work in a worker thread: hashing 64 MB takes tens of ms and
        # releases the GIL, so the loop could run on (and sim time race) if not held.
        hashlib.sha256(bytes(64 * 1024 * 1024)).digest()
        return "done"

    ticks: list[float] = []

    async def ticker() -> None:
        while True:
            await anyio.sleep(0.001)
            ticks.append(anyio.current_time())

    async def main() -> tuple[float, float, str]:
        async with anyio.create_task_group() as tg:
            tg.start_soon(ticker)
            await anyio.sleep(0.01)
            before = anyio.current_time()
            result = await run_blocking(blocking)
            after = anyio.current_time()
            tg.cancel_scope.cancel()
        return before, after, result

    before, after, result = anyio.run(
        main, backend_options={"loop_factory": virtual_loop_factory()}
    )
    assert result == "done"
    assert after == before  # tens of ms of wall time in the thread, 0 s of sim time


@pytest.mark.sim
async def test_pytest_asyncio_hook_runs_marked_tests_on_the_virtual_loop() -> None:
    loop = asyncio.get_running_loop()
    assert isinstance(loop, VirtualTimeLoop)
    start = loop.time()
    await asyncio.sleep(86_400)
    assert loop.time() - start == pytest.approx(86_400)


@pytest.mark.asyncio
async def test_unmarked_async_tests_keep_a_stock_loop() -> None:
    assert not isinstance(asyncio.get_running_loop(), VirtualTimeLoop)


class TestAnyioPlugin:
    """anyio's pytest plugin, with the backend options carrying our loop factory."""

    @pytest.fixture
    def anyio_backend(self) -> tuple[str, dict[str, object]]:
        return ("asyncio", {"loop_factory": virtual_loop_factory()})

    @pytest.fixture
    def trace(self) -> list[float]:
        return []

    @pytest.mark.anyio
    async def test_anyio_plugin_runs_on_the_virtual_loop(self, trace: list[float]) -> None:
        assert isinstance(asyncio.get_running_loop(), VirtualTimeLoop)
        with anyio.move_on_after(30):
            await anyio.sleep(1000)
        trace.append(anyio.current_time())
        assert trace == [pytest.approx(30.0)]


def _ordering_program(log: list[str]) -> list[asyncio.Task[None]]:
    """Callbacks, tasks and futures at one instant (no time passes): what asyncio runs in
    which iteration decides the order. The virtual loop runs its passes itself (ADR 0027)
    and must give exactly asyncio's order."""
    loop = asyncio.get_running_loop()

    def note(name: str, then: tuple[str, ...] = ()) -> None:
        log.append(name)
        for child in then:
            loop.call_soon(note, child)

    async def waiter(name: str, future: asyncio.Future[str]) -> None:
        log.append(f"{name} waits")
        log.append(f"{name} got {await future}")
        await asyncio.sleep(0)
        log.append(f"{name} after sleep(0)")

    future: asyncio.Future[str] = loop.create_future()
    tasks = [loop.create_task(waiter("t1", future))]
    loop.call_soon(note, "a", ("a1", "a2"))
    loop.call_at(loop.time(), note, "due now", ("due child",))
    loop.call_soon(future.set_result, "x")
    tasks.append(loop.create_task(waiter("t2", loop.create_future())))
    cancelled = loop.call_soon(note, "never")
    cancelled.cancel()
    loop.call_soon(note, "b", ("b1",))
    return tasks


@pytest.mark.parametrize("debug", [False, True], ids=["fast", "asyncio-debug"])
def test_one_instant_runs_callbacks_in_stock_asyncio_order(debug: bool) -> None:
    def trace(loop: asyncio.AbstractEventLoop) -> list[str]:
        log: list[str] = []

        async def main() -> None:
            tasks = _ordering_program(log)
            for _ in range(10):  # let every chain settle
                await asyncio.sleep(0)
            for task in tasks:
                task.cancel()

        loop.set_debug(debug)
        try:
            loop.run_until_complete(main())
        finally:
            loop.close()
        return log

    stock = trace(asyncio.new_event_loop())
    virtual = trace(VirtualTimeLoop())
    assert "never" not in stock
    assert virtual == stock


def test_timers_keep_their_order_across_debug_mode_and_a_purge() -> None:
    """Timers wait in the loop's own heap of (when, seq) tuples, or in asyncio's while
    debug mode runs asyncio's iteration (ADR 0058). Switching modes with timers pending,
    cancelling most of them (asyncio's purge of cancelled timers: >100 timers, >50 %
    cancelled) and equal deadlines must still fire every live timer once, by deadline
    then in scheduling order, at its sim time."""
    loop = VirtualTimeLoop()
    fired: list[tuple[float, int]] = []

    def fire(i: int) -> None:
        fired.append((loop.time(), i))

    async def main() -> None:
        handles = []
        for i in range(300):
            when = float(1 + i % 7)  # many equal deadlines
            handles.append(loop.call_at(when, fire, i))
        for handle in handles[::3] + handles[1::3]:
            handle.cancel()  # two thirds: the purge path
        loop.set_debug(True)
        await asyncio.sleep(2.5)  # asyncio's iteration, our timers handed over
        assert loop.next_deadline() == 3.0
        more = [loop.call_at(4.0, fire, i) for i in (1000, 1001)]
        loop.set_debug(False)
        more[0].cancel()
        await asyncio.sleep(10)

    try:
        loop.run_until_complete(main())
    finally:
        loop.close()
    live = sorted((float(1 + i % 7), i) for i in range(2, 300, 3))
    expected = [*live[: live.index((4.0, min(i for w, i in live if w == 4.0)))]]
    expected += [(w, i) for w, i in live if w == 4.0] + [(4.0, 1001)]
    expected += [(w, i) for w, i in live if w > 4.0]
    assert fired == expected
