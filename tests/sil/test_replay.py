"""Replay against the acceptance run: unchanged code gives byte-identical outputs for
every replayable actor (the contract); a deliberate change is reported at its first
divergence, and the CLI exits 1; bad input is one line and exit 2."""

from __future__ import annotations

import asyncio
import contextvars
import dataclasses
import re
import struct
from collections.abc import Callable
from pathlib import Path
from typing import TypeVarTuple

import pytest

from otonav.cli import main as cli_main
from otonav.hal import RobotHardwareInterface
from otonav.msgs import Clock, Imu, Message, Odometry, PoseStamped, TFMessage, Twist
from otonav.msgs._flat import is_flat
from otonav.nav import GoalCommand, go_to_goal
from otonav.record._reader import MAGIC, read_messages, summarize
from otonav.record._writer import RecordingWriter
from otonav.record.cdr import decode
from otonav.replay import _nodes as nodes
from otonav.replay import replay_recording
from otonav.replay._feed import FLAT_LAYOUTS
from otonav.replay._lazy import input_maker
from otonav.replay._nodes import stack_actor_names
from otonav.replay._recording import load_recording
from otonav.runtime import JumpSource, RealTime, VirtualTimeLoop
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.stack import NavConfig, SafetyConfig, StackConfig, build_world
from otonav.stack._worldmeta import WORLD_METADATA, geometry_from_metadata, world_metadata
from otonav.testing import replay

pytestmark = pytest.mark.sil

Ts = TypeVarTuple("Ts")


# The stop-only stack as it was (go-to-goal on /cmd_vel, no safety layer): these tests
# change its gains on purpose. The default (dwa) stack's replay: tests/sil/test_avoidance.py.
STOP_ONLY = StackConfig(nav=NavConfig(planner="stop"), safety=SafetyConfig(enabled=False))


