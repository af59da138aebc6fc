"""Supervision, restarts, sim-time waits and introspection."""

from __future__ import annotations

import asyncio
import logging
from dataclasses import dataclass

import anyio
import pytest

from otonav.runtime import (
    Actor,
    ActorCrashedError,
    Input,
    JumpSource,
    Output,
    RealTimeClock,
    RestartPolicy,
    SimTimeoutError,
    System,
    next_message,
    until,
    virtual_loop_factory,
)

pytestmark = pytest.mark.unit


@dataclass(frozen=True, slots=True)
class Count:
    n: int


class Counter(Actor):
    out = Output("/count", Count)

    def __init__(self, name: str = "counter", hz: float = 10.0) -> None:
        super().__init__(name)
        self.hz = hz
        self.stopped = False

    async def run(self) -> None:
        rate = self.clock.rate(self.hz)
        n = 0
        while True:
            await rate.sleep()
            n += 1
            await self.out.publish(Count(n))

    async def on_stop(self) -> None:
        self.stopped = True


class Crasher(Actor):
    inp = Input("/count", Count)

    def __init__(self, at: int) -> None:
        super().__init__("crasher")
        self.at = at
        self.starts = 0
        self.stops = 0

    async def on_start(self) -> None:
        self.starts += 1

    async def run(self) -> None:
        async for message in self.inp:
            if message.n % self.at == 0:
                raise ValueError(f"bad count {message.n}")

    async def on_stop(self) -> None:
        self.stops += 1


def _run(main: object) -> None:
    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})  # type: ignore[arg-type]


def test_crash_stops_the_system_cleanly_naming_the_actor(caplog: pytest.LogCaptureFixture) -> None:
    counter, crasher = Counter(), Crasher(at=5)

    async def main() -> None:
        with pytest.raises(ActorCrashedError) as err:
            async with System([counter, crasher]):
                await anyio.sleep(100)
        assert err.value.actor == "crasher"
        assert err.value.sim_time == pytest.approx(0.5)
        assert isinstance(err.value.__cause__, ValueError)
        assert "bad count 5" in err.value.traceback_text
        assert "Traceback" in err.value.traceback_text
        # The body was interrupted at the crash, not at its own end.
        assert anyio.current_time() == pytest.approx(0.5)

    with caplog.at_level(logging.ERROR, logger="otonav.runtime"):
        _run(main)
    assert counter.stopped
    assert crasher.stops == 1
    assert any("crasher crashed" in r.getMessage() for r in caplog.records)


def test_restart_policy_restarts_up_to_its_cap_then_stops() -> None:
    counter, crasher = Counter(), Crasher(at=2)
    system = System([counter, crasher], restart={"crasher": RestartPolicy(3, window=10.0)})

    async def main() -> None:
        with pytest.raises(ActorCrashedError, match="crasher"):
            async with system:
                await anyio.sleep(100)
        # Crashes at counts 2, 4, 6 are restarted; the 4th crash (count 8) stops it all.
        assert anyio.current_time() == pytest.approx(0.8)

    _run(main)
    kinds: list[tuple[str, str]] = [
        (e.actor, e.kind) for e in system.events if e.actor == "crasher"
    ]
    assert kinds.count(("crasher", "restarted")) == 3
    assert kinds.count(("crasher", "crashed")) == 4
    assert crasher.starts == 4
    assert system.graph().actors[1].restarts == 3


def test_restarts_outside_the_window_do_not_count() -> None:
    counter, crasher = Counter(hz=1.0), Crasher(at=2)
    system = System([counter, crasher], restart=RestartPolicy(1, window=1.5))

    async def main() -> None:
        async with system:
            await anyio.sleep(20.5)  # crashes every 2 s: never two inside 1.5 s

    _run(main)
    assert sum(1 for e in system.events if e.kind == "restarted") == 10


def test_until_resolves_at_the_instant_the_predicate_holds() -> None:
    counter = Counter()

    async def main() -> None:
        async with System([counter]) as system:
            sub = system.subscribe("/count", Count)
            seen: list[int] = []

            async def drain() -> None:
                async for m in sub:
                    seen.append(m.n)

            async with anyio.create_task_group() as tg:
                tg.start_soon(drain)
                await until(lambda: len(seen) >= 7, within=5.0)
                assert anyio.current_time() == pytest.approx(0.7)
                tg.cancel_scope.cancel()

    _run(main)


def test_until_timeout_says_sim_time_budget_and_last_value() -> None:
    async def main() -> None:
        async with System([Counter()]) as system:
            sub = system.subscribe("/count", Count)
            last = [0]

            async def drain() -> None:
                async for m in sub:
                    last[0] = m.n

            async with anyio.create_task_group() as tg:
                tg.start_soon(drain)
                with pytest.raises(SimTimeoutError) as err:
                    await until(
                        lambda: last[0] > 1000,
                        within=2.0,
                        observe=lambda: last[0],
                        what="count > 1000",
                    )
                assert isinstance(err.value, TimeoutError)
                assert err.value.sim_time == pytest.approx(2.0)
                text = str(err.value)
                assert "count > 1000" in text
                assert "within 2 s" in text
                assert "2.000" in text
                # The deadline was set (at 0 s) before the 20th tick was (at 1.9 s): FIFO at 2.0 s.
                assert "last observed: 19" in text
                tg.cancel_scope.cancel()

    _run(main)


