"""Test-suite configuration: pytester for testing the otonav pytest plugin itself, the
one check every bad-input test makes (`cli_fails`), and the seeds' pitch bug as a robot
(`sabotaged_robot`, `sabotaged_robot_config`: tests/sabotage.py)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from sabotage import sabotaged_robot as _sabotaged_robot
from sabotage import sabotaged_robot_config as _sabotaged_robot_config

from otonav.hal._description import RobotDescription
from otonav.stack._config import RobotConfig

pytest_plugins = ["pytester"]

CliFails = Callable[..., str]
"""``cli_fails(argv, *fragments) -> the error line``."""


@pytest.fixture
def cli_fails(capsys: pytest.CaptureFixture[str]) -> CliFails:
    """Run ``otonav`` with ``argv`` and check it refused as a user's mistake must be refused:
    exit 2, one short line on stderr that starts ``otonav: error:`` and holds every
    fragment (the file or key and what is valid), no traceback. Returns the line."""
    from otonav.cli import main

    def fails(argv: list[str], *fragments: str) -> str:
        code = main(argv)
        err = capsys.readouterr().err
        assert code == 2, err
        assert "Traceback" not in err
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        line = lines[0]
        assert line.startswith("otonav: error: "), line
        assert len(line) < 600, line[:600]
        for fragment in fragments:
            assert fragment in line, line
        return line

    return fails


@pytest.fixture
def sabotaged_robot(tmp_path: Path) -> RobotDescription:
    """otonav's robot without its caster, drives kv 10 with no torque limit."""
    return _sabotaged_robot(tmp_path)


@pytest.fixture
def sabotaged_robot_config(tmp_path: Path) -> RobotConfig:
    """The same robot as a stack config's ``robot`` section."""
    return _sabotaged_robot_config(tmp_path)
