"""Sim-time budgets hold in real-time mode when sim time slips behind the wall clock.

A RealTimeClock maps sim time to loop time with an offset that moves when it slips
(a stalled loop: the world does not catch up in one burst). A wait whose budget was
turned into a loop-time deadline once then ended early in sim time: the scenario
runner's arrival check (issue 16, item 1) was cut short that way. Here the "wall
clock" is a virtual loop, so the slips are exact and the test takes no wall time.
"""

from __future__ import annotations

import anyio
import pytest

from otonav.runtime import (
    JumpSource,
    RealTimeClock,
    SimTimeoutError,
    System,
    next_message,
    until,
    virtual_loop_factory,
)

pytestmark = pytest.mark.unit


async def _stalls(clock: RealTimeClock) -> None:
    """Ask for the time once every 0.3 s of loop time: each ask slips (the batch cap is
    0.05 s), so sim time falls 0.25 s further behind the loop per stall."""
    while True:
        await anyio.sleep(0.3)
        clock.now()


def _run(main: object) -> float:
    return anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})  # type: ignore[arg-type]


def test_until_spends_its_whole_budget_in_sim_time_despite_slips() -> None:
    async def main() -> float:
        clock = RealTimeClock(JumpSource(0.002), max_step_batch=0.05)
        start = clock.now()
        async with anyio.create_task_group() as tg:
            tg.start_soon(_stalls, clock)
            with pytest.raises(SimTimeoutError):
                await until(lambda: False, within=1.0, clock=clock)
            tg.cancel_scope.cancel()
        assert clock.slip_s > 0.5  # it did slip, a lot
        return clock.now() - start

    assert _run(main) >= 1.0 - 0.002  # to within one tick


def test_next_message_spends_its_whole_budget_in_sim_time_despite_slips() -> None:
    async def main() -> float:
        clock = RealTimeClock(JumpSource(0.002), max_step_batch=0.05)
        async with System([], clock=clock) as system:
            sub = system.subscribe("/nothing", int)
            start = clock.now()
            async with anyio.create_task_group() as tg:
                tg.start_soon(_stalls, clock)
                with pytest.raises(SimTimeoutError):
                    await next_message(sub, within=1.0, clock=clock)
                tg.cancel_scope.cancel()
            waited = clock.now() - start
        return waited

    assert _run(main) >= 1.0 - 0.002  # to within one tick
