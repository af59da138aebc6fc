"""One measured run of each configuration, in a fresh child process (so each has its
own peak RSS and nothing warms another's caches)."""

from __future__ import annotations

import asyncio
import resource
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from tempfile import TemporaryDirectory

from otonav.actors import _topics as topics
from otonav.bench._bare import run_bare, run_bare_stack
from otonav.msgs import LaserScan, Point, Pose, PoseStamped
from otonav.runtime import LATCHED_QOS, Actor, Input, virtual_loop_factory
from otonav.scenario import ScenarioConfig
from otonav.stack import StackConfig, WorldConfig, build_actors, build_world
from otonav.stack._session import StackSession


@dataclass(frozen=True, slots=True)
class Case:
    """What to run: ``kind`` is bare (the stack's functions inline) | bare0 (the old
    control law inline) | stack | recorded (``duration`` s of sim), fixed
    (a run of no sim time: the fixed costs) or scenario (the acceptance scenario, as
    ``otonav run`` runs it; ``duration`` unused)."""

    kind: str
    duration: float = 30.0
    beams: int = WorldConfig.model_fields["lidar_beams"].default
    scan_subscribers: int = 0
    """Extra actors subscribed to /scan (scaling with fan-out)."""
    overrides: tuple[str, ...] = ()
    """Stack config ``key.path=value`` overrides (e.g. ``nav.planner=stop``)."""
    boxes: int = 0
    """clutter: boxes in the world (otonav.bench._clutter)."""


@dataclass(frozen=True, slots=True)
class Sample:
    wall_s: float
    sim_s: float
    peak_rss_mb: float
    cpu_s: float = 0.0
    """This process's CPU time over the same span as ``wall_s`` (on a shared, loaded
    machine the steadier figure: time spent waiting for a core is not in it)."""
    phases: tuple[tuple[str, float], ...] = ()
    """fixed: wall seconds per phase; scenario: the summary's RTF."""


class ScanReader(Actor):
    """A /scan subscriber that touches each scan (for the fan-out scaling rows)."""

    scan = Input(topics.SCAN, LaserScan, topics.SENSOR_QOS)

    def __init__(self, i: int) -> None:
        super().__init__(f"scan_reader_{i}")
        self.closest = 0.0

    async def run(self) -> None:
        async for scan in self.scan:
            self.closest = min(scan.ranges)


async def _stack(
    case: Case, stack: StackConfig, goal: tuple[float, float], out: Path | None
) -> tuple[float, float]:
    hal = build_world(stack)
    actors: list[Actor] = [*build_actors(stack, hal)]
    actors += [ScanReader(i) for i in range(case.scan_subscribers)]
    session = StackSession(hal, actors, record_to=out / "bench.mcap" if out else None)
    cpu = time.process_time()
    wall = time.perf_counter()
    try:
        async with session.running(close=False) as system:
            goal_pub = system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS)
            await goal_pub.publish(PoseStamped(pose=Pose(position=Point(x=goal[0], y=goal[1]))))
            await system.clock.sleep(case.duration)
        # The run and its stop, not finishing the file.
        return time.perf_counter() - wall, time.process_time() - cpu
    finally:
        session.close()


def _fixed_costs() -> Sample:
    """A run of no sim time, phase by phase: what a run costs besides its sim seconds
    and its imports. The stack imports some modules lazily on first use (anyio's
    asyncio backend, importlib.resources): one warm-up run pays them, as a sweep
    worker's first run does; the second run is measured."""
    cold = _fixed_run()
    warm = _fixed_run()
    return replace(warm, phases=(*warm.phases, ("first run in a process", cold.wall_s)))


def _fixed_run() -> Sample:
    scenario = ScenarioConfig()
    goal = (scenario.goal.x, scenario.goal.y)
    phases: list[tuple[str, float]] = []
    wall0, cpu0 = time.perf_counter(), time.process_time()
    mark = (wall0, cpu0)

    def lap(name: str) -> None:
        nonlocal mark
        now = (time.perf_counter(), time.process_time())
        phases.append((name, now[0] - mark[0]))
        phases.append((f"{name} (CPU)", now[1] - mark[1]))
        mark = now

    with TemporaryDirectory() as tmp:
        stack = StackConfig()
        hal = build_world(stack)
        lap("world build")
        session = StackSession(hal, build_actors(stack, hal), record_to=Path(tmp) / "f.mcap")
        lap("actors + wiring + file open")

        async def start_stop() -> None:
            try:
                async with session.running(close=False) as system:
                    goal_pub = system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS)
                    await goal_pub.publish(
                        PoseStamped(pose=Pose(position=Point(x=goal[0], y=goal[1])))
                    )
                    lap("loop + actor start")
            finally:
                lap("actor stop")
                session.close()
                lap("finish file + close world")

        with asyncio.Runner(loop_factory=virtual_loop_factory(wall_ceiling=600)) as runner:
            runner.run(start_stop())
        lap("loop close")
        wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return Sample(wall, 0.0, rss, cpu, tuple(phases))


def _scenario() -> Sample:
    """The acceptance scenario as ``otonav run`` runs it (recorded, no plot): its
    summary's RTF (wall from the loop's start to the verdict, fixed costs included)."""
    from otonav.scenario._run import run_scenario

    with TemporaryDirectory() as tmp:
        wall0, cpu0 = time.perf_counter(), time.process_time()
        verdict = run_scenario(ScenarioConfig(), StackConfig(), out_dir=Path(tmp), plot=False)
        wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return Sample(wall, verdict.sim_time_s, rss, cpu, (("summary_rtf", verdict.rtf),))


def run_case(case: Case) -> Sample:
    """Run ``case`` once in this process; wall time excludes building the world."""
    if case.kind == "fixed":
        return _fixed_costs()
    if case.kind == "scenario":
        return _scenario()
    scenario = ScenarioConfig()
    stack = StackConfig(world=WorldConfig(lidar_beams=case.beams))  # the obstacle scene
    if case.overrides:
        from otonav.stack._overrides import apply_overrides

        stack = apply_overrides(stack, case.overrides, source="bench case")
    goal = (scenario.goal.x, scenario.goal.y)
    if case.kind in ("bare", "bare0"):
        hal = build_world(stack)
        bare = run_bare_stack if case.kind == "bare" else run_bare
        cpu = time.process_time()
        wall = time.perf_counter()
        bare(hal, stack, goal, case.duration)
        wall = time.perf_counter() - wall
        cpu = time.process_time() - cpu
        hal.close()
    else:
        with TemporaryDirectory() as tmp:
            out = Path(tmp) if case.kind == "recorded" else None
            with asyncio.Runner(loop_factory=virtual_loop_factory(wall_ceiling=600)) as runner:
                wall, cpu = runner.run(_stack(case, stack, goal, out))
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return Sample(wall, case.duration, rss, cpu)


def run_in_children(
    cases: Sequence[Case], run: Callable[[Case], Sample] = run_case, *, fresh: bool = True
) -> list[Sample]:
    """``run(case)`` for each case in a fresh spawned process, one after another (never
    two at once on this 2-core machine); ``run`` is a module-level function. With
    ``fresh`` False one spawned child runs them all (``--quick``: it checks that the
    bench runs, an import per case is most of its time)."""
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1, maxtasksperchild=1 if fresh else None) as pool:
        return pool.map(run, cases, chunksize=1)
