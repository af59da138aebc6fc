"""The report's figures: Wilson intervals against published values, percentiles against
numpy, failure grouping, and reading a results file a kill cut mid-line."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from otonav.sweep._results import ResultsFile, latest_by_run, read_results
from otonav.sweep._stats import (
    failures_by_reason,
    override_rates,
    pass_rate,
    percentile,
    reason_class,
    wilson,
)

pytestmark = pytest.mark.unit


@pytest.mark.parametrize(
    ("k", "n", "low", "high"),
    [
        # Newcombe (1998), Table I, method 3 (Wilson score without continuity correction)
        (81, 263, 0.2553, 0.3662),
        (15, 148, 0.0624, 0.1605),
        (0, 20, 0.0, 0.1611),
        (1, 29, 0.0061, 0.1718),
    ],
)
def test_wilson_matches_published_intervals(k: int, n: int, low: float, high: float) -> None:
    lo, hi = wilson(k, n)
    assert lo == pytest.approx(low, abs=5e-5)
    assert hi == pytest.approx(high, abs=5e-5)


@given(st.integers(1, 2000).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n))))
def test_wilson_interval_holds_the_point_estimate(kn: tuple[int, int]) -> None:
    k, n = kn
    lo, hi = wilson(k, n)
    assert 0.0 <= lo <= k / n <= hi <= 1.0


@given(st.lists(st.floats(-1e6, 1e6), min_size=1, max_size=50), st.floats(0, 100))
def test_percentile_is_numpys_linear_method(values: list[float], q: float) -> None:
    assert percentile(values, q) == pytest.approx(float(np.percentile(values, q)), abs=1e-6)


def _rec(status: str, reason: str = "", **extra: Any) -> dict[str, Any]:
    return {"status": status, "reason": reason, "overrides": {}, **extra}


def test_errors_count_as_not_passed_and_reasons_group_without_numbers() -> None:
    records = [
        _rec("passed", overrides={"nav.max_v": 0.3}),
        _rec("failed", "did not reach the goal within 20 s (ended 0.41 m away; tolerance 0.15 m)"),
        _rec("failed", "did not reach the goal within 20 s (ended 1.2 m away; tolerance 0.15 m)"),
        _rec("failed", "came 0.210 m from an obstacle (minimum 0.3 m)"),
        _rec("error", "worker died (killed by SIGKILL) during this run"),
    ]
    rate = pass_rate(records)
    assert (rate.passed, rate.runs, rate.errors) == (1, 5, 1)
    assert rate.rate == pytest.approx(0.2)
    groups = failures_by_reason(records)
    assert list(groups) == [
        "did not reach the goal within # s",
        "came # m from an obstacle",
        "error: worker died during this run",
    ]
    assert len(groups["did not reach the goal within # s"]) == 2
    assert reason_class("a (x); b 2.5e-3 m") == "a; b # m"
    assert reason_class(
        "did not reach the goal within 20 s (ended 2.1 m away); "
        "recoveries: spin at 3.1 s (blocked); backup at 7.5 s (stuck)"
    ) == "did not reach the goal within # s"  # fmt: skip
    assert override_rates(records)["nav.max_v"]["0.3"].passed == 1


def test_a_line_cut_by_a_kill_is_skipped_and_the_next_append_starts_clean(
    tmp_path: Path,
) -> None:
    path = tmp_path / "results.jsonl"
    path.write_text(json.dumps({"run_id": "a", "status": "passed"}) + '\n{"run_id": "b", "sta')
    assert [r["run_id"] for r in read_results(path)] == ["a"]
    results = ResultsFile(path)
    results.append({"run_id": "b", "status": "error"})
    results.append({"run_id": "b", "status": "passed"})
    results.close()
    records = read_results(path)
    assert [r["run_id"] for r in records] == ["a", "b", "b"]
    assert latest_by_run(records)["b"]["status"] == "passed"
