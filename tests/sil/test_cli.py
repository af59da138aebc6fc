"""The CLI end to end: exit codes, summary.json, artifacts, info and plot."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from otonav.cli import main

pytestmark = pytest.mark.sil

SUMMARY_KEYS = {
    "passed", "reached", "time_to_goal_s", "min_clearance_m", "path_length_m",
    "sim_time_s", "wall_time_s", "rtf",
}  # fmt: skip


def test_run_passes_with_exit_0_and_writes_the_artifacts(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    assert main(["run", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr()
    assert "PASSED" in out.out
    assert "\r" not in out.err  # not a terminal: no progress line
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert set(summary) >= SUMMARY_KEYS
    assert summary["passed"] is True
    assert summary["time_to_goal_s"] <= 20.0
    assert summary["min_clearance_m"] >= 0.3
    # The run goes on 2 s after first entering the tolerance: the arrival check.
    assert summary["sim_time_s"] == pytest.approx(summary["time_to_goal_s"] + 2.0, abs=0.02)
    assert (tmp_path / "recording.mcap").stat().st_size > 100_000
    assert (tmp_path / "trajectory.png").stat().st_size > 10_000

    assert main(["info", str(tmp_path / "recording.mcap")]) == 0
    info = capsys.readouterr().out
    for topic in ("/odom", "/scan", "/tf", "/rosout", "/scenario/verdict"):
        assert topic in info
    assert "sensor_msgs/msg/LaserScan" in info

    png = tmp_path / "replot.png"
    assert main(["plot", str(tmp_path / "recording.mcap"), "--out", str(png)]) == 0
    assert png.stat().st_size > 10_000


def test_a_failing_scenario_exits_1_and_says_why(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    assert (
        main(
            [
                "run",
                "--out",
                str(tmp_path),
                "--set",
                "nav.kp_lin=0",
                "--set",
                "nav.planner=stop",
                "--no-record",
            ]
        )
        == 1
    )
    out = capsys.readouterr().out
    assert "FAILED" in out
    assert "did not reach the goal within 20 s" in out
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["passed"] is False
    assert summary["reached"] is False
    assert not (tmp_path / "recording.mcap").exists()


def test_no_arguments_runs_the_default_scenario(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main([]) == 0
    assert "acceptance" in capsys.readouterr().out
    assert (tmp_path / "out" / "summary.json").exists()
