"""Lockstep's bad input (issue 37): one line, exit 2, before anything runs or is written."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CliFails

pytestmark = pytest.mark.unit


@pytest.mark.parametrize(
    ("argv", "fragments"),
    [
        (["--lockstep", "/cmd_vel_nav:0.05"], ["--lockstep: only with --ros2"]),
        (["--ros2-wait", "5"], ["--ros2-wait: only with --ros2"]),
        (
            ["--ros2", "--lockstep", "/cmd_vel_nav:0.05"],
            ["ros2.lockstep /cmd_vel_nav: not an input", "--ros2-in /cmd_vel_nav", "/goal"],
        ),
        (
            ["--ros2", "--ros2-in", "/cmd_vel_nav", "--lockstep", "/cmd_vel_nav:fast"],
            ["--lockstep /cmd_vel_nav:fast", "TOPIC:PERIOD", "/cmd_vel_nav:0.05"],
        ),
        (
            ["--ros2", "--ros2-in", "/cmd_vel_nav", "--lockstep", "/cmd_vel_nav:0"],
            ["--lockstep", "period", "0"],
        ),
        (
            ["--ros2", "--ros2-in", "/cmd_vel_nav", "--lockstep", "cmd_vel_nav:0.05"],
            ["--lockstep", "topic"],
        ),
        (["--ros2", "--lockstep"], ["--lockstep: say what your nodes answer with"]),
        (
            [
                "--ros2",
                "--realtime",
                "--ros2-in",
                "/cmd_vel_nav",
                "--lockstep",
                "/cmd_vel_nav:0.05",
            ],
            ["--lockstep: not with --realtime"],
        ),
        (["--ros2", "--ros2-wait", "0"], ["--ros2-wait", "wait"]),
    ],
)
def test_lockstep_misuse_is_one_line_and_exit_2(
    cli_fails: CliFails, tmp_path: Path, argv: list[str], fragments: list[str]
) -> None:
    out = tmp_path / "out"
    cli_fails(["run", *argv, "--out", str(out)], *fragments)
    assert not out.exists() or not any(out.iterdir())
