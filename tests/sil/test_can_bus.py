"""Layer 3: the whole stack over a CAN bus (python-can ``virtual``), the ODrive drives
emulated on the MuJoCo wheels, all in virtual time.

The acceptance scenario over CAN, deterministic recordings, startup and shutdown like a
real drive, and one test per fault: each detected by the interface, reported on /rosout
and /diagnostics, the base at zero within 2 control periods, the navigator in ``fault``,
and the recovery explicit and logged.
"""

from __future__ import annotations

import bisect
import itertools
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import pytest

from otonav.actors import topics
from otonav.hal import HealthLevel, RobotHardwareInterface, WheelSetpoint
from otonav.hal.can import CanBusInterface, MonitorLimits, RawFrame, WheelAxis, open_endpoint
from otonav.hal.can import _protocol as p
from otonav.hal.can._tap import FRAMES_TOPIC
from otonav.hal.mujoco import MujocoInterface
from otonav.hal.sim import AxisParams, DriveEmulator, DriveMount
from otonav.msgs import (
    DiagnosticArray,
    Frame,
    Log,
    NavState,
    Point,
    Pose,
    PoseStamped,
    WheelCommand,
)
from otonav.record._reader import read_messages, summarize
from otonav.runtime import (
    LATCHED_QOS,
    EventKind,
    QoS,
    Reliability,
    RestartPolicy,
    Subscription,
    until,
)
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.stack import StackConfig, StackSession
from otonav.stack._build import build_actors, build_world
from otonav.stack._overrides import apply_overrides
from otonav.testing import running_stack

pytestmark = pytest.mark.sil

CAN = apply_overrides(StackConfig(), ["hal.kind=can"])
BASE_PERIOD = 1.0 / CAN.base.rate_hz
NAV_PERIOD = 1.0 / CAN.nav.rate_hz
WATCH = QoS(Reliability.BEST_EFFORT, depth=5000)
M = TypeVar("M")


def drain(sub: Subscription[M]) -> list[M]:
    out: list[M] = []
    while (m := sub.try_recv()) is not None:
        out.append(m)
    return out


def emulator_of(hal: RobotHardwareInterface) -> DriveEmulator:
    assert isinstance(hal, CanBusInterface)
    assert isinstance(hal.peer, DriveEmulator)
    return hal.peer


# -- the acceptance scenario over CAN ----------------------------------------------------


def test_acceptance_over_can_passes_and_every_wheel_command_is_a_frame(tmp_path: Path) -> None:
    verdict = run_scenario(ScenarioConfig(), CAN, out_dir=tmp_path, plot=False)
    assert verdict.passed, verdict.reason
    assert verdict.time_to_goal_s is not None
    assert verdict.time_to_goal_s < 20.0
    assert verdict.min_clearance_m >= 0.3
    recording = tmp_path / "recording.mcap"
    frames = [m for _t, _s, m in read_messages(recording, [FRAMES_TOPIC])]
    by_cmd: dict[int, list[Any]] = {}
    for frame in frames:
        by_cmd.setdefault(p.split_id(frame.id)[1], []).append(frame)
    sim = verdict.sim_time_s
    # Encoder estimates every 10 ms and heartbeats every 100 ms, from both drives.
    assert len(by_cmd[p.CMD_GET_ENCODER_ESTIMATES]) == pytest.approx(2 * sim / 0.01, abs=4)
    assert len(by_cmd[p.CMD_HEARTBEAT]) == pytest.approx(2 * sim / 0.1, abs=4)
    # Every /wheel_cmd reached the drives as Set_Input_Vel (turns/s, float32, left motor
    # mirrored): at its instant, the last setpoint sent to each drive is its value. A
    # repeated setpoint is resent only after the keepalive, so fewer frames than
    # commands cross the bus, and no drive waits longer than keepalive + a base period.
    wheel_cmds = [m for _t, _s, m in read_messages(recording, [topics.WHEEL_CMD])]
    sent: dict[int, list[tuple[float, float]]] = {0: [], 1: []}
    for frame in by_cmd[p.CMD_SET_INPUT_VEL]:
        sent[frame.id >> 5].append((_secs(frame.header.stamp), struct_f32(frame.data)))
    checked = 0
    for cmd in wheel_cmds:
        t = _secs(cmd.header.stamp)
        if t < 0.15:
            continue  # zero while the drives start
        for node, value in ((0, -cmd.left / (2 * math.pi)), (1, cmd.right / (2 * math.pi))):
            times = [s for s, _v in sent[node]]
            last = sent[node][bisect.bisect_right(times, t + 1e-9) - 1]
            assert last[1] == pytest.approx(value, rel=1e-6, abs=1e-6), (t, node)
            checked += 1
    assert checked > 2 * 500
    keepalive = CAN.hal.can.command_keepalive
    for node in (0, 1):
        assert len(sent[node]) < 0.8 * len(wheel_cmds)
        gaps = [b - a for (a, _), (b, _) in itertools.pairwise(sent[node])]
        assert max(gaps) <= keepalive + BASE_PERIOD + 1e-9
    # Startup (Clear_Errors, controller mode, closed loop) and shutdown (IDLE) frames.
    states = [p.decode_set_axis_state(bytes(f.data)) for f in by_cmd[p.CMD_SET_AXIS_STATE]]
    assert states[:2] == [p.AxisState.CLOSED_LOOP_CONTROL] * 2
    logs = [m.msg for _t, _s, m in read_messages(recording, [topics.ROSOUT])]
    assert any("running: node 0 (left wheel), node 1 (right wheel)" in m for m in logs)


