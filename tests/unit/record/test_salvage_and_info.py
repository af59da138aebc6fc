"""What a recording stores is shown and kept: ``info`` prints its scenario, seed and stack
config (``--json`` for scripts), ``salvage`` copies its metadata, and refuses to overwrite
a file unless told to. A scenario run writes its world and run records first, so a
killed run's file still says what it was."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from otonav.cli import main
from otonav.msgs import Clock, Time
from otonav.record._reader import summarize
from otonav.record._salvage import salvage
from otonav.record._writer import RecordingWriter
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.scenario._artifacts import run_metadata
from otonav.scenario._assembly import effective_stack
from otonav.stack import NavConfig, StackConfig
from otonav.stack._worldmeta import WORLD_METADATA

pytestmark = pytest.mark.unit

SCENARIO = ScenarioConfig(name="probe", scene="empty", seed=7, sim_budget=0.3)
STACK = StackConfig(nav=NavConfig(kp_lin=0.55))


def _recording(path: Path, *, seconds: float = 1.0) -> Path:
    with RecordingWriter(path, chunk_size=1024) as writer:
        writer.add_metadata("otonav", run_metadata(SCENARIO, STACK))
        for i in range(round(seconds * 100)):
            writer.write("/clock", Clock(clock=Time.from_seconds(i / 100)), i / 100)
        writer.add_metadata("otonav", {**run_metadata(SCENARIO, STACK), "verdict": "{}"})
    return path


def _cut(path: Path, target: Path) -> Path:
    data = path.read_bytes()
    target.write_bytes(data[: len(data) // 2])
    return target


def test_info_shows_scenario_seed_and_stack_config(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["info", str(_recording(tmp_path / "r.mcap"))]) == 0
    out = capsys.readouterr().out
    assert "scenario:  probe   seed: 7" in out
    assert "scene=empty" in out
    nav = next(line for line in out.splitlines() if line.strip().startswith("nav:"))
    assert "kp_lin=0.55" in nav


def test_info_json_is_one_object_scripts_can_read(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["info", "--json", str(_recording(tmp_path / "r.mcap"))]) == 0
    facts = json.loads(capsys.readouterr().out)
    assert facts["scenario"] == "probe"
    assert facts["seed"] == 7
    assert facts["message_count"] == 100
    assert facts["truncated"] is False
    assert facts["topics"] == [
        {"topic": "/clock", "type": "rosgraph_msgs/msg/Clock", "count": 100, "rate_hz": 100.0}
    ]
    assert facts["metadata"]["otonav"]["stack_config"]["nav"]["kp_lin"] == 0.55
    assert facts["metadata"]["otonav"]["scenario_config"]["seed"] == 7


def test_salvage_keeps_the_metadata(tmp_path: Path) -> None:
    whole = _recording(tmp_path / "r.mcap")
    fixed = tmp_path / "fixed.mcap"
    assert salvage(whole, fixed) == 100
    assert summarize(fixed).metadata == summarize(whole).metadata
    assert summarize(fixed).metadata["otonav"]["verdict"] == "{}"


def test_salvage_of_a_cut_off_file_keeps_the_metadata_written_before_the_cut(
    tmp_path: Path,
) -> None:
    cut = _cut(_recording(tmp_path / "r.mcap", seconds=20.0), tmp_path / "cut.mcap")
    assert summarize(cut).truncated
    fixed = tmp_path / "fixed.mcap"
    assert salvage(cut, fixed) > 0
    kept = summarize(fixed).metadata["otonav"]
    assert kept == run_metadata(SCENARIO, STACK)  # the start record; the verdict was cut


def test_salvage_refuses_to_overwrite_without_force(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cut = _cut(_recording(tmp_path / "r.mcap", seconds=20.0), tmp_path / "cut.mcap")
    target = tmp_path / "precious.mcap"
    target.write_bytes(b"an earlier salvage")
    assert main(["salvage", str(cut), str(target)]) == 2
    err = capsys.readouterr().err
    assert err.strip() == (
        f"otonav: error: {target}: already exists; choose another path or pass --force"
    )
    assert target.read_bytes() == b"an earlier salvage"
    assert main(["salvage", str(cut), str(target), "--force"]) == 0
    assert summarize(target).message_count > 0


def test_a_killed_runs_file_still_says_its_world_scenario_and_seed(tmp_path: Path) -> None:
    scenario = SCENARIO.model_copy(update={"sim_budget": 4.0})  # > 2 chunks of 64 KiB
    run_scenario(scenario, STACK, out_dir=tmp_path, plot=False)
    cut = _cut(tmp_path / "recording.mcap", tmp_path / "cut.mcap")
    summary = summarize(cut)
    assert summary.truncated
    assert summary.message_count > 0
    assert summary.metadata["otonav"] == run_metadata(scenario, effective_stack(scenario, STACK))
    world = summary.metadata[WORLD_METADATA]
    assert json.loads(world["obstacles"]) == []  # the empty scene
    assert len(json.loads(world["walls"])) == 4
