"""otonav.embed on a host's own (stock) asyncio loop: the live stack's subscriptions,
goals, graph and clean close; the bounded catch-up of its clock; simulations in worker
threads, bounded and cancellable, leaving indexed recordings."""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Any

import anyio
import pytest

from otonav.actors import topics
from otonav.embed import (
    HOST_QOS,
    LiveStack,
    check_run,
    open_live_stack,
    run_scenario_async,
)
from otonav.msgs import LaserScan, Odometry, PoseStamped
from otonav.record._reader import read_messages, summarize
from otonav.runtime import (
    LATCHED_QOS,
    Actor,
    ActorCrashedError,
    JumpSource,
    QoSIncompatibleError,
    RealTime,
    RealTimeClock,
    TopicTypeError,
    until,
)
from otonav.scenario import GoalSpec, ScenarioConfig
from otonav.stack._files import ConfigFileError

pytestmark = pytest.mark.smoke

WALL_CEILING = 20.0
ENDLESS = ScenarioConfig(
    name="endless",
    scene="empty",
    goal=GoalSpec(x=3.0, y=-1.0),
    goal_tolerance=0.001,  # the navigator stops 8 cm short: never reached
    sim_budget=600.0,
)


def _host_subscribers(live: LiveStack, topic: str) -> int:
    return sum(1 for s in live.graph().topic(topic).subscriptions if s.actor == "host")


@pytest.mark.asyncio
async def test_live_stack_on_the_host_loop(tmp_path: Path) -> None:
    record = tmp_path / "live.mcap"
    with anyio.fail_after(WALL_CEILING):
        async with open_live_stack(record_to=record, time=RealTime(2.0)) as live:
            odom = live.subscribe(topics.ODOM, Odometry, HOST_QOS)
            first = await anext(odom)
            assert isinstance(first, Odometry)
            assert _host_subscribers(live, topics.ODOM) == 1
            # Wiring checks hold for the host too: QoS and type, at subscribe time.
            # The default is reliable, as System.subscribe's (ADR 0056): refused on
            # best-effort /scan, naming the fix. (/odom is reliable, as ROS 2 offers it.)
            with pytest.raises(QoSIncompatibleError, match=r"/scan.*SENSOR_DATA_QOS"):
                live.subscribe(topics.SCAN, LaserScan)
            with pytest.raises(TopicTypeError, match="/odom"):
                live.subscribe(topics.ODOM, PoseStamped)

            goals = live.subscribe(topics.GOAL, PoseStamped, LATCHED_QOS)
            await live.publish_goal(1.0, 0.2)
            assert (await anext(goals)).pose.position.x == 1.0
            goals.close()
            assert _host_subscribers(live, topics.GOAL) == 0
            await until(
                lambda: live.hal.ground_truth().x > 0.2,
                within=10.0,
                clock=live.clock,
                what="the robot drove toward the posted goal",
            )
            assert live.running
            assert live.slip_s < 0.5

            received: list[Odometry] = []

            async def read_all() -> None:
                async for message in odom:
                    received.append(message)

            reader = asyncio.create_task(read_all())
            await until(lambda: len(received) >= 3, within=5.0, clock=live.clock)
        # Closing the stack ended every host iterator: the reader returned by itself.
        await reader
    assert not live.running
    assert live.failure is None
    summary = summarize(record)
    assert summary.truncated is False
    goal_messages = list(read_messages(record, [topics.GOAL]))
    assert [m.pose.position.x for _, _, m in goal_messages] == [1.0]


@pytest.mark.asyncio
@pytest.mark.parametrize("how", ["task.cancel", "anyio scope"])
async def test_host_cancellation_closes_the_stack_and_its_recording(
    tmp_path: Path, how: str
) -> None:
    record = tmp_path / "live.mcap"
    opened = asyncio.Event()

    async def host() -> None:
        async with open_live_stack(record_to=record) as live:
            async for _ in live.subscribe(topics.ODOM, Odometry, HOST_QOS):
                opened.set()

    with anyio.fail_after(WALL_CEILING):
        if how == "task.cancel":
            task = asyncio.create_task(host())
            await opened.wait()
            task.cancel()
            with pytest.raises(asyncio.CancelledError):
                await task
        else:
            async with anyio.create_task_group() as tg:
                tg.start_soon(host)
                await opened.wait()
                tg.cancel_scope.cancel()
    summary = summarize(record)
    assert summary.truncated is False
    assert summary.message_count > 0


class _Boom(Actor):
    async def run(self) -> None:
        await self.clock.sleep(0.1)
        raise RuntimeError("boom")


@pytest.mark.asyncio
async def test_a_crashing_actor_stops_the_stack_not_the_host(tmp_path: Path) -> None:
    record = tmp_path / "live.mcap"
    seen: list[BaseException | None] = []

    async def host() -> None:
        async with open_live_stack(record_to=record, extra_actors=[_Boom("boom")]) as live:
            async for _ in live.subscribe(topics.ODOM, Odometry, HOST_QOS):
                pass  # ends when the stack stops
            # The host's code goes on; the stack says why it stopped.
            seen.append(live.failure)
            assert not live.running

    with anyio.fail_after(WALL_CEILING), pytest.raises(ActorCrashedError, match="boom"):
        await host()  # ... and its crash is raised when the context exits
    assert isinstance(seen[0], ActorCrashedError)
    assert summarize(record).truncated is False