def _secs(stamp: Any) -> float:
    return float(stamp.sec + stamp.nanosec * 1e-9)


def struct_f32(data: bytes | tuple[int, ...]) -> float:
    return float(p.unpack_two_f32(bytes(data))[0])


def test_two_can_runs_give_byte_identical_recordings(tmp_path: Path) -> None:
    scenario = ScenarioConfig(sim_budget=3.0)
    run_scenario(scenario, CAN, out_dir=tmp_path / "a", plot=False)
    run_scenario(scenario, CAN, out_dir=tmp_path / "b", plot=False)
    a = (tmp_path / "a" / "recording.mcap").read_bytes()
    b = (tmp_path / "b" / "recording.mcap").read_bytes()
    assert summarize(tmp_path / "a" / "recording.mcap").topics
    assert len(a) > 50_000
    assert a == b


def test_a_failed_run_ends_its_recording_with_the_idle_frames(tmp_path: Path) -> None:
    # A 1 s budget: the scenario fails. Its recording must still show the shutdown:
    # both drives set IDLE, after every other command the host sent them.
    verdict = run_scenario(ScenarioConfig(sim_budget=1.0), CAN, out_dir=tmp_path, plot=False)
    assert not verdict.passed
    frames = [m for _t, _s, m in read_messages(tmp_path / "recording.mcap", [FRAMES_TOPIC])]
    commands = [f for f in frames if f.id & 0x1F not in _FROM_DRIVES]
    assert [(f.id >> 5, f.id & 0x1F) for f in commands[-2:]] == [
        (0, p.CMD_SET_AXIS_STATE),
        (1, p.CMD_SET_AXIS_STATE),
    ]
    assert {p.decode_set_axis_state(bytes(f.data)) for f in commands[-2:]} == {p.AxisState.IDLE}
    assert _secs(commands[-1].header.stamp) == pytest.approx(verdict.sim_time_s, abs=0.011)


_FROM_DRIVES = {p.CMD_HEARTBEAT, p.CMD_GET_ENCODER_ESTIMATES}


@pytest.mark.sim(wall_ceiling=60)
async def test_a_tap_that_crashes_and_restarts_leaves_the_drives_running() -> None:
    # The tap sets the drives IDLE in on_stop; a restart also runs on_stop: only the
    # system's stop may release the drives.
    hal = build_world(CAN)
    assert isinstance(hal, CanBusInterface)
    take, calls = hal.take_frames, [0]

    def crash_once() -> list[tuple[float, RawFrame]]:
        calls[0] += 1
        if calls[0] == 10:
            raise RuntimeError("tap crash (test)")
        return take()

    hal.take_frames = crash_once  # type: ignore[method-assign]
    session = StackSession(hal, build_actors(CAN, hal), restart={"can_tap": RestartPolicy()})
    async with session.running() as system:
        await system.clock.sleep(1.0)
        kinds = [e.kind for e in system.events if e.actor == "can_tap"]
        assert kinds.count(EventKind.RESTARTED) == 1
        emulator = emulator_of(hal)
        assert emulator.drive(0).state == p.AxisState.CLOSED_LOOP_CONTROL
        assert hal.health().drivable
        assert [m for _t, m in hal.monitor.events if "running" not in m] == []  # no fault
    assert emulator.drive(0).state == p.AxisState.IDLE


