"""The run itself, shared by the virtual-time and the real-time runner: publish the
goal, wait in sim time for the judge, and end every way the same (:func:`judged_run`)."""

from __future__ import annotations

import asyncio
import contextlib
import importlib
import signal
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from otonav.actors import _topics as topics
from otonav.hal import RobotHardwareInterface
from otonav.msgs import Header, Point, Pose, PoseStamped, Time
from otonav.runtime import (
    LATCHED_QOS,
    ActorCrashedError,
    SimTimeoutError,
    until,
)
from otonav.runtime._asyncio_compat import preload_anyio_backend
from otonav.scenario._artifacts import PlotWhen, save_artifacts
from otonav.scenario._config import ScenarioConfig
from otonav.scenario._crash import RunCrashedError, crash_reason
from otonav.scenario._judge import Judge
from otonav.scenario._verdict import Verdict, judge_verdict, robot_summary
from otonav.stack import StackConfig
from otonav.stack._session import StackSession

LAZY_IMPORTS = ("numpy.ma",)
"""Modules a process's first run would otherwise import inside its timed span, with
anyio's asyncio backend (when the loop starts; :func:`preload_lazy_imports`): numpy.ma
(numpy imports it at the first ``np.unique``, in the navigator's map). 25-110 ms on this
machine: imports, not the run, so they load before the summary's wall clock starts (ADR
0027)."""


def preload_lazy_imports() -> None:
    """Import :data:`LAZY_IMPORTS` and anyio's asyncio backend now."""
    preload_anyio_backend()
    for module in LAZY_IMPORTS:
        importlib.import_module(module)


async def drive(session: StackSession, scenario: ScenarioConfig, judge: Judge) -> None:
    """Run ``session`` (not closing it): publish the goal on /goal, then wait in sim time
    until the judge is done or the budget is spent (a verdict, not an error)."""
    async with session.running(close=False) as system:
        goal = system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS, name="scenario")
        await goal.publish(
            PoseStamped(
                header=Header(stamp=Time.from_seconds(system.clock.now()), frame_id="odom"),
                pose=Pose(position=Point(x=scenario.goal.x, y=scenario.goal.y)),
            )
        )
        # Running out of budget is a verdict (judged below), not an error. The run also
        # ends when the navigator gives up (/nav/state ``unreachable``): whether that
        # passes depends on the scenario's ``expect``.
        with contextlib.suppress(SimTimeoutError):
            await until(
                lambda: judge.finished or judge.entered,
                within=scenario.sim_budget,
                observe=lambda: f"{judge.distance:.3f} m from the goal",
                what=f"reaching the goal within {scenario.goal_tolerance} m",
            )
        if judge.entered and not judge.finished:
            # Entering the tolerance is not arriving: the judge checks settle_s later
            # (past the budget if need be) that the robot stopped there.
            with contextlib.suppress(SimTimeoutError):
                await until(
                    lambda: judge.finished,
                    within=judge.settle_s + 2.0 / judge.rate_hz,
                    what="the arrival check",
                )


@contextlib.contextmanager
def run_task(
    on_start: Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None] | None,
) -> Iterator[None]:
    """The current task is a scenario run: hand it to ``on_start`` (a host that may
    cancel it), and let SIGTERM end it like Ctrl-C does (asyncio.Runner handles SIGINT):
    by cancellation, so every finally runs and the recording is finished."""
    loop = asyncio.get_running_loop()
    task = asyncio.current_task()
    if on_start is not None and task is not None:
        on_start(loop, task)
    # Only over the default handler (asyncio.Runner's rule for SIGINT): a host that
    # handles SIGTERM itself (the CLI) keeps its handler. Cancel once: a second
    # SIGTERM must not cancel the shutdown's own awaits.
    own = (
        threading.current_thread() is threading.main_thread()
        and task is not None
        and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL
    )
    if own and task is not None:
        loop.add_signal_handler(signal.SIGTERM, _cancel_once, task)
    try:
        yield
    finally:
        if own:
            loop.remove_signal_handler(signal.SIGTERM)


def _cancel_once(task: asyncio.Task[Any]) -> None:
    if not task.cancelling():
        task.cancel()


@dataclass(frozen=True, slots=True)
class JudgedRun:
    """What a judged run is made of, for :func:`judged_run`."""

    scenario: ScenarioConfig
    stack: StackConfig
    hal: RobotHardwareInterface
    judge: Judge
    session: StackSession
    out_dir: Path | None
    plot: PlotWhen


def judged_run(
    parts: JudgedRun,
    run: Callable[[], None],
    sim_time: Callable[[], float],
    *,
    amend: Callable[[Verdict], Verdict] | None = None,
) -> Verdict:
    """``run()`` the scenario, then judge it and tear it down, whatever ended it: the
    verdict (failed with "run ended early (...)" if ``run`` raised; ``amend(verdict)``
    may change one that completed), appended to the recording, the plot drawn, the
    session closed. An actor's crash raises :class:`RunCrashedError` carrying the
    verdict, once the artifacts are written; any other exception propagates after them.
    ``sim_time()`` is the run's sim time (after ``run`` returned or raised). The one
    ending of every judged runner (virtual and real time)."""
    scenario, stack, judge, session = parts.scenario, parts.stack, parts.judge, parts.session
    wall_start = time.perf_counter()
    ended = "completed"
    crash: ActorCrashedError | None = None
    try:
        run()
    except ActorCrashedError as exc:  # a verdict still (below), raised with it
        crash, ended = exc, f"ActorCrashedError: {crash_reason(exc)}"
    except BaseException as exc:
        ended = f"{type(exc).__name__} at sim time {sim_time():.3f} s: {exc}"
        ended = ended.strip().rstrip(":")
        raise
    finally:
        wall = time.perf_counter() - wall_start
        try:
            verdict = judge_verdict(
                scenario, judge, sim_time(), wall, robot=robot_summary(stack, parts.hal)
            )
            if ended != "completed":
                verdict = replace(verdict, passed=False, reason=f"run ended early ({ended})")
            elif amend is not None:
                verdict = amend(verdict)
            verdict = save_artifacts(
                verdict, scenario, stack, judge, session, parts.out_dir, parts.plot
            )
        finally:
            session.close()  # idempotent: reached even if the verdict or plot failed
    if crash is not None:
        raise RunCrashedError(crash, verdict) from crash.__cause__
    return verdict
