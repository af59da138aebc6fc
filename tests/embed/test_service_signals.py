"""Ctrl-C on the example service while heavy simulations run, a client waits on one
and another streams poses (issue 17, item 4): it exits promptly and cleanly, and every
recording, the live one included, is finished and indexed; pressing Ctrl-C again
during the shutdown does not cut it short."""

from __future__ import annotations

import selectors
import signal
import subprocess
import sys
import threading
from pathlib import Path
from typing import Any

import httpx
import pytest
from children import terminal_signals

from otonav.record._reader import summarize

pytestmark = pytest.mark.smoke

APP = Path(__file__).resolve().parents[2] / "examples" / "service" / "app.py"
HEAVY: dict[str, Any] = {  # never reaches its 1 mm tolerance: runs until cancelled
    "name": "heavy",
    "scene": "empty",
    "goal": {"x": 3.0, "y": -1.0},
    "goal_tolerance": 0.001,
    "sim_budget": 600.0,
}


def _address(process: subprocess.Popen[str]) -> str:
    assert process.stdout is not None
    with selectors.DefaultSelector() as selector:
        selector.register(process.stdout, selectors.EVENT_READ)
        assert selector.select(30), "the service printed no address"
    return process.stdout.readline().split()[-1]


def _hold(url: str, path: str, answered: threading.Event) -> None:
    """A client holding a request open (a long wait, a pose stream) until the end."""
    try:
        with httpx.stream("GET", url + path, timeout=60) as response:
            answered.set()
            for _line in response.iter_lines():
                pass
    except httpx.HTTPError:
        answered.set()


@pytest.mark.timeout(120)
def test_ctrl_c_twice_during_heavy_runs_exits_cleanly_with_every_recording_indexed(
    tmp_path: Path,
) -> None:
    process = subprocess.Popen(
        [sys.executable, str(APP), "--port", "0", "--out", str(tmp_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
        preexec_fn=terminal_signals,
    )
    try:
        url = _address(process)
        with httpx.Client(base_url=url, timeout=30) as client:
            assert client.get("/health").json()["live"] == "running"
            runs = [client.post("/runs", json={"scenario": HEAVY}).json()["id"] for _ in range(2)]
            for run_id in runs:  # each ask waits up to 50 ms server-side
                while client.get(f"/runs/{run_id}", params={"wait": 0.05}).json()["sim_time_s"] in (
                    None,
                    0.0,
                ):
                    pass
            streaming, waiting = threading.Event(), threading.Event()
            holders = [
                threading.Thread(target=_hold, args=(url, f"/runs/{runs[0]}?wait=60", waiting)),
                threading.Thread(target=_hold, args=(url, "/live/pose?hz=5", streaming)),
            ]
            for holder in holders:
                holder.start()
            assert streaming.wait(30), "the pose stream never answered"
        process.send_signal(signal.SIGINT)
        process.send_signal(signal.SIGINT)  # impatient: again, during the shutdown
        _out, err = process.communicate(timeout=60)  # a hang detector, not a timing
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    for holder in holders:
        holder.join(timeout=30)
    assert process.returncode == 130, err
    assert "Traceback" not in err, err
    live = summarize(tmp_path / "live.mcap")
    assert not live.truncated, "the live recording must be finished and indexed"
    assert live.message_count > 0
    for run_id in runs:
        recording = summarize(tmp_path / "runs" / run_id / "recording.mcap")
        assert not recording.truncated


@pytest.mark.parametrize(
    ("flag", "value"), [("--live-scale", "1e308"), ("--live-scale", "0"), ("--max-runs", "0")]
)
def test_service_options_beyond_what_it_can_honour_are_one_line_and_exit_2(
    tmp_path: Path, flag: str, value: str
) -> None:
    done = subprocess.run(
        [sys.executable, str(APP), "--port", "0", "--out", str(tmp_path), flag, value],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith(f"otonav: error: {flag} ")
