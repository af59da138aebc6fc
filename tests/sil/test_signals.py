"""Ctrl-C and SIGTERM at the worst moments give a clean exit: one or two lines, the
exit code of the signal, the recording indexed and the plot drawn (issue 17, item 5).
Real processes; each signals itself at a deterministic point (signal_child.py)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from children import terminal_signals

from otonav.record._reader import read_messages, summarize

pytestmark = pytest.mark.sil

CHILD = Path(__file__).with_name("signal_child.py")


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, str(CHILD), *args],
        capture_output=True,
        text=True,
        timeout=90,
        preexec_fn=terminal_signals,
    )


@pytest.mark.timeout(120)
@pytest.mark.parametrize(
    ("first", "second", "code"),
    # A single signal to the CLI is covered by test_cli_stale_artifacts.py; these are the
    # cases that failed: a second Ctrl-C inside the loop (a traceback), a second Ctrl-C or
    # SIGTERM while plotting (no plot; SIGTERM killed the process).
    [("INT", "cancel", 130), ("INT", "plot", 130), ("TERM", "plot", 143)],
)
def test_a_second_signal_during_shutdown_still_exits_cleanly(
    tmp_path: Path, first: str, second: str, code: int
) -> None:
    done = _run(str(tmp_path), first, second)
    assert done.returncode == code, done.stderr
    assert "Traceback" not in done.stderr
    assert len(done.stderr.strip().splitlines()) <= 2, done.stderr
    recording = tmp_path / "recording.mcap"
    assert not summarize(recording).truncated, "the recording must be finished and indexed"
    clocks = [t for _topic, t, _m in read_messages(recording, ["/clock"])]
    assert clocks[-1] >= 0.5
    assert (tmp_path / "trajectory.png").stat().st_size > 0, "the plot must be drawn"
    assert not (tmp_path / "summary.json").exists(), "an interrupted run has no summary"


@pytest.mark.timeout(60)
def test_ctrl_c_during_import_is_one_line_and_exit_130(tmp_path: Path) -> None:
    done = _run("--import")
    assert done.returncode == 130, done.stderr
    assert "Traceback" not in done.stderr
    assert done.stderr.strip() == "otonav: interrupted"
