"""Endings of paced runs, from the CLI (issue 41, cases 10 and 16).

- 10: an actor crash under ``--realtime`` or ``--ros2`` gave an ExceptionGroup traceback
  (4 blocks) and no ``summary.json``; in virtual time it is one line, the summary, the
  recording, rc 1. Now every mode ends it that way.
- 16: the out directory deleted during a ``--realtime`` run gave rc 0 and printed the
  path of a recording that did not exist (a plot and a summary were written into a
  directory made anew). Now it is an error: one line, nothing pretending to be the run.

The crash and the deletion are done by a user's node at 0.5 s of sim time."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from otonav.record._reader import summarize

pytestmark = pytest.mark.smoke

HERE = Path(__file__).resolve().parent
CEILING_S = 120.0
MODES = {
    "virtual": [],
    "realtime": ["--realtime", "--scale", "10"],
    "ros2": ["--ros2", "--scale", "10", "--ros2-domain", "197"],
}


def _run(out: Path, actor: str, mode: list[str]) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "OTONAV_TEST_OUT": str(out)}
    env["PYTHONPATH"] = os.pathsep.join([str(HERE), env.get("PYTHONPATH", "")])
    argv = ["run", "--scenario", "empty", "--out", str(out), "--actor", f"ending_actors:{actor}"]
    return subprocess.run(
        [sys.executable, "-m", "otonav", *argv, *mode],
        env=env,
        capture_output=True,
        text=True,
        timeout=CEILING_S,
        cwd=out.parent,
    )


@pytest.mark.parametrize("mode", sorted(MODES))
def test_an_actor_crash_ends_every_mode_as_a_failed_run(tmp_path: Path, mode: str) -> None:
    out = tmp_path / "out"
    done = _run(out, "Crashes", MODES[mode])
    assert done.returncode == 1, done.stderr
    # One line says it crashed; a crash in the user's own node then shows the user's own
    # frames (issue 39), never Python's whole traceback or an ExceptionGroup (issue 41).
    assert "Traceback (most recent call last)" not in done.stderr, done.stderr
    assert "ExceptionGroup" not in done.stderr, done.stderr
    assert "ending_actors.py" in done.stderr, done.stderr
    said = [line for line in done.stderr.splitlines() if "crashed" in line]
    assert len(said) == 1, done.stderr
    assert "crashes crashed: RuntimeError: boom at half a second" in said[0], said
    summary = json.loads((out / "summary.json").read_text())
    assert summary["passed"] is False
    assert "boom at half a second" in summary["reason"]
    recorded = summarize(out / "recording.mcap")
    assert recorded.truncated is False
    assert recorded.end_ns / 1e9 >= 0.5


def test_an_out_directory_deleted_during_a_realtime_run_is_an_error(tmp_path: Path) -> None:
    out = tmp_path / "out"
    done = _run(out, "DeletesTheOut", MODES["realtime"])
    assert done.returncode == 2, (done.stdout, done.stderr)
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("otonav: error: "), line
    assert "recording.mcap" in line
    assert "deleted while the run wrote it" in line
    assert f"recording: {out}" not in done.stdout  # no path of a file that is not there
    assert not (out / "summary.json").exists()
    assert not (out / "trajectory.png").exists()
