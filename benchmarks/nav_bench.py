"""Navigation on generated worlds: success, clearance, planner tick time and the BARN
metric per family.

    python benchmarks/nav_bench.py [--worlds 200] [--walled 50] [--workers 2]
        [--families sparse dense rooms ...] [--seed0 0] [--set nav.planner=stop]
        [--failures DIR] [--json FILE]

Families: the box densities ``sparse`` and ``dense`` (otonav.scenario._generator
presets; each also runs ``--walled`` walled-in worlds of its density) and the indoor
families of benchmarks/indoor_worlds.py (rooms with doors, long walls with the
start facing them, U traps, dead ends, slaloms down to the passable limit, alcove and
corner goals, walled-in rooms), ``--worlds`` each (seeds seed0 .. seed0 + worlds - 1),
headless in virtual time with the default stack (``--set`` overrides it), on a process
pool. Every world is rebuilt from its seed in the worker, so results do not depend on
the worker count.

Prints a Markdown table, one row per family: success on the reachable worlds,
walled-in worlds reported unreachable within the budget, clearance violations, false
``reached`` (the navigator said reached, the judge did not), the planner's tick time
(the navigator's map update and decision per step, CPU time of the thread: p99 and
max over every tick of the family), the longest garbage collection that fell inside a
tick, and the median real-time factor, next to the acceptance scenario's RTF measured in
the same run.

Each process frees a run before the next (``gc.collect()`` outside the timed ticks) and
keeps what it imported, and what its first run left alive, out of the collector's sight
(``gc.freeze()``), as the sweep's warm workers do (ADR 0029): a run's objects are cyclic
garbage that only a full collection frees, and without this about one navigator tick a
family in ~250 runs absorbed a ~35 ms collection of the earlier runs' worlds (ADR 0059).

Then the failures by kind with a few seeds each; ``--failures DIR`` re-runs them with
recordings into DIR next to their scenario YAML (repro: ``otonav run --scenario
DIR/NAME.yaml``).

Targets (issue 24): >= 97 % success on reachable worlds, >= 98 % of unreachable worlds
reported, 0 clearance violations, 0 false reached, planner tick p99 <= 5 ms and max
<= 20 ms on the densest family, its median RTF >= 0.5 x the acceptance scenario's.
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import multiprocessing
import statistics
import sys
import time
from collections import Counter, defaultdict
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from indoor_worlds import INDOOR_FAMILIES, generate_indoor

from otonav.nav._navigate import Navigation
from otonav.scenario import run_scenario
from otonav.scenario._config import ScenarioConfig
from otonav.scenario._generator import (
    PRESETS,
    GeneratedWorld,
    WorldParams,
    generate_world,
    walled_in,
)
from otonav.stack import StackConfig
from otonav.stack._overrides import apply_overrides

BOXES = ("sparse", "dense")
FAMILIES = (*BOXES, *INDOOR_FAMILIES)

Task = tuple[str, int, bool, tuple[str, ...]]
"""(family, seed, walled_in (box families only), --set overrides)"""


# -- scoring: one record per run, one row per family ------------------------------
# Scoring runs of generated worlds: one record per run, one row per family (what the
# navigation benchmark prints, and what a sweep can reuse).
#
# Definitions (issue 10's targets, BARN's metric):
#
# - success: the goal reached within tolerance inside the budget, with the clearance kept
#   (the scenario's verdict passed), counted over the *reachable* worlds;
# - clearance violation: a run whose robot centre came closer than ``min_clearance`` to a
#   box or wall, over *all* runs (walled-in included);
# - BARN metric: mean over the reachable worlds of ``success * optimal / clip(actual,
#   2 optimal, 8 optimal)`` (:func:`barn_metric`); 0.5 at
#   best, so the median of ``actual / optimal`` over the successes is given too (it can
#   dip under 1: the optimal path keeps footprint + clearance from every box, the judge
#   only the clearance, and the run ends at the goal tolerance);
# - walled-in reported: the navigator said ``unreachable`` inside the budget;
# - timeout: the budget ran out with neither the goal reached nor ``unreachable`` said.


def barn_metric(success: bool, actual_s: float, optimal_s: float) -> float:
    """BARN's score of one run: ``success * optimal / clip(actual, 2 optimal, 8
    optimal)``; 0.5 at best (at twice the optimal time or faster), 0 on failure."""
    if not success:
        return 0.0
    return optimal_s / min(max(actual_s, 2.0 * optimal_s), 8.0 * optimal_s)


@dataclass(frozen=True, slots=True)
class RunResult:
    """The figures of one run of one generated world (sim time, ground truth)."""

    family: str
    seed: int
    expect: str
    reachable: bool
    optimal_time_s: float | None
    budget_s: float
    passed: bool
    reached: bool
    time_to_goal_s: float | None
    min_clearance_m: float
    required_clearance_m: float
    unreachable_at_s: float | None
    sim_time_s: float
    final_distance_m: float
    wall_time_s: float
    reason: str

    @classmethod
    def of(
        cls,
        family: str,
        world: GeneratedWorld,
        *,
        passed: bool,
        reached: bool,
        time_to_goal_s: float | None,
        min_clearance_m: float,
        unreachable_at_s: float | None,
        sim_time_s: float,
        final_distance_m: float,
        wall_time_s: float,
        reason: str,
    ) -> RunResult:
        s = world.scenario
        return cls(
            family=family,
            seed=world.seed,
            expect=s.expect,
            reachable=world.reachable,
            optimal_time_s=world.optimal_time_s,
            budget_s=s.sim_budget,
            passed=passed,
            reached=reached,
            time_to_goal_s=time_to_goal_s,
            min_clearance_m=min_clearance_m,
            required_clearance_m=s.min_clearance,
            unreachable_at_s=unreachable_at_s,
            sim_time_s=sim_time_s,
            final_distance_m=final_distance_m,
            wall_time_s=wall_time_s,
            reason=reason,
        )

    @property
    def clearance_violated(self) -> bool:
        return self.min_clearance_m < self.required_clearance_m

    @property
    def gave_up(self) -> bool:
        return self.unreachable_at_s is not None and self.unreachable_at_s <= self.budget_s

    @property
    def timed_out(self) -> bool:
        return not self.reached and not self.gave_up

    @property
    def failure(self) -> str | None:
        """Why this run failed, in a word or two (None when it passed)."""
        if self.passed:
            return None
        if self.clearance_violated:
            return "clearance"
        if self.expect == "unreachable":
            return "reached walled-in goal" if self.reached else "walled-in timeout"
        if self.gave_up:
            return "gave up (false unreachable)"
        return "timeout"

    @property
    def barn(self) -> float:
        if self.optimal_time_s is None or self.time_to_goal_s is None:
            return 0.0
        return barn_metric(self.passed, self.time_to_goal_s, self.optimal_time_s)


@dataclass(frozen=True, slots=True)
class FamilyRow:
    """One density's figures. Percentages are of the reachable (``success_pct``) or of
    the walled-in worlds (``walled_reported_pct``); None when there were none."""

    family: str
    worlds: int
    reachable: int
    successes: int
    success_pct: float | None
    barn_metric: float | None
    time_ratio_median: float | None
    """Median over the successes of time to goal / optimal time."""
    timeouts: int
    gave_up: int
    clearance_violations: int
    runs: int
    walled: int
    walled_reported: int
    walled_reported_pct: float | None
    walled_timeouts: int
    wall_time_s: float


def _pct(part: int, whole: int) -> float | None:
    return 100.0 * part / whole if whole else None


def summarise(family: str, results: Sequence[RunResult]) -> FamilyRow:
    """The row of one family: its reachable worlds, its walled-in worlds, all runs."""
    reach = [r for r in results if r.expect == "reached" and r.reachable]
    walled = [r for r in results if r.expect == "unreachable"]
    successes = sum(r.passed for r in reach)
    reported = sum(r.gave_up and not r.reached for r in walled)
    ratios = [
        r.time_to_goal_s / r.optimal_time_s
        for r in reach
        if r.passed and r.time_to_goal_s is not None and r.optimal_time_s
    ]
    return FamilyRow(
        family=family,
        worlds=sum(r.expect == "reached" for r in results),
        reachable=len(reach),
        successes=successes,
        success_pct=_pct(successes, len(reach)),
        barn_metric=sum(r.barn for r in reach) / len(reach) if reach else None,
        time_ratio_median=statistics.median(ratios) if ratios else None,
        timeouts=sum(r.timed_out for r in reach),
        gave_up=sum(r.gave_up and not r.reached for r in reach),
        clearance_violations=sum(r.clearance_violated for r in results),
        runs=len(results),
        walled=len(walled),
        walled_reported=reported,
        walled_reported_pct=_pct(reported, len(walled)),
        walled_timeouts=sum(r.timed_out for r in walled),
        wall_time_s=sum(r.wall_time_s for r in results),
    )


@dataclass(frozen=True, slots=True)
class Run:
    """One run's figures plus what the judge's verdict alone does not say."""

    result: RunResult
    ticks_ms: tuple[float, ...]
    """The planner's work per navigator step (map update + decision), ms of CPU time."""
    gc_ms: float
    """The longest garbage collection inside one of those ticks, ms of CPU time (0: none)."""
    slowest_at: float
    """Sim time of the slowest tick, s."""
    rtf: float
    false_reached: bool