@pytest.mark.sim(wall_ceiling=60)
async def test_a_full_frame_mailbox_holds_the_tap_back_and_loses_no_frame() -> None:
    # A reliable subscriber that does not read: its mailbox fills and the tap waits
    # for room (backpressure) instead of dropping. Read later, every frame arrives,
    # in order: the left drive's encoder estimates 10 ms apart with no gap.
    async with running_stack(CAN) as stack:
        system = stack.system
        slow = system.subscribe(FRAMES_TOPIC, Frame, QoS(depth=3))
        await system.clock.sleep(0.3)
        assert slow.statistics().dropped == 0
        frames = [await slow.recv() for _ in range(300)]
    left = p.arbitration_id(CAN.hal.sim.left_node_id, p.CMD_GET_ENCODER_ESTIMATES)
    stamps = [_secs(f.header.stamp) for f in frames if f.id == left]
    assert stamps[-1] > 0.5
    assert stamps[0] == pytest.approx(0.0, abs=0.011)
    assert [round(b - a, 6) for a, b in itertools.pairwise(stamps)] == [0.01] * (len(stamps) - 1)


@pytest.mark.sim(wall_ceiling=60)
async def test_frames_are_kept_only_while_somebody_listens() -> None:
    # No recorder, no subscriber: from the tap's first wake (20 Hz) the interface keeps
    # no frame. A subscriber that joins gets every frame from the tap's next wake on, in
    # bus order, with no gap: the left drive's encoder estimates 10 ms apart.
    async with running_stack(CAN) as stack:
        system, hal = stack.system, stack.hal
        assert isinstance(hal, CanBusInterface)
        await system.clock.sleep(0.5)
        assert not hal.log_frames
        assert hal.take_frames() == []
        joined = system.clock.now()
        late = system.subscribe(FRAMES_TOPIC, Frame, WATCH)
        await system.clock.sleep(0.5)
        assert hal.log_frames
        frames = drain(late)
    left = p.arbitration_id(CAN.hal.sim.left_node_id, p.CMD_GET_ENCODER_ESTIMATES)
    stamps = [_secs(f.header.stamp) for f in frames if f.id == left]
    assert joined <= stamps[0] <= joined + 0.05 + 0.011  # from the tap's next wake on
    assert stamps[-1] > joined + 0.4
    assert [round(b - a, 6) for a, b in itertools.pairwise(stamps)] == [0.01] * (len(stamps) - 1)


# -- the interface alone: startup, shutdown, encoders only from frames -------------------


class _SensorsOnly(RobotHardwareInterface):
    """The world as the interface's sensor source, refusing wheel access: every wheel
    command and reading must go through the bus."""

    def __init__(self, world: MujocoInterface) -> None:
        self.world = world

    tick = property(lambda self: self.world.tick)
    ticks = property(lambda self: self.world.ticks)
    geometry = property(lambda self: self.world.geometry)

    def advance(self, n: int) -> None:
        self.world.advance(n)

    def write(self, cmd: WheelSetpoint) -> None:
        raise AssertionError("the CAN interface wrote the world's wheels directly")

    def read_wheels(self) -> Any:
        raise AssertionError("the CAN interface read the world's wheels directly")

    def read_imu(self) -> Any:
        return self.world.read_imu()

    def read_scan(self) -> Any:
        return self.world.read_scan()

    def ground_truth(self) -> Any:
        return self.world.ground_truth()

    def planar_truth(self) -> Any:
        return self.world.planar_truth()

    def obstacles(self) -> Any:
        return self.world.obstacles()

    def close(self) -> None:
        self.world.close()


