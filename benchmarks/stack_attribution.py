"""Where the stack's time goes beyond the bare loop, per stage, in CPU microseconds per
simulated second (ADR 0058): what stands between (b), (c) and the targets over (a).

The same runs as ``otonav bench`` (otonav.bench._harness: the acceptance world, 30 s of
sim by default, goal from the scenario), each in a fresh process, interleaved, medians
of ``--reps``. Inside each run, CPU time (``time.thread_time``) is charged to:

- **shared work**, what (a) calls too: the physics step (``advance``), the HAL's reads
  and its wheel write, the navigator's ``Navigation.step``/``observe`` and the pure
  nav/control functions (scan points, safety check, odometry, limits, kinematics);
  only the outermost of nested calls counts;
- in (b) and (c), **each actor's own code**: every step of its task (its ``run``
  coroutine, and the bridge's command task) less the shared work inside it; what a
  publisher's delivery costs (mailboxes, the recorder's funnel) is its publisher's;
- the recorder's **funnel offers** (in its publishers' steps) and its **chunk zstd** (in
  its drains), each taken out of the step it runs in (ADR 0064);
- **the loop**: the rest (the virtual-time loop's passes, timers and wake-ups, task
  switches, the bare loop's own glue in (a)).

Timing adds ~0.3 us per wrapped call, to every stage alike; read the differences
between (a), (b) and (c), and the shares.

    python benchmarks/stack_attribution.py [--reps 5] [--duration 30]
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import statistics
import sys
import time
from collections import defaultdict
from collections.abc import Callable, Generator
from pathlib import Path
from typing import Any

_clock = time.thread_time
_acc: defaultdict[str, float] = defaultdict(float)
_shared_total = [0.0]
_depth = [0]


def _shared(name: str, func: Callable[..., Any]) -> Callable[..., Any]:
    def timed(*args: Any, **kwargs: Any) -> Any:
        if _depth[0]:
            return func(*args, **kwargs)
        _depth[0] = 1
        start = _clock()
        try:
            return func(*args, **kwargs)
        finally:
            spent = _clock() - start
            _acc[name] += spent
            _shared_total[0] += spent
            _depth[0] = 0

    return timed


class _TimedSteps:
    """A coroutine's steps, each charged to ``name`` less the shared work inside it."""

    def __init__(self, coro: Any, name: str) -> None:
        self._coro, self._name = coro, name

    def __await__(self) -> Generator[Any, Any, Any]:
        return self

    def __iter__(self) -> _TimedSteps:
        return self

    def __next__(self) -> Any:
        return self.send(None)

    def _step(self, step: Callable[[], Any]) -> Any:
        start, shared = _clock(), _shared_total[0]
        try:
            return step()
        finally:
            _acc[self._name] += (_clock() - start) - (_shared_total[0] - shared)

    def send(self, value: Any) -> Any:
        return self._step(lambda: self._coro.send(value))

    def throw(self, *exc: Any) -> Any:
        return self._step(lambda: self._coro.throw(*exc))

    def close(self) -> None:
        self._coro.close()


def _timed_method(cls: type, method: str, name: str) -> None:
    original = getattr(cls, method)

    async def wrapper(self: Any, *args: Any, **kwargs: Any) -> Any:
        # A coroutine function still (anyio's start_soon insists on one).
        return await _TimedSteps(original(self, *args, **kwargs), name)

    setattr(cls, method, wrapper)


