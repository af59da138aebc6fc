"""Recording bytes may change between otonav versions (issue 40): every recording says
its ``format_version``, and a replay of a recording of another version says what
differs instead of calling a difference a divergence (ADR 0084). The fixture was
recorded by otonav before the change (format 1: no record): the acceptance scenario's
first 1.5 s."""

from __future__ import annotations

from pathlib import Path

import pytest
from mcap.reader import make_reader

from otonav.cli import main
from otonav.msgs import Clock, Time
from otonav.record._writer import FORMAT_METADATA, FORMAT_VERSION, RecordingWriter

pytestmark = pytest.mark.unit

FORMAT_1 = Path(__file__).parents[2] / "data" / "format1_acceptance_1s5.mcap"


def _metadata(path: Path) -> dict[str, dict[str, str]]:
    with path.open("rb") as f:
        return {m.name: dict(m.metadata) for m in make_reader(f).iter_metadata()}


def test_a_recording_says_its_format_version(tmp_path: Path) -> None:
    writer = RecordingWriter(tmp_path / "r.mcap")
    writer.write("/clock", Clock(clock=Time(sec=1, nanosec=0)), 1.0)
    writer.finish()
    assert FORMAT_VERSION == 2
    assert _metadata(tmp_path / "r.mcap")[FORMAT_METADATA] == {"format_version": "2"}
    assert FORMAT_METADATA not in _metadata(FORMAT_1)  # made before: version 1


def test_a_replay_of_a_format_1_recording_says_what_differs(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["replay", str(FORMAT_1), "--node", "base"]) == 0
    out = capsys.readouterr().out
    assert "note: the recording is format_version 1, this otonav writes 2 (format 2: a " in out
    assert "/wheel_cmd is applied to the hardware in its publisher's call" in out
    assert "SAME: every output byte-identical" in out  # the base's inputs are recorded


def test_a_difference_in_a_replay_of_another_format_is_not_called_a_divergence(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["replay", str(FORMAT_1), "--node", "base", "--set", "base.max_accel=0.5"]) == 1
    out = capsys.readouterr().out
    assert "FORMAT DIFFERS: " in out
    assert "which the format change above can explain" in out
    assert "DIVERGED" not in out
