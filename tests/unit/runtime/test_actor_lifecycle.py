"""The actor lifecycle under supervision: ``on_failure``, a failing ``on_stop``, and
what a restart keeps (ADR 0051)."""

from __future__ import annotations

from dataclasses import dataclass

import anyio
import pytest

from otonav.runtime import (
    Actor,
    ActorCrashedError,
    ActorStatus,
    EventKind,
    Input,
    Output,
    RestartPolicy,
    System,
    virtual_loop_factory,
)

pytestmark = pytest.mark.unit


@dataclass(frozen=True, slots=True)
class Count:
    n: int


@dataclass(frozen=True, slots=True)
class Fault:
    text: str


def _run(main: object) -> None:
    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})  # type: ignore[arg-type]


class Burst(Actor):
    """Publishes ``size`` counts at once, every 0.1 s."""

    out = Output("/count", Count)

    def __init__(self, size: int = 1) -> None:
        super().__init__("burst")
        self.size = size

    async def run(self) -> None:
        rate = self.clock.rate(10.0)
        n = 0
        while True:
            await rate.sleep()
            for _ in range(self.size):
                n += 1
                await self.out.publish(Count(n))


class Worker(Actor):
    """Crashes on every count divisible by ``at``; logs its whole life."""

    inp = Input("/count", Count)
    fault = Output("/fault", Fault)

    def __init__(
        self,
        system: list[System],
        at: int,
        *,
        failure_raises: bool = False,
        stop_raises: bool = False,
        stop_takes: float = 0.0,
    ) -> None:
        super().__init__("worker")
        self.system = system
        self.at = at
        self.failure_raises = failure_raises
        self.stop_raises = stop_raises
        self.stop_takes = stop_takes
        self.life: list[str] = []
        self.seen: list[int] = []
        self.failures: list[BaseException] = []
        self.events_at_failure: list[list[str]] = []

    async def on_start(self) -> None:
        self.life.append(f"on_start (seen {self.seen})")

    async def run(self) -> None:
        async for message in self.inp:
            self.seen.append(message.n)
            if message.n % self.at == 0:
                raise ValueError(f"bad count {message.n}")

    async def on_failure(self, exc: Exception) -> None:
        self.life.append("on_failure")
        self.failures.append(exc)
        self.events_at_failure.append([f"{e.kind}" for e in self.system[0].events])
        await self.fault.publish(Fault(str(exc)))  # a last word, before supervision acts
        if self.failure_raises:
            raise RuntimeError("on_failure is broken too")

    async def on_stop(self) -> None:
        self.life.append("on_stop")
        await self.clock.sleep(self.stop_takes)
        if self.stop_raises:
            raise OSError("could not close the device")


def _worker_system(
    at: int, restart: RestartPolicy | None = None, size: int = 1, **worker: bool | float
) -> tuple[System, Worker]:
    holder: list[System] = []
    actor = Worker(holder, at, **worker)  # type: ignore[arg-type]
    system = System([Burst(size), actor], restart={"worker": restart} if restart else None)
    holder.append(system)
    return system, actor


# -- on_failure ------------------------------------------------------------------------


def test_on_failure_gets_the_exception_after_the_crash_is_reported_and_before_on_stop() -> None:
    system, worker = _worker_system(at=3)
    faults: list[Fault] = []

    async def body() -> None:
        async with system:
            sub = system.subscribe("/fault", Fault)
            async with anyio.create_task_group() as tg:

                async def drain() -> None:
                    async for fault in sub:
                        faults.append(fault)

                tg.start_soon(drain)
                await anyio.sleep(100)

    async def main() -> None:
        with pytest.raises(ActorCrashedError) as err:
            await body()
        assert err.value.__cause__ is worker.failures[0]

    _run(main)
    assert [str(e) for e in worker.failures] == ["bad count 3"]
    assert worker.life == ["on_start (seen [])", "on_failure", "on_stop"]
    # The crash is reported first; no decision (restart or stop) is made before it returns.
    assert worker.events_at_failure[0][-1] == "crashed"
    assert faults == [Fault("bad count 3")]  # its ports still work in on_failure


def test_on_failure_runs_before_the_restart_decision_once_per_crash() -> None:
    system, worker = _worker_system(at=2, restart=RestartPolicy(2, window=10.0))

    async def main() -> None:
        with pytest.raises(ActorCrashedError):
            async with system:
                await anyio.sleep(100)

    _run(main)
    assert len(worker.failures) == 3  # two restarts, then the cap
    for seen in worker.events_at_failure:
        assert seen[-1] == "crashed"
        assert seen.count("restarted") == seen.count("crashed") - 1


def test_on_failure_is_called_when_on_start_raises() -> None:
    class BadStart(Actor):
        def __init__(self) -> None:
            super().__init__("bad_start")
            self.failures: list[Exception] = []

        async def on_start(self) -> None:
            raise KeyError("missing calibration")

        async def on_failure(self, exc: Exception) -> None:
            self.failures.append(exc)

    actor = BadStart()

    async def main() -> None:
        with pytest.raises(ActorCrashedError, match="missing calibration"):
            async with System([actor]):
                await anyio.sleep(1)

    _run(main)
    assert [type(e) for e in actor.failures] == [KeyError]


