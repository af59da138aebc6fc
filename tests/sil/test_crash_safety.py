"""The recording survives an actor exception, Ctrl-C and SIGTERM as an indexed file with
every message up to the stop; after SIGKILL at most the last chunk is lost and salvage
rewrites the rest as an indexed file. Real processes, real signals."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest
from children import terminal_signals

from otonav.record._reader import read_messages, summarize
from otonav.record._salvage import salvage

pytestmark = pytest.mark.sil

CHILD = Path(__file__).with_name("crash_child.py")
READY_AT = 30.0
CLOCK_HZ = 100


def _start(out: Path, mode: str) -> subprocess.Popen[str]:
    proc = subprocess.Popen(
        [sys.executable, str(CHILD), str(out), mode],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=terminal_signals,
    )
    assert proc.stdout is not None
    line = proc.stdout.readline()  # blocks until the child reached 30 s of sim time
    assert line.strip() == "ready", proc.stderr.read() if proc.stderr else line
    return proc


def _clock_times(recording: Path) -> list[float]:
    return [t for _topic, t, _m in read_messages(recording, ["/clock"])]


def _assert_complete_up_to_the_stop(recording: Path) -> float:
    summary = summarize(recording)
    assert not summary.truncated, "the file must be finished and indexed"
    clocks = _clock_times(recording)
    last = clocks[-1]
    assert last >= READY_AT
    # Every /clock tick from the start to the stop is there: nothing lost at the end.
    assert len(clocks) == round(last * CLOCK_HZ)
    return last


@pytest.mark.timeout(120)
def test_actor_exception_leaves_an_indexed_file_with_the_crash_logged(tmp_path: Path) -> None:
    proc = _start(tmp_path, "raise")
    _out, err = proc.communicate(timeout=60)
    assert proc.returncode != 0
    assert "RunCrashedError" in err  # an ActorCrashedError that carries the verdict
    assert "injected fault" in err
    recording = tmp_path / "recording.mcap"
    last = _assert_complete_up_to_the_stop(recording)
    assert last == pytest.approx(READY_AT, abs=0.02)
    logs = [m for _t, _s, m in read_messages(recording, ["/rosout"])]
    assert any(m.name == "marker" and "injected fault" in m.msg and m.level == 40 for m in logs)
    verdicts = [m for _t, _s, m in read_messages(recording, ["/scenario/verdict"])]
    assert len(verdicts) == 1
    assert not verdicts[0].passed
    assert "ActorCrashedError" in verdicts[0].reason


@pytest.mark.timeout(120)
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["sigint", "sigterm"])
def test_ctrl_c_and_sigterm_leave_an_indexed_file(tmp_path: Path, sig: signal.Signals) -> None:
    proc = _start(tmp_path, "wait")
    proc.send_signal(sig)
    proc.communicate(timeout=60)
    assert proc.returncode != 0
    _assert_complete_up_to_the_stop(tmp_path / "recording.mcap")


@pytest.mark.timeout(120)
def test_sigkill_loses_at_most_the_last_chunk_and_salvage_recovers_the_rest(
    tmp_path: Path,
) -> None:
    proc = _start(tmp_path, "wait")
    proc.kill()
    proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    cut = tmp_path / "recording.mcap"
    summary = summarize(cut)
    assert summary.truncated
    fixed = tmp_path / "salvaged.mcap"
    count = salvage(cut, fixed)
    assert count == summary.message_count > 0
    clocks = _clock_times(fixed)
    assert not summarize(fixed).truncated
    # Contiguous from the start; a 64 KiB chunk holds under 2 s of this stack's traffic.
    assert len(clocks) == round(clocks[-1] * CLOCK_HZ)
    assert clocks[-1] >= READY_AT - 2.0
