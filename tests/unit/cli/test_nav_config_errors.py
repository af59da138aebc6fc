"""Planner, footprint, safety and recovery settings are validated like the rest: a bad
value is one line naming the key and what is valid, exit 2."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.cli import main

pytestmark = pytest.mark.unit


def _fails(capsys: pytest.CaptureFixture[str], argv: list[str], *fragments: str) -> None:
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    for fragment in fragments:
        assert fragment in lines[0], lines[0]


@pytest.mark.parametrize(
    ("assignment", "fragments"),
    [
        ("nav.planner=astar", ("nav.planner", "'stop', 'dwa' or 'external'")),
        ("nav.dwa.horizon=-1", ("nav.dwa.horizon", "greater than 0")),
        ("nav.dwa.v_samples=0", ("nav.dwa.v_samples", "greater than or equal to 1")),
        ("nav.dwa.w_clearance=-0.5", ("nav.dwa.w_clearance", "greater than or equal to 0")),
        ("nav.map.resolution=0.5", ("nav.map.resolution", "less than or equal to 0.2")),
        ("nav.recovery.progress_window=0", ("nav.recovery.progress_window", "greater than 0")),
        ("nav.footprint_padding=-0.1", ("nav.footprint_padding", "greater than or equal to 0")),
        ("safety.clearance=0", ("safety.clearance", "greater than 0")),
        ("safety.rate_hz=0.5", ("safety.rate_hz", "greater than or equal to 1")),
        ("safety.enabled=maybe", ("safety.enabled", "valid boolean")),
        ("nav.clearance=0.2", ("nav.clearance", "safety.clearance")),
        ("nav.dwa.horizon=0.1", ("nav.dwa.dt", "nav.dwa.horizon")),
    ],
)
def test_bad_nav_and_safety_values(
    capsys: pytest.CaptureFixture[str], assignment: str, fragments: tuple[str, ...]
) -> None:
    _fails(capsys, ["run", "--set", assignment], "--set", *fragments)


def test_bad_value_in_a_stack_file(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    f = tmp_path / "stack.yaml"
    f.write_text("safety:\n  drive_lag: -1\n")
    _fails(capsys, ["run", "--config", str(f)], str(f), "safety.drive_lag", "-1")
