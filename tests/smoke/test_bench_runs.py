"""The benchmark runs (quick mode): it must not rot. It checks that it runs and reports,
never how fast anything is."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from otonav.cli import main

pytestmark = pytest.mark.smoke


def test_bench_quick_mode_runs_and_writes_its_figures(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    figures = tmp_path / "bench.json"
    assert main(["bench", "--quick", "--json", str(figures)]) == 0
    out = capsys.readouterr().out
    for label in (
        "(a) bare loop",
        "(b) stack, no recorder",
        "(c) stack + recorder",
        "ratios (CPU)",
        "fixed cost of a run",
        "acceptance scenario",
    ):
        assert label in out
    data = json.loads(figures.read_text())
    assert [row["label"] for row in data["rows"]] == [
        "(a) bare loop",
        "(b) stack, no recorder",
        "(c) stack + recorder",
    ]
    assert all(row["duration_s"] == 2.0 and row["wall_median_s"] > 0 for row in data["rows"])
    assert data["ratio_c_over_a"] > 0
    assert all(row["cpu_median_s"] > 0 for row in data["rows"])
    fixed = data["fixed_cost"]
    assert set(fixed["phases_ms"]) >= {"world build", "actor stop", "finish file + close world"}
    # The phases are laps of one stopwatch: together they are the whole fixed run.
    walls = [v for k, v in fixed["phases_ms"].items() if "CPU" not in k and "first" not in k]
    assert abs(sum(walls) - fixed["total_ms"]) < 0.05 * fixed["total_ms"] + 0.5
    # The scenario ran to its verdict (the acceptance goal is reached before 30 s).
    assert 0 < data["acceptance_scenario"]["sim_s"] < 30
