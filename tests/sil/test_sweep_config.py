"""``otonav sweep``'s quick form takes ``--config`` as ``otonav run`` does (issue 39 item
10): a user's own robot or nodes no longer need a sweep file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from otonav.cli import main

pytestmark = pytest.mark.sil


@pytest.mark.timeout(300)
def test_the_quick_form_runs_every_scenario_on_the_given_stack(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    stack = tmp_path / "stack.yaml"  # the navigator's commands go nowhere: nothing moves
    stack.write_text("actors:\n  - {name: nav, remap: {/cmd_vel_nav: /cmd_vel_unheard}}\n")
    out = tmp_path / "sweep"
    argv = ["sweep", "--scenario", "acceptance", "--config", str(stack), "--out", str(out)]
    assert main([*argv, "--backend", "inline", "--keep", "none"]) == 1
    capsys.readouterr()
    (record,) = [json.loads(line) for line in (out / "results.jsonl").read_text().splitlines()]
    assert record["status"] == "failed"  # with the built-in stack the scenario passes
    assert json.loads((out / "sweep.json").read_text())["spec"]["config"] == str(stack)
    assert main(["sweep", "--resume", "--out", str(out)]) == 1  # the plan kept its config
