"""Bad YAML that used to pass silently (issue 27, item 9): a key given twice (the last
one won), an empty scenario file (the defaults ran)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit


def test_a_duplicate_key_is_refused_naming_both_lines(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    f = tmp_path / "s.yaml"
    f.write_text("goal: {x: 1, y: 2}\nsim_budget: 5\ngoal: {x: 3, y: 1}\n")
    cli_fails(["run", "--scenario", str(f)], str(f), "'goal' is given twice (line 1 and line 3)")


def test_a_duplicate_nested_key_in_a_stack_config_is_refused(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    f = tmp_path / "stack.yaml"
    f.write_text("nav:\n  kp_lin: 1.0\n  kp_lin: 0.0\n")
    cli_fails(["run", "--config", str(f)], str(f), "'kp_lin' is given twice")


@pytest.mark.parametrize("text", ["", "# only a comment\n", "{}\n"])
def test_an_empty_scenario_file_is_refused(
    cli_fails: Callable[..., str], tmp_path: Path, text: str
) -> None:
    f = tmp_path / "s.yaml"
    f.write_text(text)
    cli_fails(["run", "--scenario", str(f), "--out", str(tmp_path / "out")], str(f), "empty")
    assert not (tmp_path / "out").exists()


def test_merge_keys_may_still_be_overridden() -> None:
    from otonav.stack import _safe_yaml as safe_yaml

    data = safe_yaml.load("base: &b {x: 1, y: 2}\ngoal:\n  <<: *b\n  x: 3\n")
    assert data["goal"] == {"x": 3, "y": 2}
