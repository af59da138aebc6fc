"""A user's node that cannot be built or wired is the user's mistake (issue 39 item 3,
issue 41 cases 11-13): one line naming it and the fix, exit 2, in run, graph and sweep
alike, and nothing run. They were 30-line tracebacks with exit 1."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

PROBES = Path(__file__).resolve().parents[2] / "data" / "user_nodes" / "probe_nodes.py"

CASES = {
    "ScanAsTwist": ("scan_as_twist.scan", "Twist", "LaserScan"),
    "ReliableScan": ("reliable_scan.scan", "reliable", "best_effort"),
    "RaisesInInit": ("actors.raises_in_init", "RuntimeError: no device /dev/ttyUSB0"),
}


@pytest.mark.parametrize("command", ["run", "graph", "sweep"])
@pytest.mark.parametrize("node", list(CASES))
def test_a_node_that_cannot_start_is_one_line_and_exit_2(
    cli_fails: Callable[..., str], tmp_path: Path, command: str, node: str
) -> None:
    argv = [command, "--actor", f"{PROBES}:{node}"]
    if command == "run":
        argv += ["--out", str(tmp_path / "out")]
    if command == "sweep":
        argv += ["--scenario", "acceptance", "--seeds", "1", "--out", str(tmp_path / "sweep")]
    line = cli_fails(argv, *CASES[node])
    assert line.count("otonav: error:") == 1
    assert not (tmp_path / "sweep" / "results.jsonl").exists()  # nothing was run


@pytest.mark.parametrize("command", ["run", "graph", "sweep"])
def test_an_actor_spec_with_no_module_is_one_line(
    cli_fails: Callable[..., str], command: str
) -> None:
    scenario = ["--scenario", "acceptance"] if command == "sweep" else []
    cli_fails([command, "--actor", ":X", *scenario], "--actor ':X'", "module:Class")
