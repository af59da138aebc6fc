"""Off a terminal (a pipe, a log, CI) the CLI never hard-wraps its lines."""

from __future__ import annotations

import pytest

from otonav.cli import main
from otonav.cli._console import make_console


def test_a_long_line_stays_one_line_off_a_terminal(capsys: pytest.CaptureFixture[str]) -> None:
    text = "recording: /" + "/".join(["a-rather-long-folder-name"] * 8) + "/recording.mcap"
    make_console().print(text)
    assert capsys.readouterr().out == text + "\n"


def test_graph_rows_are_not_wrapped_in_a_pipe_and_name_ros_types(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["graph"]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if "nav_msgs/msg/Odometry" in line)
    assert "bridge (reliable/depth=10/volatile)" in row  # as diff_drive_controller offers
    assert "nav (best_effort/depth=5/volatile)" in row  # the next column, on the same line