def _bench(
    channel: str,
    *,
    left_sign: int = -1,
    mount_sign: int = -1,
    host_left_id: int = 0,
    keepalive: float = 0.1,
) -> tuple[CanBusInterface, DriveEmulator, MujocoInterface]:
    world = MujocoInterface("empty")
    emulator = DriveEmulator(
        open_endpoint("virtual", channel),
        world,
        AxisParams(0),
        AxisParams(1),
        left_mount=DriveMount(mount_sign, 1.0),
        right_mount=DriveMount(1, 1.0),
        heartbeat_period=CAN.hal.sim.heartbeat_period,
        encoder_period=CAN.hal.sim.encoder_period,
    )
    hal = CanBusInterface(
        open_endpoint("virtual", channel),
        _SensorsOnly(world),
        WheelAxis(host_left_id, left_sign, 1.0, "left wheel"),
        WheelAxis(1, 1, 1.0, "right wheel"),
        MonitorLimits(),
        peer=emulator,
        command_keepalive=keepalive,
    )
    return hal, emulator, world


@pytest.mark.parametrize("mode", ["passthrough", "vel_ramp"])
def test_the_configured_input_mode_reaches_the_drives(mode: str) -> None:
    # hal.can.input_mode is what Set_Controller_Mode selects: in passthrough a drive's
    # setpoint takes a new Set_Input_Vel at the instant it arrives; in vel_ramp it slews
    # at the drive's vel_ramp_rate (100 turns/s^2 here: 1 turn/s per 10 ms).
    config = apply_overrides(
        StackConfig(), ["hal.kind=can", f"hal.can.input_mode={mode}", "hal.sim.vel_ramp_rate=100"]
    )
    hal = build_world(config)
    with hal:
        emulator = emulator_of(hal)
        ten_ms = round(0.01 / hal.tick)
        for _ in range(20):  # 0.2 s at rest, feeding the drives' watchdog: closed loop
            hal.write(WheelSetpoint(0.0, 0.0))
            hal.advance(ten_ms)
        assert hal.health().drivable
        axis = emulator.drive(config.hal.sim.right_node_id)
        assert axis.input_mode == p.InputMode[mode.upper()]
        target = 5.0  # turns/s of the right motor (sign +1, gear 1)
        hal.write(WheelSetpoint(-target * 2 * math.pi, target * 2 * math.pi))
        hal.advance(0)  # the frames cross the bus at this instant
        setpoints = [axis.setpoint]
        for _ in range(3):
            hal.advance(ten_ms)
            setpoints.append(axis.setpoint)
    if mode == "passthrough":
        assert setpoints == pytest.approx([target] * 4)
    else:
        assert setpoints == pytest.approx([0.0, 1.0, 2.0, 3.0])


def test_startup_waits_for_closed_loop_in_sim_time_and_shutdown_sets_idle() -> None:
    hal, emulator, world = _bench("test-startup")
    with hal:
        assert not hal.health().ready
        hal.advance(45)  # 0.09 s: requested, armed, but no heartbeat since
        assert not hal.health().ready
        assert emulator.drive(0).state == p.AxisState.CLOSED_LOOP_CONTROL
        hal.advance(5)  # the 100 ms heartbeat shows closed loop
        assert hal.health().drivable
        assert hal.health().since == pytest.approx(0.1)
        for _ in range(50):
            hal.write(WheelSetpoint(6.0, 6.0))
            hal.advance(5)
        wheels, truth = hal.read_wheels(), world.read_wheels()
        # Wheel angles from the last encoder frames (float32 turns): the world's, rounded.
        assert wheels.left_position == pytest.approx(truth.left_position, abs=1e-5)
        assert wheels.right_velocity == pytest.approx(truth.right_velocity, abs=1e-4)
        assert wheels.left_position != truth.left_position
        assert hal.ground_truth().x > 0.1  # forward: the signs agree
    assert emulator.drive(0).state == p.AxisState.IDLE
    assert emulator.drive(1).state == p.AxisState.IDLE
    frames = hal.take_frames()
    idle = p.set_axis_state(0, p.AxisState.IDLE)
    assert (frames[-2][1].arbitration_id, frames[-2][1].data) == idle