def _instrument() -> None:
    import otonav.actors._bridge as bridge
    import otonav.control._kinematics as kinematics
    import otonav.control._odometry as odometry
    import otonav.nav._navigate as navigate
    import otonav.nav._safety as safety
    import otonav.nav._scan as scan
    from otonav.actors._avoiding_navigator import AvoidingNavigator
    from otonav.actors._base_controller import BaseController
    from otonav.actors._recorder import Recorder
    from otonav.actors._safety_layer import SafetyLayer
    from otonav.hal.mujoco._world import MujocoInterface

    for method, stage in (
        ("advance", "physics (advance)"),
        ("read_wheels", "HAL reads + write"),
        ("wheel_values", "HAL reads + write"),
        ("read_imu", "HAL reads + write"),
        ("read_scan", "lidar (read_scan)"),
        ("write", "HAL reads + write"),
    ):
        setattr(MujocoInterface, method, _shared(stage, getattr(MujocoInterface, method)))
    for method in ("step", "observe"):
        cls = navigate.Navigation
        setattr(cls, method, _shared("nav/safety/control math", getattr(cls, method)))
    functions = {
        id(f): f
        for f in (
            scan.scan_points,
            scan.scan_in_frame,
            scan.to_frame,
            scan.nearest_return,
            safety.safe_command,
            safety.stopping_reach,
            kinematics.integrate_odometry,
            kinematics.limit_twist,
            kinematics.twist_to_wheels,
            odometry.estimate_odometry,
        )
    }
    wrapped: dict[int, Callable[..., Any]] = {}
    for module in list(sys.modules.values()):
        if not getattr(module, "__name__", "").startswith("otonav"):
            continue
        for attr, value in list(vars(module).items()):
            if id(value) in functions and callable(value):
                key = id(value)
                if key not in wrapped:
                    wrapped[key] = _shared("nav/safety/control math", functions[key])
                setattr(module, attr, wrapped[key])
    _timed_method(bridge.Bridge, "run", "actor: bridge (publishing)")
    # A /wheel_cmd is applied in the base's publish (ADR 0084): the bridge's callback,
    # the HAL write inside it included, out of the base's step.
    bridge.Bridge._apply_command = _shared(  # type: ignore[method-assign]
        "actor: bridge (wheel commands)", bridge.Bridge._apply_command
    )
    _timed_method(AvoidingNavigator, "run", "actor: navigator")
    _timed_method(SafetyLayer, "run", "actor: safety layer")
    _timed_method(BaseController, "run", "actor: base controller")
    _timed_method(Recorder, "run", "actor: recorder (drains)")
    # The recorder's own work outside its drains' Python, charged apart (ADR 0064): the
    # funnel's offers (inside the publishers' steps) and the chunks' zstd (inside the
    # drains); each is taken out of the stage it runs in.
    import zstandard

    from otonav.runtime._funnel import _Tap

    for method in ("_offer", "_offer_all"):
        setattr(_Tap, method, _shared("recorder: funnel offers", getattr(_Tap, method)))
    zstandard.compress = _shared("recorder: chunk zstd", zstandard.compress)


def _one(kind: str, duration: float) -> dict[str, float]:
    from otonav.bench._harness import Case, run_case

    _instrument()
    run_case(Case(kind, 2.0))  # warm: lazy imports, first-use compilation
    _acc.clear()
    start = _clock()
    sample = run_case(Case(kind, duration))
    total = _clock() - start
    known = sum(_acc.values())
    figures = dict(_acc)
    figures["the loop (rest)"] = total - known
    figures["total"] = total
    return {k: v / sample.sim_s * 1e6 for k, v in figures.items()}  # us per sim s


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--duration", type=float, default=30.0)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    kinds = ("bare", "stack", "recorded")
    cases = [(k, args.duration) for _ in range(args.reps) for k in kinds]
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(1, maxtasksperchild=1) as pool:
        results = pool.starmap(_one, cases, chunksize=1)
    table: dict[str, dict[str, float]] = {}
    for kind in kinds:
        runs = [r for (k, _), r in zip(cases, results, strict=True) if k == kind]
        stages = sorted({s for r in runs for s in r})
        table[kind] = {s: statistics.median(r.get(s, 0.0) for r in runs) for s in stages}
    order = sorted(
        {s for t in table.values() for s in t if s != "total"},
        key=lambda s: -table["recorded"].get(s, 0.0),
    )
    print(
        f"CPU us per simulated second, median of {args.reps} runs of {args.duration:g} s "
        "(one process each, interleaved)"
    )
    print(f"{'stage':<34}{'(a) bare':>10}{'(b) stack':>11}{'(c) +rec':>10}{'b-a':>8}{'c-a':>8}")
    for stage in [*order, "total"]:
        a, b, c = (table[k].get(stage, 0.0) for k in kinds)
        print(f"{stage:<34}{a:>10.0f}{b:>11.0f}{c:>10.0f}{b - a:>8.0f}{c - a:>8.0f}")
    a_total = table["bare"]["total"]
    print(
        f"ratios of these totals: (b)/(a) = {table['stack']['total'] / a_total:.2f}, "
        f"(c)/(a) = {table['recorded']['total'] / a_total:.2f}"
    )
    if args.json:
        args.json.write_text(json.dumps(table, indent=2) + "\n")


if __name__ == "__main__":
    main()
