"""What a CLI user expects without reading the README: --version, a help that says what
no command does and what the exit codes mean, the built-in scenarios named where they
are chosen, and no silently ignored flag."""

from __future__ import annotations

from importlib.metadata import version
from pathlib import Path

import pytest

from otonav.cli import main
from otonav.scenario._builtin import BUILTIN

pytestmark = pytest.mark.unit


def _exits(argv: list[str]) -> int:
    with pytest.raises(SystemExit) as stop:
        main(argv)
    code = stop.value.code
    assert isinstance(code, int)
    return code


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    assert _exits(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"otonav {version('otonav')}"


def test_help_says_no_command_means_run_and_lists_the_exit_codes(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert _exits(["--help"]) == 0
    out = capsys.readouterr().out
    assert "With no command, otonav runs `run`" in out
    for code, meaning in (
        ("0", "passed"),
        ("1", "scenario failed"),
        ("2", "usage or configuration error"),
        ("130/143", "Ctrl-C / SIGTERM"),
    ):
        assert any(line.split()[:1] == [code] and meaning in line for line in out.splitlines()), (
            f"exit code {code} ({meaning}) is not listed:\n{out}"
        )


def test_scenario_help_names_every_builtin(capsys: pytest.CaptureFixture[str]) -> None:
    assert _exits(["run", "--help"]) == 0
    out = " ".join(capsys.readouterr().out.split())  # argparse wraps lines
    for name in BUILTIN:
        assert name in out.split("--scenario NAME|PATH", 2)[-1], f"{name} missing:\n{out}"


@pytest.mark.parametrize("extra", [[], ["--no-record"]])
def test_scale_without_realtime_or_gui_is_a_usage_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, extra: list[str]
) -> None:
    code = main(["run", "--scale", "5", "--out", str(tmp_path), *extra])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.strip() == (
        "otonav: error: --scale 5: only with --realtime, --gui or --ros2 "
        "(a headless run is not paced: it runs as fast as it can)"
    )
    assert not list(tmp_path.iterdir()), "a refused run must not write anything"


def test_hold_without_gui_is_a_usage_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    assert main(["run", "--hold", "--realtime", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.strip() == "otonav: error: --hold: only with --gui (it keeps the viewer window open)"
    assert not list(tmp_path.iterdir())
