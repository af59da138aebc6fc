"""A user's velocity filter between the built-in navigator and the safety layer, from a
stack file (issue 39 item 2): the navigator is remapped without restating its class,
the filter takes a ROS 2 parameter file, and the acceptance scenario still passes."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from otonav.cli import main
from otonav.record._reader import read_messages

pytestmark = pytest.mark.sil

STACK = Path(__file__).resolve().parents[2] / "examples" / "my_nodes" / "smoothed.yaml"


@pytest.mark.timeout(180)
def test_a_velocity_filter_between_navigator_and_safety_passes_acceptance(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["run", "--config", str(STACK), "--out", str(tmp_path)]) == 0
    assert "acceptance: PASSED" in capsys.readouterr().out
    recording = tmp_path / "recording.mcap"
    raw = [(t, m.linear.x) for _topic, t, m in read_messages(recording, ["/cmd_vel_raw"])]
    nav = [(t, m.linear.x) for _topic, t, m in read_messages(recording, ["/cmd_vel_nav"])]
    assert len(raw) > 100  # the navigator published to the filter, not to the safety layer
    assert len(nav) == len(raw)  # one filtered command per raw one
    assert max(v for _t, v in raw) > 0.35  # the navigator wanted more ...
    assert max(v for _t, v in nav) == pytest.approx(0.3)  # ... the inline max_v capped it
    steps = [(b - a) / (tb - ta) for (ta, a), (tb, b) in itertools.pairwise(nav) if tb > ta]
    assert max(steps) <= 0.8 + 1e-9  # max_accel from the parameter file
