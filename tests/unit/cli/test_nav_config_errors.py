"""Planner, footprint, safety and recovery settings are validated like the rest: a bad
value is one line naming the key and what is valid, exit 2."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit


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
    cli_fails: Callable[..., str], assignment: str, fragments: tuple[str, ...]
) -> None:
    cli_fails(["run", "--set", assignment], "--set", *fragments)


def test_bad_value_in_a_stack_file(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    f = tmp_path / "stack.yaml"
    f.write_text("safety:\n  drive_lag: -1\n")
    cli_fails(["run", "--config", str(f)], str(f), "safety.drive_lag", "-1")
