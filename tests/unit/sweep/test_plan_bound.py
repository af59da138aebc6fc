"""A sweep plan's size is bounded (issue 27 item 2): ``seeds: {count: 100000000}``
reached 4.4 GB in 24 s with no output. Now the plan is counted before it is expanded and
refused past ``otonav.limits.MAX_SWEEP_RUNS``: one line, exit 2, nothing written."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from otonav import limits
from otonav.stack._files import ConfigFileError
from otonav.sweep._plan import plan_runs
from otonav.sweep._spec import GenerateSource, GenerateSpec, SeedRange, SweepSpec

pytestmark = pytest.mark.unit


def test_a_plan_one_past_the_bound_is_refused_before_it_is_expanded(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(limits, "MAX_SWEEP_RUNS", 1000)
    spec = SweepSpec(
        scenarios=("acceptance", GenerateSource(generate=GenerateSpec(count=10))),
        overrides={"nav.max_v": (0.3, 0.5, 0.7), "guard.stop_distance": (0.4,)},
        seeds=SeedRange(count=31),  # (1 + 10) x 3 x 31 = 1023
    )
    with pytest.raises(ConfigFileError, match=r"1,023 runs .* 11 x 3 x 31\), more than 1,000"):
        plan_runs(spec, where="s.yaml")
    assert len(plan_runs(spec.model_copy(update={"seeds": SeedRange(count=30)}))) == 990


def test_a_hundred_million_seeds_is_one_line_exit_2(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    sweep = tmp_path / "s.yaml"
    sweep.write_text("scenarios: [acceptance]\nseeds: {count: 100000000}\n")
    out = tmp_path / "out"
    cli_fails(
        ["sweep", str(sweep), "--out", str(out)], str(sweep), "100,000,000 runs", "MAX_SWEEP_RUNS"
    )
    assert not out.exists()


@pytest.mark.parametrize(
    "flags", [["--seeds", "100000000"], ["--generate", "100000000"]], ids=["seeds", "generate"]
)
def test_the_quick_form_is_bounded_too(
    cli_fails: Callable[..., str], tmp_path: Path, flags: list[str]
) -> None:
    argv = ["sweep", "--scenario", "acceptance", *flags, "--out", str(tmp_path / "out")]
    cli_fails(argv, "otonav sweep", "100,", "split it into smaller sweeps")
