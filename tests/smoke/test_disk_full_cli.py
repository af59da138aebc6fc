"""Layer 2: a full disk through the CLI (issue 27 item 5), refused by the kernel itself.

No root is needed: the child process gets ``RLIMIT_FSIZE`` (``ulimit -f``) with SIGXFSZ
ignored, so a write past the limit fails with ``EFBIG`` exactly where a full file system
fails with ``ENOSPC`` (both are a full disk to otonav). A real full tmpfs gave the same
(ADR 0052 has the commands); it needs a mount, which a test cannot count on."""

from __future__ import annotations

import resource
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from otonav.record._diskfull import DISK_FULL_EXIT
from otonav.record._reader import read_messages

pytestmark = pytest.mark.smoke


def _otonav(*args: str, limit: int) -> subprocess.CompletedProcess[str]:
    def fsize_limit() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG instead of a kill
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return subprocess.run(
        [sys.executable, "-m", "otonav", *args],
        capture_output=True,
        text=True,
        timeout=300,  # a hang guard only
        preexec_fn=fsize_limit,
        check=False,
    )


def test_a_run_onto_a_full_disk_stops_with_one_line_exit_4_and_keeps_the_recording(
    tmp_path: Path,
) -> None:
    out = tmp_path / "out"
    done = _otonav("run", "--out", str(out), limit=200_000)
    recording = out / "recording.mcap"
    lines = done.stderr.strip().splitlines()
    assert done.returncode == DISK_FULL_EXIT, done.stderr
    assert len(lines) == 1, done.stderr
    line = lines[0]
    assert line.startswith(f"otonav: error: {recording}: file too large; "), line
    assert "the run was stopped at sim time " in line
    assert f"'otonav salvage {recording} OTHER_DISK/recording.mcap'" in line
    assert "Traceback" not in done.stderr
    # What was written is kept and readable; nothing half-written passes for a result.
    assert 0 < recording.stat().st_size <= 200_000
    clock = [t for _topic, t, _m in read_messages(recording, ["/clock"])]
    assert len(clock) > 100
    stopped = float(line.split("sim time ")[1].split(" s")[0])
    assert clock[-1] <= stopped + 1e-9
    assert not (out / "summary.json").exists()
    assert not (out / "trajectory.png").exists()


def test_salvage_onto_a_full_disk_names_the_target_and_removes_it(tmp_path: Path) -> None:
    source = tmp_path / "cut.mcap"
    done = _otonav("run", "--out", str(tmp_path / "run"), limit=300_000)
    assert done.returncode == DISK_FULL_EXIT, done.stderr
    (tmp_path / "run" / "recording.mcap").rename(source)
    target = tmp_path / "fixed.mcap"
    done = _otonav("salvage", str(source), str(target), limit=50_000)
    assert done.returncode == DISK_FULL_EXIT, done.stderr
    assert done.stderr.strip().splitlines() == [
        f"otonav: error: {target}: file too large; the partial copy was removed: free some "
        "space or salvage to another disk"
    ]
    assert not target.exists()
    # With room, the same command works (no leftover to --force past).
    done = _otonav("salvage", str(source), str(target), limit=10_000_000)
    assert done.returncode == 0, done.stderr
    assert target.exists()
