"""The avoiding navigator's cost: planner step time, and the stack's bench figure (b)
with it against the stop-only stack, measured in the same run.

    python benchmarks/nav_planner_bench.py [--reps 5] [--duration 30]

1. Step time: the acceptance scenario (and a box straight ahead) with nav.planner=dwa,
   in this process; every Navigation.step (A* replans included) and every scan's
   Navigation.observe (map update), and every safe_command of the safety layer, timed
   with perf_counter. A *tick* is a step plus the observe of the scan that arrived
   with it. Medians and p95, in ms.
2. Figure (b) of ``otonav bench`` (acceptance world, stack without recorder, 30 s of sim
   time): stop-only (nav.planner=stop, no safety layer: the stack as it was), stop-only
   behind the safety layer, and dwa behind the safety layer (the default), interleaved,
   each run in a fresh process; medians and ratios to stop-only, of wall time and of
   the process's CPU time (the steadier figure on a shared machine).
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from typing import Any

from otonav.bench._harness import Case, run_in_children
from otonav.nav import _navigate as navigate
from otonav.scenario import GoalSpec, ScenarioConfig, StartSpec, run_scenario
from otonav.scenario._config import BoxSpec


def _timed(store: list[float], fn: Callable[..., Any]) -> Callable[..., Any]:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return fn(*args, **kwargs)
        finally:
            store.append(time.perf_counter() - t0)

    return wrapper


def _pct(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def step_times() -> None:
    steps: list[float] = []
    observes: list[float] = []
    ticks: list[float] = []
    checks: list[float] = []
    pending = [0.0]
    original_step = navigate.Navigation.step
    original_observe = navigate.Navigation.observe

    def step(self: navigate.Navigation, *args: Any) -> navigate.NavOutput:
        t0 = time.perf_counter()
        out = original_step(self, *args)
        dt = time.perf_counter() - t0
        steps.append(dt)
        ticks.append(dt + pending[0])
        pending[0] = 0.0
        return out

    def observe(self: navigate.Navigation, *args: Any) -> int:
        t0 = time.perf_counter()
        new = original_observe(self, *args)
        dt = time.perf_counter() - t0
        observes.append(dt)
        pending[0] += dt
        return new

    import otonav.actors._safety_layer as layer

    original_check = getattr(layer, "safe_command")  # noqa: B009 (patched for timing)
    setattr(navigate.Navigation, "step", step)  # noqa: B010
    setattr(navigate.Navigation, "observe", observe)  # noqa: B010
    setattr(layer, "safe_command", _timed(checks, original_check))  # noqa: B010
    scenarios = [
        ScenarioConfig(),
        ScenarioConfig(
            name="box_ahead",
            scene="empty",
            start=StartSpec(x=-2.5),
            goal=GoalSpec(x=2.5, y=0.0),
            obstacles=(BoxSpec(x=0.0, y=0.0, size_x=0.6, size_y=0.8),),
            sim_budget=40.0,
        ),
    ]
    try:
        for scenario in scenarios:
            run_scenario(scenario, record=False, plot=False)  # warm-up (imports, caches)
            for store in (steps, observes, ticks, checks):
                store.clear()
            pending[0] = 0.0
            verdict = run_scenario(scenario, record=False, plot=False)
            print(
                f"{scenario.name}: passed {verdict.passed}, {len(steps)} steps at 20 Hz, "
                f"360 beams, {verdict.sim_time_s:.1f} s of sim"
            )
            for label, values in (
                ("planner tick (step + map update)", ticks),
                ("  Navigation.step", steps),
                ("  Navigation.observe (per scan)", observes),
                ("safety check (safe_command, slow path)", checks),
            ):
                if not values:  # the layer's fast path: nothing was ever within reach
                    print(f"  {label:<36} never called (nothing within reach)")
                    continue
                print(
                    f"  {label:<36} median {1e3 * statistics.median(values):6.3f} ms   "
                    f"p95 {1e3 * _pct(values, 0.95):6.3f} ms   max {1e3 * max(values):6.2f} ms"
                )
    finally:
        setattr(navigate.Navigation, "step", original_step)  # noqa: B010
        setattr(navigate.Navigation, "observe", original_observe)  # noqa: B010
        setattr(layer, "safe_command", original_check)  # noqa: B010


CONFIGS = {
    "stop-only, no safety layer": ("nav.planner=stop", "safety.enabled=false"),
    "stop-only + safety layer": ("nav.planner=stop",),
    "dwa + safety layer (default)": (),
}


def bench_b(duration: float, reps: int) -> None:
    cases = [
        Case("stack", duration, overrides=overrides)
        for _ in range(reps)
        for overrides in CONFIGS.values()
    ]
    samples = run_in_children(cases)
    walls: dict[str, float] = {}
    cpus: dict[str, float] = {}
    for name, overrides in CONFIGS.items():
        mine = [s for c, s in zip(cases, samples, strict=True) if c.overrides == overrides]
        walls[name] = statistics.median(s.wall_s for s in mine)
        cpus[name] = statistics.median(s.cpu_s for s in mine)
    base, cpu_base = walls["stop-only, no safety layer"], cpus["stop-only, no safety layer"]
    print(f"figure (b), stack without recorder, {duration:g} s of sim, median of {reps}:")
    for name, wall in walls.items():
        print(
            f"  {name:<30} wall {wall:6.3f} s   RTF {duration / wall:5.0f}x   "
            f"ratio {wall / base:5.2f}   CPU {cpus[name]:6.3f} s ratio {cpus[name] / cpu_base:5.2f}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--duration", type=float, default=30.0)
    parser.add_argument("--skip-b", action="store_true", help="only the step times")
    args = parser.parse_args()
    step_times()
    if not args.skip_b:
        bench_b(args.duration, args.reps)


if __name__ == "__main__":
    main()