def _params(density: str, walled: bool) -> WorldParams:
    base = PRESETS[density]
    return walled_in(base) if walled else base


def _world(family: str, seed: int, walled: bool) -> GeneratedWorld:
    if family in BOXES:
        return generate_world(seed, _params(family, walled))
    return generate_indoor(seed, family)


def _stack(overrides: tuple[str, ...]) -> StackConfig:
    return apply_overrides(StackConfig(), list(overrides)) if overrides else StackConfig()


class _TickClock:
    """Times Navigation.observe + Navigation.step per navigator step, in the thread's
    CPU time (a benchmark may read clocks; robot code may not). CPU time, not wall:
    on a shared machine a preempted tick measured the other processes (2 cores, load
    ~4.5: dense seeds 0-7 read p99 12.5 ms / max 31.2 ms of wall time where their
    CPU time was p99 2.2 ms / max 4.6 ms)."""

    def __init__(self) -> None:
        self.ticks: list[float] = []
        self.times: list[float] = []
        self.gc_ms = 0.0
        self._pending = 0.0
        self._saved: tuple[Callable[..., Any], Callable[..., Any]] | None = None
        self._in_tick = False
        self._gc_started = 0.0

    def _on_gc(self, phase: str, info: dict[str, int]) -> None:
        if not self._in_tick:
            return
        if phase == "start":
            self._gc_started = time.thread_time()
        else:
            self.gc_ms = max(self.gc_ms, 1e3 * (time.thread_time() - self._gc_started))

    def __enter__(self) -> _TickClock:
        observe, step = Navigation.observe, Navigation.step
        self._saved = (observe, step)
        clock = self
        gc.callbacks.append(self._on_gc)

        def timed_observe(nav: Navigation, *a: Any, **k: Any) -> int:
            clock._in_tick = True
            t = time.thread_time()
            try:
                return observe(nav, *a, **k)
            finally:
                clock._pending += time.thread_time() - t
                clock._in_tick = False

        def timed_step(nav: Navigation, *a: Any, **k: Any) -> Any:
            clock._in_tick = True
            t = time.thread_time()
            try:
                return step(nav, *a, **k)
            finally:
                clock.ticks.append(1e3 * (time.thread_time() - t + clock._pending))
                clock.times.append(a[0] if a else math.nan)
                clock._pending = 0.0
                clock._in_tick = False

        Navigation.observe = timed_observe  # type: ignore[method-assign,assignment]
        Navigation.step = timed_step  # type: ignore[method-assign,assignment]
        return self

    def __exit__(self, *exc: object) -> None:
        assert self._saved is not None
        Navigation.observe, Navigation.step = self._saved  # type: ignore[method-assign]
        gc.callbacks.remove(self._on_gc)


