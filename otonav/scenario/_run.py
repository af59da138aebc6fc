"""Run a scenario on a virtual-time loop driven by the physics world, judge it, and
leave its artifacts: the recording (always finished, whatever ends the run), the
trajectory plot."""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from pathlib import Path

from otonav.runtime import (
    Actor,
    RealTime,
    System,
    TimeMode,
    Virtual,
    virtual_loop_factory,
)
from otonav.scenario._artifacts import PlotWhen
from otonav.scenario._assembly import opened_scenario
from otonav.scenario._config import ScenarioConfig
from otonav.scenario._judge import Judge
from otonav.scenario._judged import JudgedRun, drive, judged_run, preload_lazy_imports, run_task
from otonav.scenario._verdict import Verdict
from otonav.stack import StackConfig
from otonav.stack._session import StackSession

SOURCE = "scenario"
"""What configuration errors name a scenario given as an object (the CLI names its
file)."""
WALL_CEILING = 300.0
"""s of wall time after which a judged run in virtual time counts as hung."""


async def _main(
    scenario: ScenarioConfig,
    session: StackSession,
    judge: Judge,
    on_start: Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None] | None,
) -> None:
    with run_task(on_start):
        await drive(session, scenario, judge)


def run_scenario(
    scenario: ScenarioConfig = ScenarioConfig(),
    stack: StackConfig = StackConfig(),
    *,
    out_dir: Path | None = None,
    record: bool = True,
    plot: PlotWhen = True,
    wall_ceiling: float | None = WALL_CEILING,
    extra_actors: tuple[Actor, ...] = (),
    on_start: Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None] | None = None,
    source: str = SOURCE,
    progress: Callable[[Judge, float], None] | None = None,
    time: TimeMode = Virtual(),
    gui: bool = False,
    hold: Callable[[Verdict], None] | None = None,
    on_system: Callable[[System], None] | None = None,
    loop_factory: Callable[[], asyncio.AbstractEventLoop] | None = None,
) -> Verdict:
    """Run ``scenario`` headless in virtual time and judge it. With ``out_dir``, leave
    ``recording.mcap`` (unless ``record=False``) and ``trajectory.png`` there. The
    recording is finished on every exit path (an exception, Ctrl-C, SIGTERM).
    ``extra_actors`` join the system (monitors, fault injectors). ``on_system(system)``
    is called with the run's wired :class:`~otonav.runtime.System` before it starts: a
    host reaching the actors (``otonav run --foxglove`` serves their parameters).
    ``progress(judge, sim_time)`` is called after every judge sample (the CLI's progress
    line). ``on_start(loop, task)`` is called on the run's loop as it starts (once the
    viewer window, if any, is up): a host running this in a worker thread cancels the
    run with ``loop.call_soon_threadsafe(task.cancel)``. A goal outside the arena or on
    an obstacle raises ``ConfigFileError`` naming ``source``.
    Another run writing to ``out_dir`` raises :class:`~otonav.record._outlock.OutputBusyError`
    before anything is touched. An actor's crash raises
    :class:`~otonav.scenario._crash.RunCrashedError` once the artifacts are written: an
    ``ActorCrashedError`` carrying the failed verdict. A full disk stops the run and
    raises :class:`~otonav.record._diskfull.DiskFullError` naming the file, once the
    recording is closed (readable) and the world too.

    ``time=RealTime(scale)`` paces sim time to the wall clock times ``scale`` instead (the
    same actors, judge and artifacts; ``wall_ceiling`` does not apply), on a stock
    asyncio loop (``loop_factory``: another one, e.g. a test's whose clock it controls).
    ``gui=True`` (real time, scale 1 unless given) shows the run in MuJoCo's viewer: the
    display is checked before anything is built (:class:`~otonav.hal._viewer.NoDisplayError`,
    one line, when there is none), the window opens before the clock starts, is synced at
    ~60 Hz wall and closed at the end; closing it stops the run (the verdict fails and says
    so). ``hold(verdict)`` (with ``gui``): once the run is over and its recording finished,
    it is called (the artifact paths are not set yet) and the window stays open on the
    final state until the user closes it; Ctrl-C ends the hold too."""
    if hold is not None and not gui:
        raise ValueError("run_scenario: hold= needs gui=True (it keeps the viewer open)")
    paced = time if isinstance(time, RealTime) else RealTime() if gui else None
    if gui:
        from otonav.hal._viewer import check_display

        check_display()
    with opened_scenario(
        scenario,
        stack,
        out_dir,
        record,
        source,
        progress,
        tuple(extra_actors),
        time=paced or time,
        on_system=on_system,
    ) as (scenario, stack, hal, judge, session):
        parts = JudgedRun(scenario, stack, hal, judge, session, out_dir, plot)
        if paced is not None:
            from otonav.scenario._realtime import paced_run

            return paced_run(parts, gui, hold, on_start, loop_factory)
        preload_lazy_imports()
        sim_time = [0.0]

        def run() -> None:
            # The session makes the world the loop's time source when the run starts.
            factory = virtual_loop_factory(wall_ceiling=wall_ceiling)
            with asyncio.Runner(loop_factory=factory) as runner:
                try:
                    runner.run(_main(scenario, session, judge, on_start))
                finally:
                    sim_time[0] = runner.get_loop().time()

        return judged_run(parts, run, lambda: sim_time[0])
