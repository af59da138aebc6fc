"""Navigation on generated worlds: success, clearance and the BARN metric per density.

    python benchmarks/nav_bench.py [--worlds 200] [--walled 50] [--workers 2]
        [--seed0 0] [--set nav.planner=stop] [--failures DIR] [--json FILE]

For each density (``sparse``, ``dense``: otonav.scenario.generator presets) it runs
``--worlds`` generated worlds (seeds seed0 .. seed0 + worlds - 1, each redrawn until a
path exists for the footprint) and ``--walled`` walled-in worlds of the same density
(the goal inside a closed ring: the navigator must report ``unreachable``), headless in
virtual time with the default stack (``--set`` overrides it), on a process pool. Every
world is rebuilt from its seed in the worker, so results do not depend on the worker
count. Prints a Markdown table, the failures by kind with a few seeds each, and (with
``--failures DIR``) re-runs each failure with its recording and plot into DIR, next to
its scenario YAML (repro: ``otonav run --scenario DIR/NAME.yaml``).

Targets (issue 10): success >= 95 % of the reachable worlds, zero clearance violations,
walled-in >= 95 % reported unreachable before the budget. Anchor: BARN's DWA baseline,
88 % success, 4.8 % collisions.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import sys
import time
from collections import Counter, defaultdict
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict
from pathlib import Path

import yaml

from otonav.scenario import run_scenario
from otonav.scenario.generator import PRESETS, WorldParams, generate_world, walled_in
from otonav.scenario.generator_report import FamilyRow, RunResult, summarise
from otonav.stack import StackConfig
from otonav.stack.overrides import apply_overrides

Task = tuple[str, int, bool, tuple[str, ...]]
"""(density, seed, walled_in, --set overrides)"""


def _params(density: str, walled: bool) -> WorldParams:
    base = PRESETS[density]
    return walled_in(base) if walled else base


def _stack(overrides: tuple[str, ...]) -> StackConfig:
    return apply_overrides(StackConfig(), list(overrides)) if overrides else StackConfig()


def run_one(task: Task) -> RunResult:
    """Rebuild the world from its seed and run it (in a worker process)."""
    density, seed, walled, overrides = task
    world = generate_world(seed, _params(density, walled))
    verdict = run_scenario(
        world.scenario, _stack(overrides), record=False, plot=False, wall_ceiling=900.0
    )
    return RunResult.of(
        density,
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


def _results(tasks: list[Task], workers: int) -> Iterator[RunResult]:
    if workers <= 1:
        yield from map(run_one, tasks)
        return
    context = multiprocessing.get_context("forkserver")
    with ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
        yield from pool.map(run_one, tasks, chunksize=1)


def _fmt(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)


def table(rows: list[FamilyRow]) -> str:
    head = (
        "| density | worlds | reachable | success (% of reachable) | BARN metric "
        "| time / optimal (median) "
        "| timeouts | false unreachable | clearance violations (all runs) "
        "| walled-in reported unreachable | walled-in timeouts |"
    )
    lines = [head, "|" + "|".join("---" for _ in range(head.count("|") - 1)) + "|"]
    for r in rows:
        lines.append(
            f"| {r.family} | {r.worlds} | {r.reachable} "
            f"| {r.successes} ({_fmt(r.success_pct, '.1f')} %) "
            f"| {_fmt(r.barn_metric, '.3f')} | {_fmt(r.time_ratio_median, '.2f')} "
            f"| {r.timeouts} | {r.gave_up} "
            f"| {r.clearance_violations} of {r.runs} "
            f"| {r.walled_reported} of {r.walled} ({_fmt(r.walled_reported_pct, '.1f')} %) "
            f"| {r.walled_timeouts} |"
        )
    return "\n".join(lines)


def _record_failure(result: RunResult, overrides: tuple[str, ...], out: Path) -> str:
    world = generate_world(result.seed, _params(result.family, result.expect == "unreachable"))
    name = world.scenario.name
    path = out / f"{name}.yaml"
    path.write_text(yaml.safe_dump(world.scenario.model_dump(mode="json"), sort_keys=False))
    verdict = run_scenario(world.scenario, _stack(overrides), out_dir=out / name)
    return f"{path} -> {verdict.recording}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=200, help="per density (default 200)")
    parser.add_argument("--walled", type=int, default=50, help="walled-in per density (50)")
    parser.add_argument("--densities", nargs="+", default=["sparse", "dense"])
    parser.add_argument("--seed0", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--set", dest="overrides", action="append", default=[])
    parser.add_argument("--failures", type=Path, help="re-run failures with recordings here")
    parser.add_argument("--json", type=Path, help="write every run's figures here")
    args = parser.parse_args()
    unknown = [d for d in args.densities if d not in ("sparse", "dense")]
    if unknown:
        print(f"--densities: {unknown} not valid (sparse, dense)", file=sys.stderr)
        return 2
    overrides = tuple(args.overrides)
    _stack(overrides)  # a bad --set fails here, before any run
    tasks: list[Task] = [
        (density, args.seed0 + i, walled, overrides)
        for density in args.densities
        for walled, count in ((False, args.worlds), (True, args.walled))
        for i in range(count)
    ]
    started = time.perf_counter()
    by_family: dict[str, list[RunResult]] = defaultdict(list)
    for done, result in enumerate(_results(tasks, args.workers), 1):
        by_family[result.family].append(result)
        if done % 25 == 0 or done == len(tasks):
            print(
                f"  {done}/{len(tasks)} runs, {time.perf_counter() - started:.0f} s",
                file=sys.stderr,
                flush=True,
            )
    wall = time.perf_counter() - started
    rows = [summarise(d, by_family[d]) for d in args.densities]
    print(
        f"nav_bench: {args.worlds} worlds + {args.walled} walled-in per density, "
        f"seeds {args.seed0}.., stack overrides {list(overrides) or 'none'}, "
        f"{args.workers} workers, {wall:.0f} s wall"
    )
    print()
    print(table(rows))
    print()
    all_results = [r for d in args.densities for r in by_family[d]]
    failures = [r for r in all_results if r.failure is not None]
    kinds = Counter(f"{r.family}: {r.failure}" for r in failures)
    if failures:
        print("failures by kind (a few seeds each):")
        for kind, n in kinds.most_common():
            family, _, what = kind.partition(": ")
            seeds = [r.seed for r in failures if r.family == family and r.failure == what]
            print(f"  {kind}: {n}  seeds {seeds[:8]}")
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
