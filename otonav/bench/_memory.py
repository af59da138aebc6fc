"""Memory over a long run: does a 10-minute simulated run grow?

One run of (c), the stack with the recorder, for ``duration`` s of sim time, with a
probe actor reading this process's resident set size every ``every`` s of sim time;
a second run does the same with :mod:`tracemalloc` tracing the Python heap (its own
bookkeeping inflates RSS, so RSS is read from the first run, the heap from the second).
Growth is the difference between the first checkpoint (after warm-up) and the last.
"""

from __future__ import annotations

import asyncio
import os
import resource
import tracemalloc
from dataclasses import dataclass
from pathlib import Path
from tempfile import TemporaryDirectory

from otonav.actors import _topics as topics
from otonav.msgs import Point, Pose, PoseStamped
from otonav.runtime import LATCHED_QOS, Actor, virtual_loop_factory
from otonav.scenario import ScenarioConfig
from otonav.stack import StackConfig, build_actors, build_world
from otonav.stack._session import StackSession


def current_rss_mb() -> float:
    """Resident set size now, MB (Linux ``/proc/self/statm``; elsewhere the peak)."""
    try:
        with open("/proc/self/statm") as f:
            pages = int(f.read().split()[1])
        return pages * os.sysconf("SC_PAGE_SIZE") / 2**20
    except (OSError, ValueError, IndexError):
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


@dataclass(frozen=True, slots=True)
class Checkpoint:
    sim_s: float
    rss_mb: float
    heap_mb: float
    """Python heap traced by tracemalloc, MB (0 when not tracing)."""
    recorded_mb: float
    """Size of the recording on disk so far, MB."""


class MemoryProbe(Actor):
    """Every ``every`` s of sim time: RSS, the traced heap and the recording's size."""

    def __init__(self, every: float, recording: Path) -> None:
        super().__init__("memory_probe")
        self.every = every
        self.recording = recording
        self.checkpoints: list[Checkpoint] = []

    async def run(self) -> None:
        rate = self.clock.rate(1.0 / self.every)
        while True:
            await rate.sleep()
            heap = tracemalloc.get_traced_memory()[0] / 2**20 if tracemalloc.is_tracing() else 0.0
            size = self.recording.stat().st_size / 2**20 if self.recording.exists() else 0.0
            self.checkpoints.append(Checkpoint(self.clock.now(), current_rss_mb(), heap, size))


def long_run(duration: float, every: float, trace: bool) -> list[Checkpoint]:
    """(c) for ``duration`` s of sim time in this process; the probe's checkpoints."""
    scenario = ScenarioConfig()
    goal = (scenario.goal.x, scenario.goal.y)
    stack = StackConfig()
    with TemporaryDirectory() as tmp:
        path = Path(tmp) / "long.mcap"
        hal = build_world(stack)
        probe = MemoryProbe(every, path)
        session = StackSession(hal, [*build_actors(stack, hal), probe], record_to=path)

        async def main() -> None:
            async with session.running() as system:
                pub = system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS)
                await pub.publish(PoseStamped(pose=Pose(position=Point(x=goal[0], y=goal[1]))))
                await system.clock.sleep(duration + 1e-6)

        if trace:
            tracemalloc.start()
        try:
            with asyncio.Runner(loop_factory=virtual_loop_factory()) as runner:
                runner.run(main())
        finally:
            if trace:
                tracemalloc.stop()
    return probe.checkpoints


def run_long(duration: float, every: float = 60.0) -> dict[str, object]:
    """Both runs, each in a fresh process; figures for the report."""
    import multiprocessing

    with multiprocessing.get_context("spawn").Pool(1, maxtasksperchild=1) as pool:
        plain = pool.apply(long_run, (duration, every, False))
        traced = pool.apply(long_run, (duration, every, True))
    return {
        "duration_s": duration,
        "every_s": every,
        "checkpoints": [
            {
                "sim_s": p.sim_s,
                "rss_mb": p.rss_mb,
                "heap_mb": t.heap_mb,
                "recorded_mb": p.recorded_mb,
            }
            for p, t in zip(plain, traced, strict=False)
        ],
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
    }


def format_long(result: dict[str, object]) -> str:
    rows: list[dict[str, float]] = result["checkpoints"]  # type: ignore[assignment]
    lines = [
        f"memory over {result['duration_s']:g} s of sim time, stack + recorder "
        "(RSS from one run; Python heap from a second run under tracemalloc):",
        f"  {'sim (s)':>8}{'RSS MB':>9}{'heap MB':>9}{'file MB':>9}",
    ]
    lines += [
        f"  {r['sim_s']:>8.0f}{r['rss_mb']:>9.1f}{r['heap_mb']:>9.2f}{r['recorded_mb']:>9.1f}"
        for r in rows
    ]
    if len(rows) >= 2:
        first, last = rows[0], rows[-1]
        lines.append(
            f"  growth from {first['sim_s']:.0f} s to {last['sim_s']:.0f} s: RSS "
            f"{last['rss_mb'] - first['rss_mb']:+.1f} MB, heap "
            f"{last['heap_mb'] - first['heap_mb']:+.2f} MB; peak RSS of the children "
            f"{result['peak_rss_mb']:.0f} MB"
        )
    return "\n".join(lines)
