"""otonav graph and otonav scenarios: what they print comes from the configured stack."""

from __future__ import annotations

import pytest

from otonav.cli import main

pytestmark = pytest.mark.unit


def test_graph_lists_actors_topics_types_and_qos(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["graph"]) == 0
    out = capsys.readouterr().out
    for actor in ("bridge", "base", "nav"):
        assert actor in out
    for topic, kind in (("/scan", "LaserScan"), ("/cmd_vel", "Twist"), ("/rosout", "Log")):
        assert topic in out
        assert kind in out
    assert "best_effort/depth=5/volatile" in out  # the sensor topics' QoS
    assert "reliable/depth=1/transient_local" in out  # /tf_static, latched


def test_graph_follows_set_overrides(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["graph", "--set", "rates.scan_hz=5"]) == 0  # a valid stack: it builds
    assert main(["graph", "--set", "rates.scan_hz=0"]) == 2
    assert "rates.scan_hz" in capsys.readouterr().err


def test_scenarios_lists_the_built_ins(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    assert "acceptance" in out
    assert "goal (4, 1.5)" in out
    assert "empty" in out
