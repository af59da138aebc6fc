"""report.md leads with the worst run, its figures against the limits and its repro."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from otonav.sweep._report import summarize, worst_case, write_report


def record(run_id: str, status: str, clearance: float | None, **more: Any) -> dict[str, Any]:
    return {
        "run_id": run_id, "scenario": "box", "seed": 0, "family": "box", "overrides": {},
        "status": status, "reason": f"{status} reason", "min_clearance_m": clearance,
        "clearance_floor_m": 0.3, "time_to_goal_s": 10.0, "sim_budget_s": 80.0,
        "repro": f"otonav run --scenario box --seed 0 # {run_id}", "artifacts": None,
        "sim_time_s": 12.0, "wall_time_s": 0.5, **more,
    }  # fmt: skip


def test_a_failed_run_is_worse_than_any_pass() -> None:
    records = [record("a", "passed", 0.31), record("b", "failed", 0.9), record("c", "passed", 2)]
    lines = worst_case(records)
    assert lines[0] == "## Worst case"
    assert "run `b`" in lines[2]
    assert "**failed**" in lines[2]
    assert lines[3] == "- min clearance 0.900 m (floor 0.3 m); time to goal 10.000 s (budget 80 s)"
    assert lines[4].endswith("# b`")


def test_among_passes_the_closest_to_the_floor_is_worst() -> None:
    records = [record("a", "passed", 0.5), record("b", "passed", 0.31), record("c", "passed", 2)]
    assert "run `b`" in worst_case(records)[2]


def test_the_report_opens_with_the_worst_case(tmp_path: Path) -> None:
    records = [record("a", "passed", 0.5, overrides={"nav.max_v": 0.2}),
               record("b", "passed", 0.4, overrides={"nav.max_v": 0.4})]  # fmt: skip
    report = write_report(
        tmp_path, summarize(records, planned=2, name="worst"), records
    ).read_text()
    assert report.index("## Worst case") < report.index("| group |")
    assert "nav.max_v=0.4" in report.split("## Worst case")[1].split("\n\n")[1]
    assert (tmp_path / "pass_fail.png").stat().st_size > 1000
    assert (tmp_path / "histograms.png").stat().st_size > 1000