@pytest.fixture(scope="module")
def acceptance(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("acceptance")
    verdict = run_scenario(stack=STOP_ONLY, out_dir=out, plot=False)
    assert verdict.passed
    return out / "recording.mcap"


def test_every_replayable_actor_is_byte_identical_on_the_acceptance_run(
    acceptance: Path,
) -> None:
    names = stack_actor_names(STOP_ONLY)
    assert {"nav", "base"} <= set(names)
    assert "bridge" not in names
    for replayed in [[name] for name in names] + [names]:
        result = replay_recording(acceptance, replayed)
        assert result.byte_identical, (replayed, result.first_divergence, result.crash)
        assert all(t.recorded > 100 for t in result.topics), result.topics
        assert result.sim_time_s == pytest.approx(summarize(acceptance).duration_s, abs=0.02)


def test_the_recorded_robot_spares_building_the_world(
    acceptance: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The recording keeps the geometry the run's actors were built for...
    with build_world(STOP_ONLY) as world:
        geometry = world.geometry
    stored = load_recording(acceptance, ()).metadata[WORLD_METADATA]
    assert geometry_from_metadata(stored) == geometry
    # ...so the replayed actors are built for it without compiling the robot model.
    built: list[StackConfig] = []
    build = nodes._world

    def counted(stack: StackConfig) -> RobotHardwareInterface:
        built.append(stack)
        return build(stack)

    monkeypatch.setattr(nodes, "_world", counted)
    for names in (["nav"], ["base"], ["nav", "base"]):
        result = replay_recording(acceptance, names)
        assert result.byte_identical, (names, result.first_divergence)
    assert built == []
    # Asking for another world (--set world.*) builds that one.
    result = replay_recording(acceptance, ["base"], overrides=["world.lidar_range_max=7.5"])
    assert result.byte_identical, result.first_divergence  # the base ignores the lidar
    assert [stack.world.lidar_range_max for stack in built] == [7.5]
    # A recording made before the geometry was kept builds the world, as it did.
    monkeypatch.setattr(
        "otonav.stack._session.world_metadata",
        lambda hal: {k: v for k, v in world_metadata(hal).items() if k != "robot"},
    )
    run_scenario(ScenarioConfig(sim_budget=1.0), stack=STOP_ONLY, out_dir=tmp_path, plot=False)
    older = tmp_path / "recording.mcap"
    assert "robot" not in load_recording(older, ()).metadata[WORLD_METADATA]
    built.clear()
    result = replay_recording(older, ["nav", "base"])
    assert result.byte_identical, result.first_divergence
    assert len(built) == 1


def test_the_bridges_streams_are_fed_as_the_flat_messages_it_published(acceptance: Path) -> None:
    recorded = load_recording(acceptance, ["/odom", "/tf", "/imu", "/clock"]).messages
    kinds: dict[str, type[Message]] = {
        "/odom": Odometry,
        "/tf": TFMessage,
        "/imu": Imu,
        "/clock": Clock,
    }
    assert len(recorded) > 4 * 1000
    for message in recorded:
        kind = kinds[message.topic]
        fed = input_maker(kind, FLAT_LAYOUTS)(message.data)
        assert is_flat(fed), message.topic
        assert fed == decode(kind, message.data)


def test_the_pytest_helper_and_a_user_actor_by_import_path(acceptance: Path) -> None:
    assert replay(acceptance, "nav") == []
    assert replay(acceptance, "replay_user_actor:make_navigator") == []


def test_a_deliberate_change_is_reported_at_its_first_divergence(
    acceptance: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def sluggish(*args: object, **kwargs: object) -> GoalCommand:
        command = go_to_goal(*args, **kwargs)  # type: ignore[arg-type]
        return dataclasses.replace(command, omega=command.omega * 0.9)

    monkeypatch.setattr("otonav.actors._navigator.go_to_goal", sluggish)
    divergences = replay(acceptance, "nav")
    assert divergences
    first = divergences[0]
    assert (first.topic, first.kind, first.field) == ("/cmd_vel", "content", "angular.z")
    assert first.replayed == pytest.approx(0.9 * first.recorded)
    # The first commanded turn is the first output that can differ (before it: zeros).
    recorded = [m for _t, _s, m in read_messages(acceptance, ["/cmd_vel"])]
    turning = next(i for i, m in enumerate(recorded) if m.angular.z != 0.0)
    assert first.index == turning
    # /nav/state only reports the recorded inputs: it does not diverge.
    assert {d.topic for d in divergences} == {"/cmd_vel"}


def test_cli_exit_codes_summary_and_out(
    acceptance: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert cli_main(["replay", str(acceptance), "--node", "nav,base"]) == 0
    printed = capsys.readouterr().out
    assert "SAME: every output byte-identical" in printed
    # The speed it prints: sim time, wall time, RTF and CPU time of the replay.
    speed = r"\d+\.\d{3} s of sim time in \d+\.\d{3} s \(\d+x; CPU \d+\.\d{3} s\)"
    assert re.search(speed, " ".join(printed.split())), printed  # rich wraps at 80

    out = tmp_path / "replayed.mcap"
    code = cli_main(
        ["replay", str(acceptance), "--node", "nav", "--set", "nav.kp_ang=3.0", "--out", str(out)]
    )
    printed = capsys.readouterr().out
    assert code == 1
    assert "first divergence: /cmd_vel at sim time" in printed
    assert "angular.z" in printed
    assert "DIVERGED" in printed
    topics = {t.topic: t.count for t in summarize(out).topics}
    # 13.3 s of acceptance run (reached at 11.3 s, then the 2 s arrival check).
    assert topics["/cmd_vel"] == topics["/recorded/cmd_vel"] == 266
    assert topics["/odom"] == 1330  # the inputs, copied
    assert "/scenario/verdict" not in topics
    # Within a tolerance as large as the change, the same run passes.
    assert cli_main(["replay", str(acceptance), "--node", "nav", "--tolerance", "10"]) == 0


@pytest.mark.parametrize(
    ("args", "expected"),
    [
        (["--node", "navv"], "--node navv: no such node; replayable nodes: base, nav"),
        (["--node", "bridge"], "--node bridge: cannot be replayed (it owns the hardware"),
        (["--node", "nosuchmodule:Thing"], "cannot import 'nosuchmodule'"),
        (["--node", "nav", "--set", "nav.kp_angg=3"], "unknown key 'kp_angg'"),
        (["--node", "nav", "--tolerance", "-1"], "--tolerance -1.0: must be"),
        ([], "--node: name a node to replay"),
    ],
)
def test_cli_bad_input_is_one_line_and_exit_2(
    acceptance: Path, args: list[str], expected: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert cli_main(["replay", str(acceptance), *args]) == 2
    err = capsys.readouterr().err
    assert expected in err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err


def test_cli_bad_files_are_exit_2(
    acceptance: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(acceptance.read_bytes()[: acceptance.stat().st_size // 2])
    no_scan = tmp_path / "no_scan.mcap"
    kinds: dict[str, type[Message]] = {"/odom": Odometry, "/goal": PoseStamped, "/cmd_vel": Twist}
    with RecordingWriter(no_scan) as writer:
        for m in load_recording(acceptance, list(kinds)).messages:
            writer.write(m.topic, decode(kinds[m.topic], m.data), m.time_ns / 1e9)
    # Damaged, not cut off: a chunk's CRC, and a byte of a chunk's compressed records.
    crc, flipped = tmp_path / "crc.mcap", tmp_path / "flipped.mcap"
    data = acceptance.read_bytes()
    chunk = _chunk_offsets(data)[3]
    (name_len,) = struct.unpack_from("<I", data, chunk + 9 + 28)
    for path, at in [(crc, chunk + 9 + 24), (flipped, chunk + 9 + 28 + 4 + name_len + 8 + 40)]:
        damaged = bytearray(data)
        damaged[at] ^= 0x10
        path.write_bytes(bytes(damaged))
    for path, expected in [
        (crc, f"{crc}: 1 damaged chunk: chunk at byte {chunk} (sim time"),
        (crc, "CRC mismatch"),
        (flipped, f"{flipped}: 1 damaged chunk: chunk at byte {chunk} (sim time"),
        (flipped, "a replay would feed damaged data as recorded"),
        (cut, f"otonav salvage {cut} RECOVERED.mcap"),
        (no_scan, "has no /scan, which nav reads (sensor_msgs/msg/LaserScan)"),
        (tmp_path / "missing.mcap", "no such file"),
        (acceptance.parent, "is a directory"),
    ]:
        assert cli_main(["replay", str(path), "--node", "nav"]) == 2
        err = capsys.readouterr().err
        assert expected in err, err
        assert len(err.strip().splitlines()) == 1


def _chunk_offsets(data: bytes) -> list[int]:
    """Offsets of the chunk records (opcode 0x06) of an MCAP file."""
    offsets, pos = [], len(MAGIC)
    while pos < len(data) - len(MAGIC):
        opcode, (length,) = data[pos], struct.unpack_from("<Q", data, pos + 1)
        if opcode == 0x06:
            offsets.append(pos)
        pos += 9 + length
    return offsets


class LateWallLoop(VirtualTimeLoop):
    """A fake wall clock for the real-time runner: wall time jumps ahead while the loop
    is idle (a JumpSource of 1 us), and every timer fires ``LATE`` wall seconds after
    its deadline, as a busy host's would. A paced run on it is exact and repeatable."""

    LATE = 0.0013  # 13 ms of sim time at scale 10: the navigator's wake-ups miss k * 50 ms

    def __init__(self) -> None:
        super().__init__(JumpSource(1e-6))

    def call_at(
        self,
        when: float,
        callback: Callable[[*Ts], object],
        *args: *Ts,
        context: contextvars.Context | None = None,
    ) -> asyncio.TimerHandle:
        return super().call_at(when + self.LATE, callback, *args, context=context)


def test_a_real_time_recording_replays_with_recorded_wakes(tmp_path: Path) -> None:
    from otonav.scenario import run_scenario

    run_scenario(
        ScenarioConfig(sim_budget=2.0),
        out_dir=tmp_path,
        time=RealTime(10.0),
        plot=False,
        loop_factory=LateWallLoop,
    )
    recording = tmp_path / "recording.mcap"
    # On its own timers the navigator wakes at k * 50 ms; in real time it woke when the
    # world had caught up with the wall clock, later: only timing differs. (The default
    # navigator's command goes to the safety layer on /cmd_vel_nav.)
    timers = replay_recording(recording, ["nav"])
    cmd = next(t for t in timers.topics if t.topic == "/cmd_vel_nav")
    assert cmd.recorded == 40  # 2 s at 20 Hz
    assert cmd.identical == 0
    assert {d.kind for d in timers.divergences} == {"missing", "extra"}
    # Woken at the recorded instants, it decides the same: every output is identical.
    # (On a real host the world moves on while an actor computes, so a stamp taken at
    # the wake-up, /nav/state's header, can differ from the publish instant recorded;
    # on this clock computing takes no wall time.)
    recorded = replay_recording(recording, ["nav"], wake="recorded")
    cmd = next(t for t in recorded.topics if t.topic == "/cmd_vel_nav")
    assert cmd.identical == cmd.recorded == cmd.replayed == 40
    assert recorded.byte_identical, recorded.first_divergence