_runs_here = 0
"""Runs this process has done (the first one's leftovers are frozen after it)."""


def _start_process() -> None:
    """What a fresh process has imported is out of the collector's sight from now on."""
    gc.collect()
    gc.freeze()


def _free_run() -> None:
    """Free the run that just ended (its objects are cyclic garbage), outside the
    timed ticks; after the first run, freeze what it left alive (lazy imports, caches)."""
    global _runs_here
    gc.collect()
    _runs_here += 1
    if _runs_here == 1:
        gc.freeze()


def run_one(task: Task) -> Run:
    """Rebuild the world from its seed and run it (in a worker process)."""
    family, seed, walled, overrides = task
    world = _world(family, seed, walled)
    with _TickClock() as clock:
        verdict = run_scenario(
            world.scenario, _stack(overrides), record=False, plot=False, wall_ceiling=900.0
        )
    _free_run()
    result = RunResult.of(
        family,
        world,
        passed=verdict.passed,
        reached=verdict.reached,
        time_to_goal_s=verdict.time_to_goal_s,
        min_clearance_m=verdict.min_clearance_m,
        unreachable_at_s=verdict.unreachable_at_s,
        sim_time_s=verdict.sim_time_s,
        final_distance_m=verdict.final_distance_m,
        wall_time_s=verdict.wall_time_s,
        reason=verdict.reason,
    )
    return Run(
        result,
        tuple(round(t, 4) for t in clock.ticks),
        clock.gc_ms,
        clock.times[int(np.argmax(clock.ticks))] if clock.ticks else math.nan,
        verdict.sim_time_s / max(verdict.wall_time_s, 1e-9),
        verdict.nav_state == "reached" and not verdict.reached,
    )