@pytest.mark.parametrize(("keepalive", "expected"), [(0.1, 5), (0.0, 50)])
def test_an_unchanged_setpoint_is_resent_only_after_the_keepalive(
    keepalive: float, expected: int
) -> None:
    hal, emulator, _world = _bench(f"test-keepalive-{keepalive}", keepalive=keepalive)
    with hal:
        hal.advance(50)
        assert hal.health().drivable
        hal.take_frames()
        for _ in range(50):  # 0.5 s of the same setpoint, written every 10 ms
            hal.write(WheelSetpoint(6.0, 6.0))
            hal.advance(5)
        frames = [f for _t, f in hal.take_frames()]
        hal.write(WheelSetpoint(5.0, 6.0))  # a change goes out at once
        changed = [f for _t, f in hal.take_frames()]
        # The drives were fed all along: the 0.2 s watchdog never expired.
        assert emulator.drive(0).state == p.AxisState.CLOSED_LOOP_CONTROL
        assert hal.health().drivable
    setpoints = [f for f in frames if f.arbitration_id & 0x1F == p.CMD_SET_INPUT_VEL]
    for node in (0, 1):
        assert len([f for f in setpoints if f.arbitration_id >> 5 == node]) == expected
    left = [f for f in changed if f.arbitration_id == p.arbitration_id(0, p.CMD_SET_INPUT_VEL)]
    assert struct_f32(left[0].data) == pytest.approx(-5.0 / (2 * math.pi), rel=1e-6)


def test_short_payloads_on_the_bus_are_ignored_not_fatal() -> None:
    # A third node puts truncated frames on the bus: an encoder estimate from a drive
    # we drive, a heartbeat, and a Set_Input_Vel to a drive. Both ends ignore them, like
    # bad frames on a wire, and the robot keeps running on the good ones.
    hal, emulator, _world = _bench("test-short")
    rogue = open_endpoint("virtual", "test-short")
    with hal:
        hal.advance(50)
        assert hal.health().drivable
        hal.write(WheelSetpoint(6.0, 6.0))
        hal.advance(5)
        for ident in (
            p.arbitration_id(1, p.CMD_GET_ENCODER_ESTIMATES),
            p.arbitration_id(1, p.CMD_HEARTBEAT),
            p.arbitration_id(0, p.CMD_SET_INPUT_VEL),
        ):
            rogue.send(RawFrame(ident, b"\x01\x02"))
        before = hal.read_wheels()
        hal.advance(1)  # an instant between the drives' frames: only the rogue ones
        assert hal.read_wheels() == before
        for _ in range(20):
            hal.write(WheelSetpoint(6.0, 6.0))
            hal.advance(5)
        assert hal.health().drivable
        assert emulator.drive(0).state == p.AxisState.CLOSED_LOOP_CONTROL
        assert hal.read_wheels().right_velocity > 1.0
    rogue.close()


def test_a_wrong_direction_sign_drives_the_wheel_backwards() -> None:
    # The host thinks the left motor is not mirrored; the robot then spins in place:
    # the sign in the config is what makes it drive straight.
    hal, _emulator, _world = _bench("test-sign", left_sign=1, mount_sign=-1)
    with hal:
        hal.advance(50)
        for _ in range(50):
            hal.write(WheelSetpoint(6.0, 6.0))
            hal.advance(5)
        truth = hal.ground_truth()
        assert abs(truth.x) < 0.02
        assert abs(truth.yaw) > 0.5


# -- faults ----------------------------------------------------------------------------


