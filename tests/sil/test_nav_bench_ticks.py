"""The navigation benchmark times the planner, not the process's garbage (issue 24,
ADR 0059): the ~40 ms "planner tick" it printed once per family was a full collection
of earlier runs' worlds (a run's objects are cyclic garbage) landing inside a navigator
tick of a later run. Each benchmark process now frees a run before the next."""

from __future__ import annotations

import gc
import sys
from types import ModuleType

import pytest
from benchmark_module import load_benchmark

pytestmark = pytest.mark.sil


def _bench() -> ModuleType:
    return load_benchmark("nav_bench.py")


def test_no_run_leaves_its_world_for_a_later_runs_ticks() -> None:
    """Two short generated worlds in this process as a benchmark worker runs them: after
    each, no object of a per-run type is alive (this test collects nothing itself), so
    no later tick can absorb its collection; and the ticks were timed."""
    from otonav.runtime._loop import VirtualTimeLoop
    from otonav.runtime._system import System
    from otonav.stack._session import StackSession

    per_run = (StackSession, System, VirtualTimeLoop)

    def alive() -> list[str]:
        return [type(o).__name__ for o in gc.get_objects() if isinstance(o, per_run)]

    bench = _bench()
    gc.collect()
    before = len(alive())
    bench._start_process()  # freezes what exists: hidden from alive()
    try:
        for seed in (2, 3):  # dense, reachable, 11-20 s of sim each
            run = bench.run_one(("dense", seed, False, ()))
            assert run.result.passed, run.result.reason
            assert len(run.ticks_ms) > 100
            assert alive() == []
    finally:
        gc.unfreeze()  # this process is pytest's, not a benchmark worker's
        sys.modules.pop("nav_bench_under_test", None)
    assert len(alive()) == before