class _CountingSource(JumpSource):
    def __init__(self, tick: float) -> None:
        super().__init__(tick)
        self.batches: list[int] = []

    def advance(self, n: int) -> None:
        self.batches.append(n)
        super().advance(n)


def test_a_stalled_host_slips_sim_time_instead_of_stepping_one_long_batch() -> None:
    source = _CountingSource(0.002)
    loop = asyncio.new_event_loop()
    stall = [0.0]
    real_time = loop.time
    setattr(loop, "time", lambda: real_time() + stall[0])  # noqa: B010 - a stall, simulated

    async def main() -> tuple[float, float]:
        clock = RealTimeClock(source, scale=1.0)  # capped at MAX_STEP_BATCH by default
        start = clock.now()
        pacer = asyncio.ensure_future(clock.pace())
        sleeper = asyncio.ensure_future(clock.sleep_until(start + 0.2))
        await asyncio.sleep(0)
        stall[0] = 1.0  # the loop "was blocked" for a wall second
        await sleeper
        pacer.cancel()
        return clock.now() - start, clock.slip_s

    try:
        elapsed, slip = loop.run_until_complete(main())
    finally:
        loop.close()
    assert max(source.batches) <= 25  # 0.05 s of 2 ms steps
    # The stalled second, less the one batch stepped (and the sleeper's few ms).
    assert 0.9 <= slip <= 1.0
    assert source.ticks >= 100  # the sleeper still woke at (or after) its sim instant
    assert elapsed >= 0.2


@pytest.mark.asyncio
@pytest.mark.parametrize("how", ["task.cancel", "anyio scope"])
async def test_cancelled_simulation_leaves_a_finished_recording(tmp_path: Path, how: str) -> None:
    host_loop = asyncio.get_running_loop()
    started = asyncio.Event()

    def on_start(_loop: asyncio.AbstractEventLoop, _task: asyncio.Task[None]) -> None:
        host_loop.call_soon_threadsafe(started.set)

    async def run() -> None:
        await run_scenario_async(ENDLESS, out_dir=tmp_path, plot=False, on_start=on_start)

    with anyio.fail_after(WALL_CEILING):
        if how == "task.cancel":
            task = asyncio.create_task(run())
            await started.wait()
            task.cancel()
            with pytest.raises(asyncio.CancelledError):
                await task
        else:
            async with anyio.create_task_group() as tg:
                tg.start_soon(run)
                await started.wait()
                tg.cancel_scope.cancel()
    # Finished before the cancellation reached us: indexed, with the verdict appended.
    summary = summarize(tmp_path / "recording.mcap")
    assert summary.truncated is False
    assert "run ended early" in summary.metadata["otonav"]["verdict"]


@pytest.mark.asyncio
async def test_a_limiter_bounds_the_simulations_running_at_once() -> None:
    limiter = anyio.CapacityLimiter(1)
    loops: list[asyncio.AbstractEventLoop] = []
    overlaps: list[bool] = []
    short = ENDLESS.model_copy(update={"sim_budget": 1.0})

    def on_start(loop: asyncio.AbstractEventLoop, _task: asyncio.Task[None]) -> None:
        overlaps.append(any(not other.is_closed() for other in loops))
        loops.append(loop)

    verdicts: list[Any] = []

    async def one() -> None:
        verdicts.append(
            await run_scenario_async(
                short, out_dir=None, plot=False, limiter=limiter, on_start=on_start
            )
        )

    with anyio.fail_after(WALL_CEILING):
        async with anyio.create_task_group() as tg:
            for _ in range(3):
                tg.start_soon(one)
    assert overlaps == [False, False, False]
    assert [v.sim_time_s for v in verdicts] == [1.0, 1.0, 1.0]


@pytest.mark.asyncio
async def test_the_host_loop_keeps_serving_while_a_simulation_runs() -> None:
    """The host's loop runs between the simulation's instants, not before and after it:
    a ticker on the host reads the run's sim time (its loop's ``time()``) and must see
    it at many instants inside the run. A simulation on the host's loop would be seen at
    its start and its end only. (The wall-clock gaps: benchmarks/embed_bench.py.)"""
    budget = 10.0
    run_loop: list[asyncio.AbstractEventLoop] = []
    seen: list[float] = []

    def on_start(loop: asyncio.AbstractEventLoop, _task: asyncio.Task[None]) -> None:
        run_loop.append(loop)

    async def ticker() -> None:
        while True:
            await anyio.sleep(0.005)
            if run_loop:
                seen.append(run_loop[0].time())

    with anyio.fail_after(WALL_CEILING):
        async with anyio.create_task_group() as tg:
            tg.start_soon(ticker)
            verdict = await run_scenario_async(
                ENDLESS.model_copy(update={"sim_budget": budget}),
                out_dir=None,
                plot=False,
                on_start=on_start,
            )
            tg.cancel_scope.cancel()
    assert verdict.sim_time_s == budget
    inside = sorted({t for t in seen if 0.0 < t < budget})
    assert len(inside) >= 5, f"the host ran at sim instants {sorted(set(seen))} only"
    # Spread over the run, not bunched at one end.
    assert inside[0] < budget / 2 < inside[-1], inside


def test_check_run_raises_what_the_cli_would() -> None:
    with pytest.raises(ConfigFileError, match="outside the arena"):
        check_run(ScenarioConfig(goal=GoalSpec(x=40.0, y=0.0)), source="scenario")
    check_run(ScenarioConfig())
