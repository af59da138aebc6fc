"""A run never leaves the previous run's verdict next to its own artifacts: an
interrupted run (Ctrl-C, SIGTERM) leaves no summary.json at all, so a CI script that
reads it cannot see a stale PASS; bad input deletes nothing."""

from __future__ import annotations

import json
import os
import pty
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from children import terminal_signals

from otonav.cli import main
from otonav.record._reader import summarize

pytestmark = pytest.mark.sil

STALE = {"scenario": "acceptance", "passed": True, "reached": True}


def _stale_out(out: Path) -> Path:
    out.mkdir()
    (out / "summary.json").write_text(json.dumps(STALE))
    (out / "recording.mcap").write_bytes(b"the previous run's recording")
    return out


@pytest.mark.timeout(120)
@pytest.mark.parametrize(("sig", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_an_interrupted_run_leaves_no_summary(
    tmp_path: Path, sig: signal.Signals, code: int
) -> None:
    out = _stale_out(tmp_path / "out")
    scenario = tmp_path / "long.yaml"
    scenario.write_text("name: long\nsim_budget: 1800.0\n")  # the longest allowed
    # stderr on a pseudo-terminal: the progress line says when the run is under way.
    terminal, child_side = pty.openpty()
    argv = ["run", "--scenario", str(scenario), "--set", "nav.kp_lin=0", "--out", str(out)]
    proc = subprocess.Popen(
        [sys.executable, "-m", "otonav", *argv],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=child_side,
        preexec_fn=terminal_signals,
    )
    os.close(child_side)
    try:
        seen = b""
        while b"to goal" not in seen:  # blocks on the child's output, not on a clock
            seen += os.read(terminal, 4096)
        proc.send_signal(sig)
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
        os.close(terminal)
    assert proc.returncode == code
    assert not (out / "summary.json").exists(), "the previous run's summary survived"
    assert not summarize(out / "recording.mcap").truncated  # this run's, finished


def test_no_record_removes_the_previous_recording(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = _stale_out(tmp_path / "out")
    assert main(["run", "--scenario", "empty", "--no-record", "--out", str(out)]) == 0
    assert json.loads((out / "summary.json").read_text())["scenario"] == "empty"
    assert not (out / "recording.mcap").exists(), "a stale recording beside a new summary"


def test_bad_input_deletes_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = _stale_out(tmp_path / "out")
    assert main(["run", "--set", "nav.kp_lin=fast", "--out", str(out)]) == 2
    far = tmp_path / "far.yaml"
    far.write_text("goal: {x: 40.0, y: 0.0}\n")  # outside the arena: found once built
    assert main(["run", "--scenario", str(far), "--no-record", "--out", str(out)]) == 2
    assert json.loads((out / "summary.json").read_text()) == STALE
    assert (out / "recording.mcap").read_bytes() == b"the previous run's recording"