def _results(tasks: list[Task], workers: int) -> Iterator[Run]:
    if workers <= 1:
        _start_process()
        yield from map(run_one, tasks)
        return
    context = multiprocessing.get_context("forkserver")
    with ProcessPoolExecutor(
        max_workers=workers, mp_context=context, initializer=_start_process
    ) as pool:
        yield from pool.map(run_one, tasks, chunksize=1)


def _fmt(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def table(rows: list[tuple[FamilyRow, list[Run]]]) -> str:
    head = (
        "| family | worlds | reachable | success (% of reachable) | BARN metric "
        "| time / optimal (median) | timeouts | false unreachable "
        "| unreachable reported | clearance violations | false reached "
        "| tick p99 / max (ms) | GC in a tick (max ms) | RTF (median) |"
    )
    lines = [head, "|" + "|".join("---" for _ in range(head.count("|") - 1)) + "|"]
    for r, runs in rows:
        ticks = np.fromiter((t for run in runs for t in run.ticks_ms), dtype=np.float64)
        p99 = float(np.percentile(ticks, 99)) if ticks.size else None
        worst = float(ticks.max()) if ticks.size else None
        rtf = statistics.median(run.rtf for run in runs) if runs else None
        lines.append(
            f"| {r.family} | {r.worlds + r.walled} | {r.reachable} "
            f"| {r.successes} ({_fmt(r.success_pct, '.1f')} %) "
            f"| {_fmt(r.barn_metric, '.3f')} | {_fmt(r.time_ratio_median, '.2f')} "
            f"| {r.timeouts} | {r.gave_up} "
            f"| {r.walled_reported} of {r.walled} ({_fmt(r.walled_reported_pct, '.1f')} %) "
            f"| {r.clearance_violations} of {r.runs} "
            f"| {sum(run.false_reached for run in runs)} "
            f"| {_fmt(p99, '.2f')} / {_fmt(worst, '.1f')} "
            f"| {_fmt(max((run.gc_ms for run in runs), default=None), '.1f')} "
            f"| {_fmt(rtf, '.1f')} |"
        )
    return "\n".join(lines)


def _record_failure(result: RunResult, overrides: tuple[str, ...], out: Path) -> str:
    world = _world(result.family, result.seed, result.expect == "unreachable")
    name = world.scenario.name
    path = out / f"{name}.yaml"
    path.write_text(yaml.safe_dump(world.scenario.model_dump(mode="json"), sort_keys=False))
    verdict = run_scenario(world.scenario, _stack(overrides), out_dir=out / name)
    return f"{path} -> {verdict.recording}"


def _acceptance_rtf(overrides: tuple[str, ...]) -> float:
    """The acceptance scenario's RTF, measured here (the yardstick for the families)."""
    verdict = run_scenario(ScenarioConfig(), _stack(overrides), record=False, plot=False)
    return verdict.sim_time_s / max(verdict.wall_time_s, 1e-9)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=200, help="per family (default 200)")
    parser.add_argument("--walled", type=int, default=50, help="walled-in per box density (50)")
    parser.add_argument("--families", nargs="+", default=list(FAMILIES))
    parser.add_argument("--seed0", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--set", dest="overrides", action="append", default=[])
    parser.add_argument("--failures", type=Path, help="re-run failures with recordings here")
    parser.add_argument("--json", type=Path, help="write every run's figures here")
    args = parser.parse_args()
    unknown = [f for f in args.families if f not in FAMILIES]
    if unknown:
        print(f"--families: {unknown} not valid ({', '.join(FAMILIES)})", file=sys.stderr)
        return 2
    overrides = tuple(args.overrides)
    _stack(overrides)  # a bad --set fails here, before any run
    tasks: list[Task] = [
        (family, args.seed0 + i, walled, overrides)
        for family in args.families
        for walled, count in ((False, args.worlds), (True, args.walled if family in BOXES else 0))
        for i in range(count)
    ]
    started = time.perf_counter()
    acceptance_rtf = _acceptance_rtf(overrides)
    by_family: dict[str, list[Run]] = defaultdict(list)
    for done, run in enumerate(_results(tasks, args.workers), 1):
        by_family[run.result.family].append(run)
        if done % 25 == 0 or done == len(tasks):
            print(
                f"  {done}/{len(tasks)} runs, {time.perf_counter() - started:.0f} s",
                file=sys.stderr,
                flush=True,
            )
    wall = time.perf_counter() - started
    rows = [
        (summarise(f, [run.result for run in by_family[f]]), by_family[f]) for f in args.families
    ]
    print(
        f"nav_bench: {args.worlds} worlds per family (+ {args.walled} walled-in per box "
        f"density), seeds {args.seed0}.., stack overrides {list(overrides) or 'none'}, "
        f"{args.workers} workers, {wall:.0f} s wall; acceptance scenario RTF "
        f"{acceptance_rtf:.1f} in this run"
    )
    print()
    print(table(rows))
    print()
    all_results = [run.result for f in args.families for run in by_family[f]]
    failures = [r for r in all_results if r.failure is not None]
    kinds = Counter(f"{r.family}: {r.failure}" for r in failures)
    if failures:
        print("failures by kind (a few seeds each):")
        for kind, n in kinds.most_common():
            family, _, what = kind.partition(": ")
            seeds = [r.seed for r in failures if r.family == family and r.failure == what]
            print(f"  {kind}: {n}  seeds {seeds[:8]}")
    slow = [(max(run.ticks_ms), run) for f in args.families for run in by_family[f] if run.ticks_ms]
    if slow:
        ms, run = max(slow, key=lambda pair: pair[0])
        print(
            f"slowest tick: {ms:.1f} ms ({run.result.family} seed {run.result.seed}, "
            f"{run.result.expect}, at {run.slowest_at:.2f} s of sim time)"
        )
    if all_results:
        worst = min(all_results, key=lambda r: r.min_clearance_m)
        print(
            f"closest approach over all runs: {worst.min_clearance_m:.3f} m "
            f"({worst.family} seed {worst.seed}, {worst.expect})"
        )
    if args.json is not None:
        args.json.write_text(json.dumps([asdict(r) for r in all_results], indent=1))
    if args.failures is not None and failures:
        args.failures.mkdir(parents=True, exist_ok=True)
        for r in failures[:20]:
            print(f"  recorded {_record_failure(r, overrides, args.failures)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
