"""Every user mistake gets one line naming the file or flag, the key path and what is
valid, exit code 2, and no traceback."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from otonav.cli import main

pytestmark = pytest.mark.unit


def _write(path: Path, text: str) -> str:
    path.write_text(text)
    return str(path)


def test_missing_scenario_file(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    cli_fails(["run", "--scenario", str(tmp_path / "nope.yaml")], "nope.yaml", "no such file")


def test_unknown_builtin_scenario_lists_the_valid_ones(cli_fails: Callable[..., str]) -> None:
    cli_fails(["run", "--scenario", "acceptence"], "acceptence", "acceptance", "empty")


def test_invalid_yaml_names_file_and_line(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    f = _write(tmp_path / "s.yaml", "goal: [1\n")
    cli_fails(["run", "--scenario", f], f, "invalid YAML at line 2")


def test_unknown_key(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    f = _write(tmp_path / "s.yaml", "goal: {x: 1, y: 2}\ngoal_tolerence: 0.2\n")
    cli_fails(["run", "--scenario", f], f, "goal_tolerence: unknown key")


def test_wrong_type(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    f = _write(tmp_path / "s.yaml", "sim_budget: soon\n")
    cli_fails(["run", "--scenario", f], "sim_budget", "valid number", "'soon'")


@pytest.mark.parametrize(
    ("text", "key"),
    [("goal_tolerance: 0\n", "goal_tolerance"), ("goal_tolerance: -0.1\n", "goal_tolerance")],
)
def test_tolerance_must_be_positive(
    cli_fails: Callable[..., str], tmp_path: Path, text: str, key: str
) -> None:
    f = _write(tmp_path / "s.yaml", text)
    cli_fails(["run", "--scenario", f], f, key, "greater than 0")


def test_negative_rate_in_the_stack_config(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    f = _write(tmp_path / "stack.yaml", "rates:\n  scan_hz: -10\n")
    cli_fails(["run", "--config", f], f, "rates.scan_hz", "greater than 0", "-10")


def test_set_override_errors(cli_fails: Callable[..., str]) -> None:
    cli_fails(["run", "--set", "nav.kp_lin=fast"], "--set", "nav.kp_lin", "valid number")
    cli_fails(["run", "--set", "nav.kpl=1"], "nav.kpl", "unknown key", "kp_lin")
    cli_fails(["run", "--set", "kp_lin"], "expected key.path=value")
    # Strict numbers: YAML's "yes" is a boolean, not a gain of 1.0.
    cli_fails(["run", "--set", "nav.kp_lin=yes"], "nav.kp_lin", "valid number")


def test_goal_inside_an_obstacle(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    f = _write(tmp_path / "s.yaml", "goal: {x: 2.0, y: 0.05}\n")
    cli_fails(["run", "--scenario", f, "--out", str(tmp_path)], f, "goal", "inside the obstacle")


def test_goal_outside_the_arena(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    f = _write(tmp_path / "s.yaml", "goal: {x: 12, y: 0}\n")
    cli_fails(
        ["run", "--scenario", f, "--out", str(tmp_path)],
        "outside the arena",
        "x in (-5, 5)",
    )


def test_start_inside_an_obstacle(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    f = _write(tmp_path / "s.yaml", "start: {x: 1.5, y: 1.4}\n")
    cli_fails(["run", "--scenario", f, "--out", str(tmp_path)], f, "start", "inside the obstacle")


def test_invalid_mjcf(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    xml = _write(
        tmp_path / "bad.xml", "<mujoco><worldbody><geom type='blob'/></worldbody></mujoco>"
    )
    f = _write(tmp_path / "s.yaml", f"scene: {xml}\n")
    cli_fails(["run", "--scenario", f, "--out", str(tmp_path)], "bad.xml", "does not parse")


def test_info_on_missing_and_non_mcap_files(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    cli_fails(["info", str(tmp_path / "none.mcap")], "none.mcap", "no such file")
    f = _write(tmp_path / "x.mcap", "not a recording")
    cli_fails(["info", f], "x.mcap", "not an MCAP file")


def test_unknown_command_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["fly"])
    assert exit_info.value.code == 2
    assert "invalid choice: 'fly'" in capsys.readouterr().err


def test_gui_without_a_display_is_one_line_and_exit_2(
    cli_fails: Callable[..., str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    cli_fails(["run", "--gui", "--out", str(tmp_path)], "no display", "xvfb-run")


def test_realtime_scale_must_be_positive(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    cli_fails(["run", "--realtime", "--scale", "0", "--out", str(tmp_path)], "--scale")


def test_info_on_a_cut_off_recording_warns_and_still_shows_it(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    from otonav.msgs import Clock, Time
    from otonav.record._writer import RecordingWriter

    path = tmp_path / "cut.mcap"
    writer = RecordingWriter(path, chunk_size=1024)
    for i in range(500):
        writer.write("/clock", Clock(clock=Time.from_seconds(i * 0.01)), i * 0.01)
    writer._file.close()  # the process "dies" here: no finish(), no footer
    cut = path.read_bytes()
    path.write_bytes(cut[: len(cut) - 100])  # and the last chunk was half written
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr()
    assert "was cut off" in out.err
    assert "otonav salvage" in out.err
    assert "/clock" in out.out
