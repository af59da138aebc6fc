"""BARN in the gate (issue 42): ten of its 300 worlds (0, 30, ..., 270), converted by
benchmarks/barn/convert.py, run with otonav's default robot in virtual time and judged
as BARN judges them: the first entry into the 1 m goal circle within 100 s, no contact
(the centre never nearer a cylinder than the footprint radius), no ``unreachable``
(every BARN world has a path). The cylinders are measured, not skipped: the clearance
is finite. The full 300 are a benchmark (benchmarks/barn_bench.py)."""

from __future__ import annotations

import math
from types import ModuleType

import pytest
from benchmark_module import load_benchmark

from otonav.stack import StackConfig

pytestmark = pytest.mark.sil


def _bench() -> ModuleType:
    return load_benchmark("barn_bench.py")


def test_the_converted_worlds_are_barn_s() -> None:
    """300 worlds; world 0 as BARN's Gazebo file has it: 209 cylinders on the 0.15 m
    grid inside a 4.5 m wide corridor closed behind the start, its optimal path 13.59 m."""
    worlds = _bench().load_worlds()
    assert sorted(worlds) == list(range(300))
    w0 = worlds[0]
    assert len(w0.cylinders) == 209
    assert w0.optimal_path_m == pytest.approx(13.5923)
    assert (-0.075, 0.075) in w0.cylinders
    assert (-4.425, 9.525) in w0.cylinders
    assert all(-4.5 < x < 0.0 and 0.0 < y < 9.6 for x, y in w0.cylinders)


@pytest.mark.parametrize("index", range(0, 300, 30))
def test_barn_world(index: int) -> None:
    bench = _bench()
    run = bench.run_world(bench.load_worlds()[index], StackConfig())
    assert run.success, run
    assert not run.collision, run
    assert not run.false_unreachable, run
    assert math.isfinite(run.min_clearance_m)
    assert run.min_clearance_m >= run.footprint_radius_m
    assert 0.0 < run.metric <= 0.5