def test_a_failing_on_failure_is_reported_and_the_actor_is_not_restarted() -> None:
    system, worker = _worker_system(at=2, restart=RestartPolicy(5), failure_raises=True)

    async def main() -> None:
        with pytest.raises(ActorCrashedError) as err:
            async with system:
                await anyio.sleep(100)
        assert isinstance(err.value.__cause__, ValueError)  # the crash that started it
        assert "on_failure is broken too" in err.value.traceback_text

    _run(main)
    kinds = [(e.kind, e.detail.split(":")[0]) for e in system.events if e.actor == "worker"]
    assert (EventKind.CRASHED, "in on_failure") in kinds
    assert EventKind.RESTARTED not in [k for k, _ in kinds]
    assert worker.life == ["on_start (seen [])", "on_failure", "on_stop"]


def test_on_failure_is_not_called_when_nothing_failed() -> None:
    system, worker = _worker_system(at=10**9)

    async def main() -> None:
        async with system:
            await anyio.sleep(1.0)

    _run(main)
    assert worker.life == ["on_start (seen [])", "on_stop"]


# -- a failing on_stop is a crash --------------------------------------------------------


def test_an_exception_in_on_stop_at_shutdown_is_reported_like_a_crash() -> None:
    """It used to be an event only: the run ended green and the verdict never saw it."""
    system, _ = _worker_system(at=10**9, stop_raises=True)

    async def main() -> None:
        with pytest.raises(ActorCrashedError) as err:
            async with system:
                await anyio.sleep(1.0)
        assert err.value.actor == "worker"
        assert err.value.sim_time == pytest.approx(1.0)
        assert isinstance(err.value.__cause__, OSError)
        assert "in on_stop" in err.value.traceback_text
        assert "could not close the device" in err.value.traceback_text

    _run(main)
    mine = [e for e in system.events if e.actor == "worker"]
    assert [e.kind for e in mine] == ["started", "crashed", "stopped"]
    assert system.graph().actors[1].status is ActorStatus.CRASHED


def test_an_exception_in_on_stop_after_run_returned_stops_the_system() -> None:
    class Finisher(Actor):
        async def run(self) -> None:
            await self.clock.sleep(0.5)

        async def on_stop(self) -> None:
            raise OSError("flush failed")

    burst = Burst()

    async def main() -> None:
        with pytest.raises(ActorCrashedError, match=r"actor 'finisher' crashed at sim time 0\.500"):
            async with System([burst, Finisher()]):
                await anyio.sleep(100)
        assert anyio.current_time() == pytest.approx(0.5)  # not at the body's end

    _run(main)


def test_an_exception_in_on_stop_during_a_restart_stops_instead_of_restarting() -> None:
    system, worker = _worker_system(at=2, restart=RestartPolicy(5), stop_raises=True)

    async def main() -> None:
        with pytest.raises(ActorCrashedError) as err:
            async with system:
                await anyio.sleep(100)
        assert isinstance(err.value.__cause__, OSError)
        assert anyio.current_time() == pytest.approx(0.2)

    _run(main)
    assert worker.life == ["on_start (seen [])", "on_failure", "on_stop"]


# -- a restart keeps the instance --------------------------------------------------------


def test_a_restart_keeps_the_instance_its_state_and_its_mailboxes() -> None:
    """ADR 0051: restarting re-runs on_start on the same object, with what the crashed
    run left in its attributes and in its mailboxes; on_start resets what must be fresh."""
    system, worker = _worker_system(at=2, restart=RestartPolicy(1, window=10.0), size=3)

    async def main() -> None:
        with pytest.raises(ActorCrashedError):
            async with system:
                await anyio.sleep(100)

    _run(main)
    assert system.actor("worker") is worker
    # Burst publishes 1, 2, 3 at 0.1 s: 2 crashes the run; the restarted run still finds
    # 3 in its mailbox (nothing lost), then 4 (at 0.2 s) crashes it past the cap.
    assert worker.seen == [1, 2, 3, 4]
    assert worker.life == [
        "on_start (seen [])",
        "on_failure",
        "on_stop",
        "on_start (seen [1, 2])",  # the crashed run's state is there
        "on_failure",
        "on_stop",
    ]


def test_every_on_start_is_paired_with_one_on_stop_even_when_stopped_mid_restart() -> None:
    """A stop requested while the restart's on_stop was running used to call on_stop a
    second time."""
    system, worker = _worker_system(at=2, restart=RestartPolicy(5), stop_takes=1.0)

    async def main() -> None:
        async with system:
            await anyio.sleep(0.5)  # the crash at 0.2 s is in its 1 s on_stop until 1.2 s

    _run(main)
    assert worker.life == ["on_start (seen [])", "on_failure", "on_stop"]
    assert [e.kind for e in system.events if e.actor == "worker"] == [
        "started",
        "crashed",
        "restarted",
        "stopped",
    ]
