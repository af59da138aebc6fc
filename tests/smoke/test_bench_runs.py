"""The benchmark runs (quick mode): it must not rot. It checks that it runs and reports,
never how fast anything is."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from otonav.cli import main

pytestmark = pytest.mark.smoke


def test_bench_quick_mode_runs_and_writes_its_figures(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    figures = tmp_path / "bench.json"
    assert main(["bench", "--quick", "--json", str(figures)]) == 0
    out = capsys.readouterr().out
    for label in ("(a) bare loop", "(b) stack, no recorder", "(c) stack + recorder", "ratios"):
        assert label in out
    data = json.loads(figures.read_text())
    assert [row["label"] for row in data["rows"]] == [
        "(a) bare loop",
        "(b) stack, no recorder",
        "(c) stack + recorder",
    ]
    assert all(row["duration_s"] == 2.0 and row["wall_median_s"] > 0 for row in data["rows"])
    assert data["ratio_c_over_a"] > 0
