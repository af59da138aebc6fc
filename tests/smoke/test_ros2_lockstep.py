"""Lockstep with no node answering (issue 37): the run fails with one line naming the topic
and the instant, exit 1, and keeps its recording, indexed. No rclpy needed: nobody
answers at all (tests/sil/test_ros2_nodes.py runs real nodes)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from dds_domain import exclusive_domain

from otonav.record._reader import read_messages, summarize

pytestmark = pytest.mark.smoke


@pytest.mark.timeout(120)
def test_a_node_that_never_answers_fails_the_run_with_one_line_and_its_recording(
    tmp_path: Path,
) -> None:
    out = tmp_path / "out"
    with exclusive_domain() as domain:
        env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CYCLONEDDS"))}
        env["ROS_DOMAIN_ID"] = str(domain)
        argv = [
            sys.executable, "-m", "otonav", "run", "--ros2", "--ros2-in", "/cmd_vel_nav",
            "--lockstep", "/cmd_vel_nav:0.05", "--ros2-wait", "0.2",
            "--set", "ros2.lockstep_timeout=0.3", "--set", "nav.planner=external",
            "--out", str(out),
        ]  # fmt: skip
        done = subprocess.run(
            argv,
            env=env,
            capture_output=True,
            text=True,
            timeout=100,
        )
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert lines[0].startswith("ros2: ")
    assert "in lockstep" in lines[0]
    (why,) = [line for line in lines[1:] if "lockstep" in line]
    assert "no ROS 2 node answered on /cmd_vel_nav within 0.3 s" in why
    assert "of /clock 0.050 s" in why
    assert len(lines) <= 3, done.stderr  # the ros2 line, the crash, at most a warning
    summary = json.loads((out / "summary.json").read_text())
    assert not summary["passed"]
    recording = out / "recording.mcap"
    assert not summarize(recording).truncated
    clocks = [t for _topic, t, _m in read_messages(recording, ["/clock"])]
    assert clocks[-1] == pytest.approx(0.05)  # sim time held at the unanswered instant
