"""Scoring generated-world runs: what counts as a success, a timeout, a violation, and
the BARN metric per family."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import pytest
from benchmark_module import load_benchmark
from hypothesis import given, settings
from hypothesis import strategies as st

from otonav.scenario._generator import SPARSE, WALLED_IN, generate_world

pytestmark = pytest.mark.unit

NAV_BENCH = load_benchmark("nav_bench.py")  # the scoring is benchmarks/nav_bench.py's
RunResult = NAV_BENCH.RunResult
summarise = NAV_BENCH.summarise
barn_metric = NAV_BENCH.barn_metric

WORLD = generate_world(1, SPARSE)
WALLED = generate_world(1, WALLED_IN)
OPT = WORLD.optimal_time_s or 0.0


def _run(**kw: object) -> Any:
    base = RunResult.of(
        "sparse",
        WORLD,
        passed=True,
        reached=True,
        time_to_goal_s=3 * OPT,
        min_clearance_m=0.4,
        unreachable_at_s=None,
        sim_time_s=3 * OPT,
        final_distance_m=0.1,
        wall_time_s=1.0,
        reason="reached the goal with clearance",
    )
    return replace(base, **kw)


def _walled(**kw: object) -> Any:
    base = RunResult.of(
        "sparse",
        WALLED,
        passed=True,
        reached=False,
        time_to_goal_s=None,
        min_clearance_m=0.4,
        unreachable_at_s=20.0,
        sim_time_s=20.0,
        final_distance_m=3.0,
        wall_time_s=1.0,
        reason="reported unreachable",
    )
    return replace(base, **kw)


def test_a_family_row_counts_each_outcome_once() -> None:
    results = [
        _run(),  # success at 3 x optimal: BARN 1/3
        _run(time_to_goal_s=OPT),  # success at optimal: BARN clipped to 0.5
        _run(passed=False, reached=False, time_to_goal_s=None),  # timeout
        _run(passed=False, reached=False, time_to_goal_s=None, unreachable_at_s=5.0),
        _run(passed=False, min_clearance_m=0.25),  # reached, but too close
        _walled(),  # reported
        _walled(passed=False, unreachable_at_s=None),  # walled-in timeout
        _walled(passed=False, min_clearance_m=0.1),  # reported, but too close
    ]
    row = summarise("sparse", results)
    assert row.worlds == 5
    assert row.reachable == 5
    assert row.successes == 2
    assert row.success_pct == pytest.approx(40.0)
    assert row.barn_metric == pytest.approx((1 / 3 + 0.5) / 5)
    assert row.time_ratio_median == pytest.approx((3 + 1) / 2)
    assert row.timeouts == 1
    assert row.gave_up == 1
    assert row.clearance_violations == 2
    assert row.runs == 8
    assert row.walled == 3
    assert row.walled_reported == 2
    assert row.walled_timeouts == 1
    assert [r.failure for r in results] == [
        None,
        None,
        "timeout",
        "gave up (false unreachable)",
        "clearance",
        None,
        "walled-in timeout",
        "clearance",
    ]


def test_an_empty_family_has_no_percentages() -> None:
    row = summarise("dense", [])
    assert row.success_pct is None
    assert row.barn_metric is None
    assert row.time_ratio_median is None
    assert row.walled_reported_pct is None


def test_unreachable_said_after_the_budget_is_a_timeout() -> None:
    late = _walled(passed=False, unreachable_at_s=WALLED.scenario.sim_budget + 1.0)
    assert late.timed_out
    assert summarise("sparse", [late]).walled_reported == 0


@settings(deadline=None)
@given(optimal=st.floats(0.1, 100.0), factor=st.floats(0.0, 20.0))
def test_barn_metric_is_clipped_between_an_eighth_and_a_half(optimal: float, factor: float) -> None:
    score = barn_metric(True, factor * optimal, optimal)
    assert 1 / 8 - 1e-12 <= score <= 0.5 + 1e-12
    if factor <= 2.0:
        assert score == pytest.approx(0.5)
    elif factor >= 8.0:
        assert score == pytest.approx(1 / 8)
    else:
        assert score == pytest.approx(1 / factor)
    assert barn_metric(False, factor * optimal, optimal) == 0.0
