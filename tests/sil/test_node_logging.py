"""A node logs as an rclpy node does (issue 39 item 1): ``self.log`` lines reach the
console as they happen (warnings and errors; everything with ``-v``) and /rosout in the
recording, where ``otonav echo`` reads them; a node that raises in run() shows the
frames of its own code."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from otonav.actors import topics
from otonav.cli import main
from otonav.record._reader import read_messages

pytestmark = pytest.mark.sil

NODES = Path(__file__).resolve().parents[1] / "data" / "user_nodes" / "log_nodes.py"


@pytest.mark.timeout(120)
def test_a_nodes_log_lines_reach_the_console_and_rosout(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    assert main(["run", "--actor", f"{NODES}:Talker", "--out", str(tmp_path)]) == 0
    err = capsys.readouterr().err.splitlines()
    assert "[WARN] [1.000] [talker]: battery low: 12 %" in err
    assert "[ERROR] [2.000] [talker]: lost the drive" in err
    assert not [line for line in err if "starting" in line or "detail" in line]  # no -v

    recording = tmp_path / "recording.mcap"
    lines = [
        (t, m.level, m.msg, m.function)
        for _topic, t, m in read_messages(recording, [topics.ROSOUT])
        if m.name == "talker" and m.file == str(NODES)
    ]
    assert lines == [
        (0.0, 20, "starting, warning at 1.0 s", "run"),
        (1.0, 30, "battery low: 12 %", "run"),
        (2.0, 40, "lost the drive", "run"),
    ]  # INFO and up recorded, stamped in sim time; debug is not

    assert main(["echo", "/rosout", str(recording), "--field", "msg", "--since", "0.5"]) == 0
    out = capsys.readouterr().out
    assert "'battery low: 12 %'\n---\n" in out  # YAML quotes a ': '
    assert "lost the drive\n---\n" in out
    assert "starting" not in out  # before --since
    assert main(["echo", "rosout", str(recording), "--once"]) == 0  # relative, as ROS 2
    first = capsys.readouterr().out
    assert first.startswith("stamp:\n  sec: 0\n  nanosec: 0\nlevel: 20\n")
    assert first.count("---") == 1


@pytest.mark.timeout(120)
def test_verbose_prints_every_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    argv = ["run", "-v", "--actor", f"{NODES}:Talker", "--out", str(tmp_path)]
    assert main([*argv, "--set", "actors.talker.at=0.5"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert "[INFO] [0.000] [talker]: starting, warning at 0.5 s" in err
    assert "[DEBUG] [0.500] [talker]: a detail only -v shows" in err


@pytest.mark.timeout(120)
def test_a_node_that_raises_shows_its_own_frames(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    assert main(["run", "--actor", f"{NODES}:Crasher", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert "crasher crashed: ValueError: node exploded" in err
    assert f'File "{NODES}", line' in err
    assert "in _helper" in err
    assert 'raise ValueError("node exploded")' in err
    assert "otonav/runtime" not in err  # the framework's frames stay on /rosout
    assert (tmp_path / "summary.json").exists()


@pytest.mark.timeout(120)
def test_echo_refuses_an_unknown_topic_in_one_line(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    assert main(["run", "--out", str(tmp_path)]) == 0
    cli_fails(["echo", "/nope", str(tmp_path / "recording.mcap")], "no topic '/nope'", "/rosout")
    cli_fails(["echo", "/rosout", str(tmp_path / "recording.mcap"), "--field", "level.x"],
              "--field level.x: no field 'x'")  # fmt: skip


@pytest.mark.timeout(300)
def test_a_sweeps_workers_keep_node_lines_off_its_console(
    capfd: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """In a worker process Python's last-resort handler printed each run's warnings bare
    ("battery low: 12 %", no run, no node): they stay on /rosout of the kept runs."""
    argv = ["sweep", "--scenario", "acceptance", "--workers", "1", "--out", str(tmp_path)]
    assert main([*argv, "--actor", f"{NODES}:Talker", "--keep", "none"]) == 0
    err = capfd.readouterr().err
    assert "battery low" not in err
    assert "lost the drive" not in err
