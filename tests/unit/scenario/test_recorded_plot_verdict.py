"""A plot drawn from a recording that holds a verdict tells it, as `otonav run` does:
the scenario, PASSED or FAILED, why, and the closest approach."""

from __future__ import annotations

from pathlib import Path

from otonav.scenario import ScenarioConfig, run_scenario
from otonav.scenario._replay import recorded_plot
from otonav.scenario._verdict import verdict_title


def test_a_recorded_verdict_titles_the_plot(tmp_path: Path) -> None:
    scenario = ScenarioConfig.model_validate(
        {"name": "short", "scene": "empty", "goal": {"x": 3.0, "y": 0.0}, "sim_budget": 1.0}
    )
    verdict = run_scenario(scenario, out_dir=tmp_path, plot=False)
    assert not verdict.passed
    plot = recorded_plot(tmp_path / "recording.mcap")
    assert plot.title.splitlines()[0] == "short: FAILED"
    assert "did not reach the goal within 1 s" in plot.title
    assert plot.closest is not None
    assert list(plot.closest) == verdict.closest_xy


def test_a_long_reason_is_wrapped_onto_two_lines_at_most() -> None:
    title = verdict_title("s", True, "word " * 60)
    lines = title.splitlines()
    assert lines[0] == "s: PASSED"
    assert len(lines) == 3
    assert all(len(line) <= 64 for line in lines[1:])
    assert lines[-1].endswith("…")
