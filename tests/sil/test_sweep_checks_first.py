"""Sweeps that check first and report in the runs' own words (issue 29): every scenario
validated before the first run, --resume from the stored plan, unmasked reasons."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.cli import main

pytestmark = pytest.mark.sil

BAD = """name: bad
scene: empty
goal: {x: 2.0, y: 0.0}
obstacles:
  - {x: 2.0, y: 0.0, size_x: 0.4, size_y: 0.4}
"""
SHORT = """name: short
scene: empty
goal: {x: 3.0, y: 0.0}
sim_budget: 0.5
"""


def test_a_bad_scenario_stops_the_sweep_before_any_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "bad.yaml").write_text(BAD)
    (tmp_path / "sweep.yaml").write_text("name: s\nscenarios: [empty, bad.yaml]\nseeds: [0, 1]\n")
    out = tmp_path / "out"
    assert main(["sweep", str(tmp_path / "sweep.yaml"), "--out", str(out)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err[0] == (
        f"otonav: error: {tmp_path / 'bad.yaml'}: goal: (2, 0) is inside the obstacle at "
        "(2, 0); it needs at least min_clearance = 0.3 m from every obstacle and wall"
    )
    assert "nothing was run" in err[1]
    assert not (out / "results.jsonl").exists()


def test_resume_takes_the_stored_plan_and_refuses_other_arguments(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "short.yaml").write_text(SHORT)
    out = tmp_path / "out"
    args = ["--scenario", str(tmp_path / "short.yaml"), "--seeds", "2"]
    assert main(["sweep", *args, "--out", str(out)]) == 1  # both runs fail: 0.5 s budget
    printed = capsys.readouterr().out
    # the runs' own words, numbers included (the group key masks them)
    assert "did not reach the goal within 0.5 s" in printed
    assert "(and 1 more like it)" in printed
    lines = (out / "results.jsonl").read_text().splitlines()
    assert main(["sweep", "--resume", "--out", str(out)]) == 1  # the stored plan: nothing left
    assert (out / "results.jsonl").read_text().splitlines() == lines
    assert main(["sweep", "--resume", "--out", str(out), *args[:2], "--seeds", "3"]) == 2
    err = capsys.readouterr().err
    assert "--seeds (stored 2, given 3)" in err
    assert err.count("\n") == 1
