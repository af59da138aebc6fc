"""A text field that differs is shown as its two values, not as "|diff| inf"."""

from __future__ import annotations

import io
from pathlib import Path

from rich.console import Console

from otonav.cli._replay import print_result
from otonav.msgs import NavState
from otonav.record.cdr import encode
from otonav.replay import ReplayResult
from otonav.replay._compare import Divergence, Replayed, compare_topic
from otonav.replay._recording import RecordedMessage


def test_a_text_difference_prints_both_values() -> None:
    recorded = [RecordedMessage("/nav/state", 0, encode(NavState(state="driving")))]
    replayed = [Replayed("/nav/state", 0, NavState(state="avoiding"))]
    divergences: list[Divergence] = []
    topic = compare_topic("/nav/state", NavState, recorded, replayed, 0.0, divergences)
    assert topic.max_diff_values == ("driving", "avoiding")
    out = io.StringIO()
    result = ReplayResult(
        recording=Path("r.mcap"), nodes=("nav",), inputs={}, topics=[topic],
        divergences=divergences, sim_time_s=1.0, wall_time_s=0.1,
    )  # fmt: skip
    print_result(result, Console(file=out, width=200))
    text = out.getvalue()
    assert "at state: recorded 'driving', replayed 'avoiding'" in text
    assert "inf" not in text
