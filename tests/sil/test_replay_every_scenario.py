"""Replay of unchanged code is byte-identical on every built-in scenario and on a
held-out start pose (issue 41, case 15): the navigator's map and plan are anchored at
the start pose, and a replay that built it at the origin drifted by 2e-15 on every
scenario starting elsewhere (box, gap, slalom: first at 0.55 s, in angular.z). Each run
is a virtual-time run; all replayable actors are replayed at once (the navigator's
/cmd_vel_nav is then both compared and fed to the safety layer), and the navigator
alone, as `otonav replay --node nav` does."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from otonav.replay import replay_recording
from otonav.replay._nodes import stack_actor_names
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.scenario._builtin import BUILTIN
from otonav.stack import StackConfig

pytestmark = pytest.mark.sil

HELD_OUT = ScenarioConfig.model_validate_json(
    json.dumps(
        {
            "name": "held_out",
            "scene": "empty",
            "start": {"x": 1.37, "y": -2.21, "yaw": 2.3},
            "goal": {"x": -2.6, "y": 1.9},
            "obstacles": [{"x": -0.4, "y": 0.1, "size_x": 0.5, "size_y": 0.3, "yaw": 0.4}],
            "sim_budget": 40.0,
        }
    )
)
SCENARIOS = {**BUILTIN, HELD_OUT.name: HELD_OUT}


@pytest.mark.parametrize("name", sorted(SCENARIOS))
def test_replay_of_unchanged_code_is_byte_identical(name: str, tmp_path: Path) -> None:
    scenario = SCENARIOS[name]
    verdict = run_scenario(scenario, out_dir=tmp_path, plot=False)
    assert verdict.sim_time_s > 1.0, verdict
    recording = tmp_path / "recording.mcap"
    names = stack_actor_names(StackConfig())
    for nodes in (["nav"], names):
        result = replay_recording(recording, nodes)
        assert result.crash is None, result.crash
        assert result.byte_identical, (name, nodes, result.first_divergence)
        assert all(t.recorded > 0 for t in result.topics), result.topics