async def _fault_scenario(
    config: StackConfig,
    inject: Callable[[DriveEmulator], None],
    clear: Callable[[DriveEmulator], None] | None,
    *,
    fault: set[str],
    names: str,
    estop: bool,
    drive_first: bool = True,
) -> None:
    """Drive toward a goal, inject the fault, check detection and the reaction, clear
    it and check the logged recovery (``clear`` None: it must stay faulted)."""
    async with running_stack(config) as stack:
        system, hal = stack.system, stack.hal
        emulator = emulator_of(hal)
        wheel = system.subscribe(topics.WHEEL_CMD, WheelCommand, WATCH)
        state = system.subscribe(topics.NAV_STATE, NavState, WATCH)
        rosout = system.subscribe(topics.ROSOUT, Log, WATCH)
        diagnostics = system.subscribe(topics.DIAGNOSTICS, DiagnosticArray, WATCH)
        frames = system.subscribe(FRAMES_TOPIC, Frame, WATCH)
        goal = system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS, name="test")
        await goal.publish(PoseStamped(pose=Pose(position=Point(x=4.0, y=1.5))))
        if drive_first:
            await until(
                lambda: math.hypot(hal.ground_truth().vx_world, hal.ground_truth().vy_world) > 0.1,
                within=3.0,
                what="the robot drives over CAN",
            )
            inject(emulator)
        start = hal.ground_truth()
        await until(lambda: hal.health().faulted, within=2.0, what="fault detected")
        health = hal.health()
        detected = health.since
        assert health.fault in fault, health
        assert names in health.message
        await system.clock.sleep(0.3)

        # Base: zero within 2 control periods of detection, and from then on.
        cmds = [m for m in drain(wheel) if m.header.stamp.to_seconds() > detected - 1e-9]
        first_zero = next(m for m in cmds if m.left == 0.0 and m.right == 0.0)
        assert first_zero.header.stamp.to_seconds() <= detected + 2 * BASE_PERIOD + 1e-9
        late = [m for m in cmds if m.header.stamp.to_seconds() >= detected + 2 * BASE_PERIOD]
        assert late
        assert all(m.left == 0.0 and m.right == 0.0 for m in late)
        # Navigator: 'fault' within 2 of its periods.
        faults = [m for m in drain(state) if m.state == "fault"]
        assert faults[0].header.stamp.to_seconds() <= detected + 2 * NAV_PERIOD + 1e-9
        # Reported on /rosout and /diagnostics, naming the part.
        logs = drain(rosout)
        assert any(m.level == Log.ERROR and names in m.msg for m in logs), logs
        assert any(
            s.level == HealthLevel.ERROR and names in s.message
            for d in drain(diagnostics)
            for s in d.status
        )
        sent = [f for f in drain(frames) if f.header.stamp.to_seconds() >= detected - 1e-9]
        estops = {f.id >> 5 for f in sent if f.id & 0x1F == p.CMD_ESTOP}
        assert estops == (
            {config.hal.can.left.node_id, config.hal.can.right.node_id} if estop else set()
        )

        if clear is None:
            await system.clock.sleep(1.0)
            assert hal.health().faulted
            if not drive_first:  # it never moved: the drives never took a command
                end = hal.ground_truth()
                assert math.hypot(end.x - start.x, end.y - start.y) < 0.01
            return
        clear(emulator)
        await until(lambda: hal.health().drivable, within=3.0, what="recovery")
        assert hal.health().message.startswith("recovered from")
        await system.clock.sleep(0.2)
        logs = drain(rosout)
        assert any("recovering from" in m.msg and m.level == Log.WARN for m in logs), logs
        assert any("recovered from" in m.msg for m in logs)
        restart = [f for f in drain(frames) if f.id & 0x1F == p.CMD_CLEAR_ERRORS]
        assert {f.id >> 5 for f in restart} == {0, 1}
        await until(
            lambda: math.hypot(hal.ground_truth().vx_world, hal.ground_truth().vy_world) > 0.1,
            within=2.0,
            what="driving again after the recovery",
        )
        assert drain(state)[-1].state == "driving"


@pytest.mark.sim(wall_ceiling=60)
async def test_heartbeat_loss_is_detected_and_estops() -> None:
    await _fault_scenario(
        CAN,
        lambda emu: emu.silence_heartbeat(1),
        lambda emu: emu.silence_heartbeat(1, False),
        fault={"heartbeat_lost"},
        names="node 1 (right wheel): no heartbeat",
        estop=True,
    )