def test_next_message_waits_for_a_match_and_times_out_in_sim_time() -> None:
    async def main() -> None:
        async with System([Counter()]) as system:
            sub = system.subscribe("/count", Count)
            message = await next_message(sub, lambda m: m.n == 12, within=5.0)
            assert message == Count(12)
            assert anyio.current_time() == pytest.approx(1.2)
            with pytest.raises(SimTimeoutError, match="last observed: Count"):
                await next_message(sub, lambda m: m.n < 0, within=1.0)
            assert anyio.current_time() == pytest.approx(2.2)

    _run(main)


def test_graph_lists_actors_ports_qos_and_live_statistics() -> None:
    system = System([Counter(), Crasher(at=10**9)])

    async def run() -> None:
        async with system:
            await anyio.sleep(1.05)

    _run(run)
    graph = system.graph()
    assert [a.name for a in graph.actors] == ["counter", "crasher"]
    assert graph.actors[0].outputs == ("/count",)
    assert graph.actors[1].inputs == ("/count",)
    topic = graph.topic("/count")
    assert topic.type.endswith("Count")
    assert topic.publishers[0].published == 10
    assert topic.subscriptions[0].qos == "reliable/depth=10/volatile"
    assert topic.subscriptions[0].statistics.received == 10


def test_real_time_mode_runs_the_same_actors_on_a_stock_loop() -> None:
    source = JumpSource(tick=0.002)
    counter = Counter(hz=100.0)

    async def main() -> None:
        assert type(asyncio.get_running_loop()).__name__ != "VirtualTimeLoop"
        clock = RealTimeClock(source, scale=10.0)  # 10x faster than the wall clock
        async with System([counter], clock=clock) as system:
            sub = system.subscribe("/count", Count)
            with anyio.fail_after(10):  # wall ceiling against a hang (0.05 s expected)
                await next_message(sub, lambda m: m.n >= 50, within=5.0)
            # 50 ticks of 10 ms sim at 100 Hz = 0.5 s sim; the world followed.
            assert clock.now() >= 0.5
            assert source.ticks * 0.002 >= 0.5

    anyio.run(main)
    assert counter.stopped


class _Slow(Actor):
    """An actor whose on_stop takes sim time (it publishes a last message, say)."""

    def __init__(self, name: str, log: list[tuple[str, str, float]], stop_takes: float) -> None:
        super().__init__(name)
        self.events = log
        self.stop_takes = stop_takes

    async def run(self) -> None:
        await anyio.sleep_forever()

    async def on_stop(self) -> None:
        self.events.append((self.name, "on_stop begins", self.clock.now()))
        await self.clock.sleep(self.stop_takes)
        self.events.append((self.name, "on_stop ends", self.clock.now()))


@pytest.mark.parametrize("how", ["exit", "crash"])
def test_actors_stop_one_after_another_in_reverse_start_order(how: str) -> None:
    """ADR 0007: the first actor (the recorder) stops last, after every later actor's
    on_stop has finished, whatever those take (they used to be cancelled together, so a
    recorder listed first drained before the others' last messages)."""
    log: list[tuple[str, str, float]] = []
    first = _Slow("first", log, 0.0)
    second = _Slow("second", log, 0.5)
    third = _Slow("third", log, 0.25)
    actors: list[Actor] = [first, second, third]
    if how == "crash":
        actors.append(Counter(hz=10.0))
        actors.append(Crasher(at=3))  # crashes at sim time 0.3

    async def main() -> None:
        async with System(actors):
            await anyio.sleep(1.0 if how == "exit" else 10.0)

    if how == "crash":
        with pytest.raises(ActorCrashedError):
            _run(main)
    else:
        _run(main)
    t0 = 1.0 if how == "exit" else 0.3
    assert [(name, what) for name, what, _ in log] == [
        ("third", "on_stop begins"),
        ("third", "on_stop ends"),
        ("second", "on_stop begins"),
        ("second", "on_stop ends"),
        ("first", "on_stop begins"),
        ("first", "on_stop ends"),
    ]
    expected = [t0, t0 + 0.25, t0 + 0.25, t0 + 0.75, t0 + 0.75, t0 + 0.75]
    assert [t for *_, t in log] == pytest.approx(expected)


class SelfCanceller(Actor):
    async def run(self) -> None:
        await self.clock.sleep(1.0)
        raise asyncio.CancelledError("nobody asked")


def test_a_cancelled_error_nobody_asked_for_is_a_crash() -> None:
    """It used to be logged as "stopped" and end the run silently at 1.0 s (issue 27)."""
    counter, rogue = Counter(), SelfCanceller("rogue")
    system = System([counter, rogue])

    async def main() -> None:
        with pytest.raises(ActorCrashedError, match=r"actor 'rogue' crashed at sim time 1\.000"):
            async with system:
                await anyio.sleep(100)

    _run(main)
    assert ("rogue", "crashed") in [(e.actor, e.kind) for e in system.events]
    assert counter.stopped
