"""A scenario run paced to the wall clock (optionally scaled), optionally in MuJoCo's
viewer: the same world, actors, judge, recording and verdict as a virtual-time
:func:`~otonav.scenario._run.run_scenario`, on a stock asyncio loop with a
:class:`~otonav.runtime.RealTimeClock` instead of the virtual-time loop."""

from __future__ import annotations

import asyncio
import time
from collections.abc import Callable
from dataclasses import replace

import anyio

from otonav.hal.mujoco import MujocoInterface, ViewerHandle
from otonav.runtime import RealTimeClock
from otonav.runtime._timesource import tick_rate
from otonav.scenario._config import ScenarioConfig
from otonav.scenario._judge import Judge
from otonav.scenario._judged import JudgedRun, drive, judged_run, run_task
from otonav.scenario._verdict import Verdict
from otonav.stack._session import StackSession

__all__ = ["VIEWER_HZ", "paced_run"]

VIEWER_HZ = 60.0
"""Wall-clock rate at which the viewer is shown the world."""

HOLD_POLL_S = 0.05
"""Wall seconds between looks at whether the user closed the held window."""


async def _show(
    viewer: ViewerHandle, clock: RealTimeClock, closed_at: list[float], stop: anyio.CancelScope
) -> None:
    """Sync the viewer at ``VIEWER_HZ`` wall; if the user closes it, stop the run."""
    rate = clock.rate(VIEWER_HZ / clock.scale)  # the clock's time is sim time
    while viewer.is_running():
        viewer.sync()
        await rate.sleep()  # wakes with the world stepped to the wall clock
    closed_at.append(clock.now())
    stop.cancel()


def _hold(viewer: ViewerHandle, held: list[Verdict], hold: Callable[[Verdict], None]) -> None:
    """Keep the window open on the final state until the user closes it (a cleanup of
    the session: the recording is finished, the world not yet closed)."""
    if not held or not viewer.is_running():
        return  # the run did not finish, or the user closed the window during it
    hold(held[0])
    while viewer.is_running():  # the viewer's thread draws and takes input meanwhile
        time.sleep(HOLD_POLL_S)


async def _main(
    scenario: ScenarioConfig,
    session: StackSession,
    judge: Judge,
    viewer: ViewerHandle | None,
    closed_at: list[float],
    on_start: Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None] | None,
) -> None:
    with run_task(on_start):
        clock = session.realtime_clock
        assert clock is not None
        try:
            async with anyio.create_task_group() as tg:
                if viewer is not None:
                    tg.start_soon(_show, viewer, clock, closed_at, tg.cancel_scope)
                await drive(session, scenario, judge)
                tg.cancel_scope.cancel()
        except BaseExceptionGroup as group:
            # anyio wraps what drive raised (an actor's crash) in a group: the run ends on
            # that exception itself, as a virtual run does (issue 41).
            if len(group.exceptions) != 1:
                raise
            raise group.exceptions[0]  # noqa: B904 - its own cause is kept


def paced_run(
    parts: JudgedRun,
    gui: bool,
    hold: Callable[[Verdict], None] | None,
    on_start: Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None] | None,
    loop_factory: Callable[[], asyncio.AbstractEventLoop] | None,
) -> Verdict:
    """:func:`~otonav.scenario._run.run_scenario` with ``time=RealTime(scale)`` or ``gui``
    (see there), once its scenario is opened."""
    scenario, hal, judge, session = parts.scenario, parts.hal, parts.judge, parts.session
    viewer: ViewerHandle | None = None
    held: list[Verdict] = []
    if gui:
        try:
            # Over CAN the world is the interface's sensor source: view that.
            world = hal if isinstance(hal, MujocoInterface) else getattr(hal, "sensors", None)
            if not isinstance(world, MujocoInterface):
                raise TypeError(f"gui=True needs the MuJoCo world, got {type(hal).__name__}")
            viewer = world.open_viewer()
        except BaseException:
            session.close()
            raise
        session.add_cleanup(viewer.close)  # after the recording, before the world
        if hold is not None:  # cleanups run last added first: before the window closes
            shown = viewer
            session.add_cleanup(lambda: _hold(shown, held, hold))
    closed_at: list[float] = []

    def run() -> None:
        with asyncio.Runner(loop_factory=loop_factory) as runner:
            runner.run(_main(scenario, session, judge, viewer, closed_at, on_start))

    def amend(verdict: Verdict) -> Verdict:
        if closed_at and not judge.reached:
            verdict = replace(
                verdict,
                passed=False,
                reason=(
                    f"stopped: the viewer window was closed at sim time {closed_at[0]:.3f} s "
                    f"({judge.distance:.3f} m from the goal)"
                ),
            )
        held.append(verdict)  # the run completed: what a held window shows
        return verdict

    return judged_run(parts, run, lambda: hal.ticks / tick_rate(hal.tick), amend=amend)
