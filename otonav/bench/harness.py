"""One measured run of each configuration, in a fresh child process (so each has its
own peak RSS and nothing warms another's caches)."""

from __future__ import annotations

import asyncio
import resource
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from tempfile import TemporaryDirectory

from otonav.actors import topics
from otonav.bench.bare import run_bare
from otonav.msgs import LaserScan, Point, Pose, PoseStamped
from otonav.runtime import LATCHED_QOS, Actor, Input, virtual_loop_factory
from otonav.scenario import ScenarioConfig
from otonav.stack import StackConfig, WorldConfig, build_actors, build_world
from otonav.stack.session import StackSession


@dataclass(frozen=True, slots=True)
class Case:
    """What to run: ``kind`` is bare | stack | recorded."""

    kind: str
    duration: float = 30.0
    beams: int = 360
    scan_subscribers: int = 0
    """Extra actors subscribed to /scan (scaling with fan-out)."""
    overrides: tuple[str, ...] = ()
    """Stack config ``key.path=value`` overrides (e.g. ``nav.planner=stop``)."""


@dataclass(frozen=True, slots=True)
class Sample:
    wall_s: float
    sim_s: float
    peak_rss_mb: float


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
) -> float:
    hal = build_world(stack)
    actors: list[Actor] = [*build_actors(stack, hal)]
    actors += [ScanReader(i) for i in range(case.scan_subscribers)]
    session = StackSession(hal, actors, record_to=out / "bench.mcap" if out else None)
    wall = time.perf_counter()
    try:
        async with session.running(close=False) as system:
            goal_pub = system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS)
            await goal_pub.publish(PoseStamped(pose=Pose(position=Point(x=goal[0], y=goal[1]))))
            await system.clock.sleep(case.duration)
        return time.perf_counter() - wall  # the run and its stop, not finishing the file
    finally:
        session.close()


def run_case(case: Case) -> Sample:
    """Run ``case`` once in this process; wall time excludes building the world."""
    scenario = ScenarioConfig()
    stack = StackConfig(world=WorldConfig(lidar_beams=case.beams))  # the obstacle scene
    if case.overrides:
        from otonav.stack.overrides import apply_overrides

        stack = apply_overrides(stack, case.overrides, source="bench case")
    goal = (scenario.goal.x, scenario.goal.y)
    if case.kind == "bare":
        hal = build_world(stack)
        wall = time.perf_counter()
        run_bare(hal, stack, goal, case.duration)
        wall = time.perf_counter() - wall
        hal.close()
    else:
        with TemporaryDirectory() as tmp:
            out = Path(tmp) if case.kind == "recorded" else None
            with asyncio.Runner(loop_factory=virtual_loop_factory(wall_ceiling=600)) as runner:
                wall = runner.run(_stack(case, stack, goal, out))
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return Sample(wall, case.duration, rss)


def run_in_children(cases: Sequence[Case]) -> list[Sample]:
    """Each case in a fresh spawned process, one after another (never two at once on
    this 2-core machine)."""
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1, maxtasksperchild=1) as pool:
        return pool.map(run_case, cases, chunksize=1)
