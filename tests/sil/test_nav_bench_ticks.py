"""The navigation benchmark times the planner, not the process's garbage (issue 24,
ADR 0059): the ~40 ms "planner tick" it printed once per family was a full collection
of earlier runs' worlds (a run's objects are cyclic garbage) landing inside a navigator
tick of a later run. Each benchmark process now frees a run before the next."""

from __future__ import annotations

import gc
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import pytest

pytestmark = pytest.mark.sil

BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "nav_bench.py"


def _bench() -> ModuleType:
    spec = importlib.util.spec_from_file_location("nav_bench_under_test", BENCH)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def test_no_run_leaves_its_world_for_a_later_runs_ticks() -> None:
    """Two short generated worlds in this process as a benchmark worker runs them: after
    each, no object of a per-run type is alive (this test collects nothing itself), so
    no later tick can absorb its collection; and the ticks were timed."""
    from otonav.runtime.loop import VirtualTimeLoop
    from otonav.runtime.system import System
    from otonav.stack.session import StackSession

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
