"""The recording as the forensic artifact: deterministic bytes, and a failing scenario
(a broken gain, a wrong sign) leaves a recording that shows it did not reach the goal."""

from __future__ import annotations

import importlib.metadata
import math
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

import otonav
from otonav.control import DiffDriveGeometry, twist_to_wheels
from otonav.record._reader import read_messages, summarize
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.stack import NavConfig, StackConfig

pytestmark = pytest.mark.sil

EXPECTED_TOPICS = {
    "/clock", "/odom", "/imu", "/scan", "/tf", "/tf_static", "/cmd_vel", "/wheel_cmd",
    "/goal", "/nav/state", "/rosout", "/scenario/verdict", "/cmd_vel_nav", "/safety/state",
    "/hardware/status", "/diagnostics", "/joint_states",
}  # fmt: skip


def test_two_runs_give_byte_identical_recordings(tmp_path: Path) -> None:
    first = run_scenario(out_dir=tmp_path / "a", plot=False)
    second = run_scenario(out_dir=tmp_path / "b", plot=False)
    assert first.passed
    assert second.passed
    a = (tmp_path / "a" / "recording.mcap").read_bytes()
    b = (tmp_path / "b" / "recording.mcap").read_bytes()
    assert len(a) > 100_000
    assert a == b


def test_the_recording_does_not_depend_on_the_installed_metadata(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The version a recording carries is the code's. Looked up in the installed
    metadata at each run, it read ``unknown`` while the venv was being reinstalled (pip
    removes the old .dist-info before it writes the new one): the same config and seed,
    other bytes, with the same verdict."""
    scenario = ScenarioConfig(sim_budget=0.5)  # the bytes, not the outcome: 0.5 s will do
    run_scenario(scenario, out_dir=tmp_path / "a", plot=False)

    def hidden(name: str) -> object:  # as importlib.metadata answers mid-reinstall
        raise importlib.metadata.PackageNotFoundError(name)

    monkeypatch.setattr(importlib.metadata, "version", hidden)
    monkeypatch.setattr(importlib.metadata, "distribution", hidden)
    run_scenario(scenario, out_dir=tmp_path / "b", plot=False)
    a = (tmp_path / "a" / "recording.mcap").read_bytes()
    b = (tmp_path / "b" / "recording.mcap").read_bytes()
    assert a == b
    assert (
        summarize(tmp_path / "b" / "recording.mcap").metadata["otonav"]["otonav_version"]
        == otonav.__version__
    )


def _plain(value: Any) -> Any:
    """A decoded message as nested dicts and lists, floats as their exact hex: ours (a
    pydantic model) and mcap_ros2's (a class with ``__slots__``) alike."""
    names = getattr(type(value), "model_fields", None) or getattr(type(value), "__slots__", None)
    if names is not None:
        return {n: _plain(getattr(value, n)) for n in names if n != "_type"}
    if isinstance(value, bytes | list | tuple):
        return [_plain(item) for item in value]
    return value.hex() if isinstance(value, float) else value


def test_every_recorded_message_decodes_as_mcap_ros2_decodes_it(tmp_path: Path) -> None:
    """The oracle for ``read_messages`` (otonav's own decoder, otonav's types): every
    message of every topic of a real run, decoded by mcap_ros2's generic decoder from
    the recorded schema, holds the same fields with the same values, bit for bit."""
    run_scenario(ScenarioConfig(sim_budget=2.0), out_dir=tmp_path, plot=False)
    recording = tmp_path / "recording.mcap"
    ours = [(topic, round(t * 1e9), _plain(m)) for topic, t, m in read_messages(recording)]
    with recording.open("rb") as f:
        theirs = [
            (channel.topic, message.log_time, _plain(decoded))
            for _s, channel, message, decoded in make_reader(
                f, decoder_factories=[DecoderFactory()]
            ).iter_decoded_messages()
        ]
    every = {t.topic for t in summarize(recording).topics}
    assert every >= EXPECTED_TOPICS
    assert {topic for topic, _t, _m in ours} == every
    assert len(ours) == len(theirs) > 1000
    for mine, other in zip(ours, theirs, strict=True):
        assert mine == other


def _assert_failed_recording(
    out: Path, scenario: ScenarioConfig, *, extra: frozenset[str] = frozenset()
) -> None:
    recording = out / "recording.mcap"
    summary = summarize(recording)
    assert not summary.truncated
    assert {t.topic for t in summary.topics} == EXPECTED_TOPICS | extra
    assert summary.duration_s == pytest.approx(scenario.sim_budget, abs=0.02)
    meta = summary.metadata["otonav"]
    assert meta["scenario"] == scenario.name
    assert meta["seed"] == str(scenario.seed)
    assert meta["otonav_version"] == "0.1.0"
    assert ScenarioConfig.model_validate_json(meta["scenario_config"]) == scenario
    verdict = [m for _t, _s, m in read_messages(recording, ["/scenario/verdict"])][-1]
    assert not verdict.passed
    assert not verdict.reached
    # The robot's own odometry, read back from the file, never got near the goal.
    closest = min(
        math.hypot(
            m.pose.pose.position.x - scenario.goal.x, m.pose.pose.position.y - scenario.goal.y
        )
        for _t, _s, m in read_messages(recording, ["/odom"])
    )
    assert closest > scenario.goal_tolerance
    assert (out / "trajectory.png").stat().st_size > 10_000


def test_zero_linear_gain_fails_and_leaves_its_recording(tmp_path: Path) -> None:
    scenario = ScenarioConfig()
    verdict = run_scenario(
        scenario, StackConfig(nav=NavConfig(planner="stop", kp_lin=0.0)), out_dir=tmp_path
    )
    assert not verdict.passed
    assert verdict.recording == str(tmp_path / "recording.mcap")
    _assert_failed_recording(tmp_path, scenario)


def test_wrong_sign_in_the_kinematics_fails_and_leaves_its_recording(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def flipped(v: float, omega: float, geometry: DiffDriveGeometry) -> tuple[float, float]:
        return twist_to_wheels(v, -omega, geometry)  # the seeds' classic: wheels swapped

    # The base controller looks the function up in its own module at each call.
    monkeypatch.setattr("otonav.actors._base_controller.twist_to_wheels", flipped)
    scenario = ScenarioConfig()
    verdict = run_scenario(scenario, out_dir=tmp_path)
    assert not verdict.passed
    # The default (dwa) planner also records its diagnostics.
    _assert_failed_recording(tmp_path, scenario, extra=frozenset({"/nav/diagnostics"}))