@pytest.mark.sim(wall_ceiling=60)
async def test_axis_error_is_detected_and_recovered_with_clear_errors() -> None:
    await _fault_scenario(
        CAN,
        lambda emu: emu.inject_axis_error(0, p.AxisError.DRV_FAULT),
        lambda emu: None,  # transient: Clear_Errors clears it
        fault={"axis_error"},
        names="node 0 (left wheel): axis error 0x00000020 (DRV_FAULT)",
        estop=True,
    )


def _drop(rate: float) -> Callable[[DriveEmulator], None]:
    def inject(emu: DriveEmulator) -> None:
        emu.faults.drop_rate = rate

    return inject


@pytest.mark.sim(wall_ceiling=60)
async def test_dropped_frames_are_detected() -> None:
    await _fault_scenario(
        CAN,
        _drop(0.4),
        _drop(0.0),
        fault={"frame_loss", "encoder_stale"},
        names="wheel)",
        estop=False,
    )


@pytest.mark.sim(wall_ceiling=60)
async def test_a_few_dropped_frames_are_tolerated() -> None:
    async with running_stack(CAN) as stack:
        await until(lambda: stack.hal.health().drivable, within=1.0)
        emulator = emulator_of(stack.hal)
        emulator.faults.drop_rate = 0.05
        await stack.system.clock.sleep(3.0)
        assert emulator.faults.dropped > 20
        assert stack.hal.health().drivable


def _delay(seconds: float) -> Callable[[DriveEmulator], None]:
    def inject(emu: DriveEmulator) -> None:
        emu.faults.delay = seconds

    return inject


@pytest.mark.sim(wall_ceiling=60)
async def test_delayed_frames_are_detected() -> None:
    await _fault_scenario(
        CAN,
        _delay(0.08),
        _delay(0.0),
        fault={"encoder_stale"},
        names="newest encoder estimate",
        estop=False,
    )


@pytest.mark.sim(wall_ceiling=60)
async def test_bus_off_is_detected_and_the_restart_recovers() -> None:
    await _fault_scenario(
        CAN,
        lambda emu: emu.set_bus_off(True),
        lambda emu: emu.set_bus_off(False),
        fault={"bus_off"},
        names="CAN bus-off",
        estop=False,
    )


@pytest.mark.sim(wall_ceiling=60)
async def test_a_wrong_node_id_at_startup_times_out_naming_it() -> None:
    config = apply_overrides(CAN, ["hal.can.left.node_id=9"])
    await _fault_scenario(
        config,
        lambda emu: None,  # the drives answer on 0 and 1; the host expects 9 and 1
        None,
        fault={"startup_timeout"},
        names="node 9 (left wheel): no heartbeat within 1 s",
        estop=True,
        drive_first=False,
    )


# -- the command line ---------------------------------------------------------------------


def test_cli_runs_the_acceptance_scenario_over_can(tmp_path: Path) -> None:
    from otonav.cli import main

    assert main(["run", "--set", "hal.kind=can", "--out", str(tmp_path), "--no-record"]) == 0
    assert '"passed": true' in (tmp_path / "summary.json").read_text()


def test_cli_without_python_can_names_the_extra(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import sys

    from otonav.cli import main

    for name in [m for m in sys.modules if m == "can" or m.startswith(("can.", "otonav.hal.can"))]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "can", None)  # import can -> ImportError
    assert main(["run", "--set", "hal.kind=can", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.strip().splitlines() == [
        "otonav: error: hal.kind: can needs python-can (can is missing): pip install 'otonav[can]'"
    ]


def test_a_fault_from_the_cli_starts_at_its_time(tmp_path: Path) -> None:
    from otonav.cli import main
    from otonav.msgs import HardwareStatus
    from otonav.record._reader import read_messages

    args = ["run", "--out", str(tmp_path), "--set", "hal.kind=can",
            "--set", "hal.sim.faults.axis_error.node_id=1",
            "--set", "hal.sim.faults.axis_error.at=3"]  # fmt: skip
    main(args)
    faulted = [
        t
        for _topic, t, m in read_messages(tmp_path / "recording.mcap", ["/hardware/status"])
        if m.level >= HardwareStatus().level + 2  # ERROR: a fault
    ]
    assert faulted
    assert 3.0 <= faulted[0] <= 3.0 + 0.05  # within an encoder period or two of 3 s
