"""Flags that were silently ignored or wrong (issue 27, item 9): ``plot X --out /tmp``
wrote ``/tmp.png``; ``bench --duration -1`` ran and overwrote ``out/bench.json``;
``sweep FILE --generate 3`` ignored ``--generate``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from otonav.cli._inspect import plot_target

pytestmark = pytest.mark.unit


def test_plot_out_a_directory_writes_inside_it(tmp_path: Path) -> None:
    recording = tmp_path / "run" / "recording.mcap"
    assert plot_target(recording, tmp_path) == tmp_path / "recording.png"
    assert plot_target(recording, tmp_path / "p.png") == tmp_path / "p.png"
    assert plot_target(recording, None) is None


def test_plot_out_without_png_is_refused(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    cli_fails(["plot", str(tmp_path / "r.mcap"), "--out", str(tmp_path / "p.jpg")], "p.jpg", ".png")


@pytest.mark.parametrize(
    ("flags", "fragment"),
    [(["--duration", "-1"], "--duration -1"), (["--duration", "nan"], "--duration nan"),
     (["--reps", "0"], "--reps 0")],
)  # fmt: skip
def test_bench_refuses_a_duration_or_reps_out_of_range(
    cli_fails: Callable[..., str], tmp_path: Path, flags: list[str], fragment: str
) -> None:
    out = tmp_path / "bench.json"
    out.write_text("{}")
    cli_fails(["bench", *flags, "--json", str(out)], fragment, "must be in")
    assert out.read_text() == "{}"


@pytest.mark.parametrize(
    "flags", [["--generate", "3"], ["--seeds", "2"], ["--set", "nav.max_v=0.3"], ["--keep", "all"]]
)
def test_sweep_file_with_quick_form_flags_is_refused(
    cli_fails: Callable[..., str], tmp_path: Path, flags: list[str]
) -> None:
    sweep = tmp_path / "s.yaml"
    sweep.write_text("scenarios: [acceptance]\n")
    argv = ["sweep", str(sweep), *flags, "--out", str(tmp_path / "out")]
    cli_fails(argv, flags[0], "not used with a sweep file", str(sweep))
    assert not (tmp_path / "out").exists()
