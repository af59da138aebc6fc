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
    assert main(["bench", "--quick", "--clutter", "--json", str(figures)]) == 0
    out = capsys.readouterr().out
    for label in (
        "(a0) bare loop, old law",
        "(a) bare loop",
        "(b) stack, no recorder",
        "(c) stack + recorder",
        "ratios (CPU)",
        "fixed cost of a run",
        "acceptance scenario",
        "clutter curve",
        "in this session: (b)/(a) =",
    ):
        assert label in out
    data = json.loads(figures.read_text())
    assert [row["label"] for row in data["rows"]] == [
        "(a0) bare loop, old law",
        "(a) bare loop",
        "(b) stack, no recorder",
        "(c) stack + recorder",
    ]
    assert all(row["duration_s"] == 2.0 and row["wall_median_s"] > 0 for row in data["rows"])
    assert data["ratio_c_over_a"] > 0
    assert data["cpu_ratio_c_over_a0"] > 0
    assert all(row["cpu_median_s"] > 0 for row in data["rows"])
    fixed = data["fixed_cost"]
    assert set(fixed["phases_ms"]) >= {"world build", "actor stop", "finish file + close world"}
    # The phases are laps of one stopwatch: together they are the whole fixed run.
    walls = [v for k, v in fixed["phases_ms"].items() if "CPU" not in k and "first" not in k]
    assert abs(sum(walls) - fixed["total_ms"]) < 0.05 * fixed["total_ms"] + 0.5
    # The scenario ran to its verdict (the acceptance goal is reached before 30 s).
    assert 0 < data["acceptance_scenario"]["sim_s"] < 30
    # The clutter curve's quick form: no boxes and 100, each run to its verdict.
    curve = data["clutter"]["rows"]
    assert [row["boxes"] for row in curve] == [0, 100]
    assert curve[0]["rtf_vs_none"] == 1.0
    assert all(row["rtf"] > 0 and row["plot_s"] > 0 for row in curve)


def test_memory_probe_reads_rss_heap_and_file_at_each_checkpoint() -> None:
    from otonav.bench._memory import long_run

    points = long_run(3.0, 1.0, trace=True)
    assert [round(p.sim_s, 6) for p in points] == [1.0, 2.0, 3.0]
    assert all(p.rss_mb > 10 and p.heap_mb > 0 for p in points)
    # The recording is written as it goes (chunks flushed), so the file grows.
    assert points[-1].recorded_mb > points[0].recorded_mb


@pytest.mark.parametrize("value", ["0", "-5", "nan", "1e9"])
def test_bench_long_rejects_a_bad_duration_in_one_line(
    value: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["bench", "--long", value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "--long must be in (0, 86400]" in err[0]
