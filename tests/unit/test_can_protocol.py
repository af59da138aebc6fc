"""Layer 1: the ODrive CAN Simple codec, the emulated axis, and the drive monitor:
pure logic, no bus."""

from __future__ import annotations

import math
import struct

import pytest

from otonav.hal import HealthLevel
from otonav.hal.can import _protocol as p
from otonav.hal.can._monitor import Action, DriveMonitor, MonitorLimits, NodeLabel, Phase
from otonav.hal.sim._odrive import AxisModel, AxisParams

pytestmark = pytest.mark.unit


def test_set_input_vel_matches_the_odrive_docs_worked_example() -> None:
    # ODrive docs (can-protocol): node 1, Set_Input_Vel(-2.5, 0.25) -> 0x02D, these bytes.
    ident, data = p.set_input_vel(1, -2.5, 0.25)
    assert ident == 0x02D
    assert data == bytes.fromhex("000020c00000803e")
    assert p.decode_set_input_vel(data) == (-2.5, 0.25)


@pytest.mark.parametrize(
    ("node", "cmd", "ident"),
    [
        (0, p.CMD_HEARTBEAT, 0x001),
        (3, p.CMD_SET_AXIS_STATE, 0x067),
        (63, p.CMD_CLEAR_ERRORS, 0x7F8),
    ],
)
def test_arbitration_id_is_node_shifted_by_five_or_cmd(node: int, cmd: int, ident: int) -> None:
    assert p.arbitration_id(node, cmd) == ident
    assert p.split_id(ident) == (node, cmd)


def test_node_ids_out_of_range_are_refused() -> None:
    with pytest.raises(ValueError, match=r"0\.\.63"):
        p.arbitration_id(64, p.CMD_ESTOP)


def test_payload_layouts_are_little_endian() -> None:
    assert p.set_axis_state(2, p.AxisState.CLOSED_LOOP_CONTROL) == (0x047, b"\x08\x00\x00\x00")
    assert p.estop(5) == (0x0A2, b"")
    assert p.clear_errors(1) == (0x038, b"\x00")
    ident, data = p.encode_heartbeat(1, p.Heartbeat(0x2000040, 1, 0, 1))
    assert ident == 0x021
    assert data == struct.pack("<IBBBx", 0x2000040, 1, 0, 1)
    assert p.decode_heartbeat(data) == p.Heartbeat(0x2000040, 1, 0, 1)
    ident, data = p.encode_encoder_estimates(0, p.EncoderEstimates(12.5, -0.75))
    assert (ident, data) == (0x009, struct.pack("<ff", 12.5, -0.75))
    assert p.unpack_two_f32(data) == (12.5, -0.75)


def test_error_names_list_every_bit() -> None:
    assert p.error_names(0) == "NONE"
    assert p.error_names(0x2000040) == "MISSING_INPUT|ESTOP_REQUESTED"
    assert p.error_names(0x80000000) == "0x80000000"


# -- the emulated axis -------------------------------------------------------------------


def _state(axis: AxisModel) -> p.AxisState:
    return axis.state


def _error(axis: AxisModel) -> p.AxisError:
    return axis.error


def test_axis_arms_after_arm_time_then_follows_the_clamped_setpoint() -> None:
    axis = AxisModel(AxisParams(0, vel_limit=5.0, vel_ramp_rate=1000.0, arm_time=0.01))
    axis.request_state(p.AxisState.CLOSED_LOOP_CONTROL, 0.0)
    axis.set_input_vel(9.0, 0.0)
    assert axis.update(0.005, 0.0) == 0.0
    assert _state(axis) == p.AxisState.IDLE
    axis.update(0.01, 0.0)
    assert _state(axis) == p.AxisState.CLOSED_LOOP_CONTROL
    axis.set_input_vel(9.0, 0.01)
    assert axis.update(0.02, 0.0) == 5.0  # clamped to vel_limit


def test_axis_ramp_limits_the_setpoint_slew_in_vel_ramp_mode() -> None:
    axis = AxisModel(AxisParams(0, vel_ramp_rate=10.0, arm_time=0.0))
    axis.set_controller_mode(p.ControlMode.VELOCITY_CONTROL, p.InputMode.VEL_RAMP)
    axis.request_state(p.AxisState.CLOSED_LOOP_CONTROL, 0.0)
    axis.update(0.0, 0.0)
    assert axis.set_input_vel(4.0, 0.0) is False  # the ramp follows as time passes
    assert axis.update(0.0, 0.0) == 0.0  # no time passed: no slew yet
    assert axis.update(0.1, 0.0) == pytest.approx(1.0)  # 10 turns/s^2 * 0.1 s
    assert axis.update(0.2, 0.0) == pytest.approx(2.0)


def test_passthrough_takes_the_input_at_once_and_inactive_ignores_it() -> None:
    # An ODrive's input modes: PASSTHROUGH (what the CAN interface selects) has no
    # ramp, whatever vel_ramp_rate says; INACTIVE ignores new input.
    axis = AxisModel(AxisParams(0, vel_limit=5.0, vel_ramp_rate=10.0, arm_time=0.0))
    axis.set_controller_mode(p.ControlMode.VELOCITY_CONTROL, p.InputMode.PASSTHROUGH)
    axis.request_state(p.AxisState.CLOSED_LOOP_CONTROL, 0.0)
    axis.update(0.0, 0.0)
    assert axis.set_input_vel(4.0, 0.0) is True  # the caller updates now
    assert axis.update(0.0, 0.0) == 4.0
    axis.set_input_vel(-9.0, 0.01)
    assert axis.update(0.01, 0.0) == -5.0  # still clamped to vel_limit
    axis.set_controller_mode(p.ControlMode.VELOCITY_CONTROL, p.InputMode.INACTIVE)
    axis.set_input_vel(2.0, 0.02)
    assert axis.update(0.03, 0.0) == -5.0


def test_watchdog_expires_without_commands_and_disarms() -> None:
    axis = AxisModel(AxisParams(0, watchdog_timeout=0.2, arm_time=0.0))
    axis.request_state(p.AxisState.CLOSED_LOOP_CONTROL, 0.0)
    axis.update(0.0, 0.0)
    axis.set_input_vel(1.0, 0.0)
    axis.update(0.19, 0.0)
    assert _state(axis) == p.AxisState.CLOSED_LOOP_CONTROL
    assert axis.update(0.21, 0.0) == 0.0
    assert _state(axis) == p.AxisState.IDLE
    assert axis.error & p.AxisError.WATCHDOG_TIMER_EXPIRED
    axis.request_state(p.AxisState.CLOSED_LOOP_CONTROL, 0.3)  # refused: error active
    axis.update(0.4, 0.0)
    assert _state(axis) == p.AxisState.IDLE
    axis.clear_errors()
    axis.request_state(p.AxisState.CLOSED_LOOP_CONTROL, 0.4)
    axis.update(0.4, 0.0)
    assert _state(axis) == p.AxisState.CLOSED_LOOP_CONTROL


def test_estop_and_overspeed_raise_their_errors() -> None:
    axis = AxisModel(AxisParams(0, vel_limit=2.0, arm_time=0.0))
    axis.request_state(p.AxisState.CLOSED_LOOP_CONTROL, 0.0)
    axis.update(0.0, 0.0)
    axis.update(0.01, 3.5)  # measured 3.5 turns/s > 1.5 * 2.0
    assert _error(axis) == p.AxisError.VELOCITY_LIMIT_VIOLATION
    axis.clear_errors()
    axis.estop()
    assert _error(axis) == p.AxisError.ESTOP_REQUESTED
    assert _state(axis) == p.AxisState.IDLE


# -- the monitor ---------------------------------------------------------------------------

NODES = (NodeLabel(0, "left wheel"), NodeLabel(1, "right wheel"))
CLOSED = int(p.AxisState.CLOSED_LOOP_CONTROL)


def _running(limits: MonitorLimits = MonitorLimits()) -> DriveMonitor:
    monitor = DriveMonitor(NODES, limits)
    monitor.requested(0.0)
    for node in (0, 1):
        monitor.heartbeat(node, 0, CLOSED, 0.1)
        monitor.encoder(node, 0.1)
    assert monitor.check(0.1) == ()
    assert monitor.phase is Phase.RUNNING
    return monitor


def test_startup_waits_for_a_heartbeat_after_the_request() -> None:
    monitor = DriveMonitor(NODES)
    monitor.requested(0.5)
    monitor.heartbeat(0, 0, CLOSED, 0.5)  # the same instant as the request: too early
    monitor.heartbeat(1, 0, CLOSED, 0.6)
    monitor.check(0.6)
    assert monitor.phase is Phase.STARTING
    assert not monitor.health.ready
    monitor.heartbeat(0, 0, CLOSED, 0.6)
    monitor.check(0.6)
    assert monitor.health.drivable
    assert monitor.health.since == 0.6


def test_startup_timeout_names_the_silent_node_and_who_did_answer() -> None:
    monitor = DriveMonitor((NodeLabel(9, "left wheel"), NodeLabel(1, "right wheel")))
    monitor.requested(0.0)
    monitor.heartbeat(0, 0, 1, 0.1)  # a drive we do not drive
    monitor.heartbeat(1, 0, CLOSED, 0.1)
    assert monitor.check(0.9) == ()
    assert monitor.check(1.01) == (Action.ESTOP_ALL,)
    health = monitor.health
    assert health.level == HealthLevel.ERROR
    assert health.fault == "startup_timeout"
    assert "node 9 (left wheel): no heartbeat" in health.message
    assert "node ids [0]" in health.message
    assert "node 1" not in health.message.split(";")[0]


def test_heartbeat_loss_faults_then_recovers_only_after_the_delay() -> None:
    limits = MonitorLimits(heartbeat_timeout=0.25, recovery_delay=0.3)
    monitor = _running(limits)
    t = 0.1
    while t < 0.36:
        t = round(t + 0.01, 3)
        monitor.heartbeat(0, 0, CLOSED, t)
        for node in (0, 1):
            monitor.encoder(node, t)
        actions = monitor.check(t)
    assert actions == (Action.ESTOP_ALL,)
    assert monitor.health.fault == "heartbeat_lost"
    assert "node 1 (right wheel)" in monitor.health.message
    monitor.heartbeat(1, 0x2000000, 1, 0.4)  # back, estopped
    monitor.heartbeat(0, 0x2000000, 1, 0.4)
    assert monitor.check(0.4) == ()
    for node in (0, 1):
        monitor.heartbeat(node, 0x2000000, 1, 0.6)
    assert monitor.check(0.69) == ()  # not yet clear for 0.3 s
    assert monitor.check(0.70) == (Action.START_ALL,)
    assert monitor.phase is Phase.RECOVERING
    assert "recovering from heartbeat_lost (attempt 1)" in monitor.health.message
    for node in (0, 1):
        monitor.heartbeat(node, 0, CLOSED, 0.8)
    monitor.check(0.8)
    assert monitor.health.drivable
    assert monitor.health.message.startswith("recovered from heartbeat_lost")


def test_axis_error_in_a_heartbeat_is_a_fault_naming_the_error() -> None:
    monitor = _running()
    monitor.heartbeat(0, int(p.AxisError.DRV_FAULT), 1, 0.11)
    assert monitor.check(0.11) == (Action.ESTOP_ALL,)
    assert monitor.health.fault == "axis_error"
    assert "node 0 (left wheel): axis error 0x00000020 (DRV_FAULT), state IDLE" in (
        monitor.health.message
    )


def test_frame_loss_over_the_window_is_a_fault() -> None:
    monitor = _running(MonitorLimits(max_frame_loss=0.2, loss_window=0.5, encoder_timeout=1.0))
    fault = ""
    for k in range(11, 120):
        t = k / 100
        for node in (0, 1):
            monitor.heartbeat(node, 0, CLOSED, t)
            if k % 3:  # a third of the encoder frames lost
                monitor.encoder(node, t)
        if monitor.check(t):
            fault = monitor.health.fault
            break
    assert fault == "frame_loss"
    assert "% of encoder frames lost over the last 0.5 s" in monitor.health.message


def test_recovery_gives_up_after_max_attempts() -> None:
    monitor = _running(MonitorLimits(recovery_delay=0.0, max_recovery_attempts=2))
    t = 0.11
    for _ in range(3):
        for node in (0, 1):
            monitor.heartbeat(node, int(p.AxisError.DRV_FAULT), 1, t)
        monitor.check(t)  # fault, or the recovery's startup seeing the error again
        t = round(t + 1.5, 3)
        for node in (0, 1):
            monitor.heartbeat(node, int(p.AxisError.DRV_FAULT), 1, t)
        monitor.check(t)
    assert "recovery from axis_error failed" in monitor.health.message
    monitor.check(t)
    assert monitor.phase is Phase.FAULT
    assert "gave up after 2 recovery attempts" in monitor.health.message
    assert math.isfinite(monitor.health.since)


class _CheckedEveryInstant(DriveMonitor):
    """The reference: the full check at every instant (no quiet interval)."""

    def check(self, now: float) -> tuple[Action, ...]:
        self._quiet_until = -math.inf
        return super().check(now)


@pytest.mark.parametrize("seed", range(6))
def test_skipping_quiet_checks_detects_every_fault_at_the_same_instant(seed: int) -> None:
    # The monitor skips the running check while no condition can hold; the same
    # traffic (random gaps, losses, errors, recoveries) must give the same actions and
    # health at every 10 ms instant as a check of everything every time.
    import random

    rng = random.Random(seed)
    limits = MonitorLimits(recovery_delay=0.05, max_recovery_attempts=100)
    gated, reference = DriveMonitor(NODES, limits), _CheckedEveryInstant(NODES, limits)
    silent = {0: 0, 1: 0}  # instants left without heartbeats / encoders, per node
    mute = {0: 0, 1: 0}
    faults = set()
    for monitor in (gated, reference):
        monitor.requested(0.0)
    for k in range(1, 3000):
        t = k / 100
        events: list[tuple[str, int, int, int]] = []
        for node in (0, 1):
            roll = rng.random()
            if roll < 0.004:
                silent[node] = rng.randint(5, 40)
            elif roll < 0.008:
                mute[node] = rng.randint(2, 12)
            if mute[node]:
                mute[node] -= 1
            elif rng.random() > 0.1:  # 10 % of encoder frames lost
                events.append(("encoder", node, 0, 0))
            if silent[node]:
                silent[node] -= 1
            elif k % 10 == node:  # heartbeats every 100 ms, nodes out of phase
                error = int(p.AxisError.DRV_FAULT) if rng.random() < 0.03 else 0
                state = 1 if error or rng.random() < 0.01 else CLOSED
                events.append(("heartbeat", node, error, state))
        for monitor in (gated, reference):
            for kind, node, error, state in events:
                if kind == "encoder":
                    monitor.encoder(node, t)
                else:
                    monitor.heartbeat(node, error, state, t)
        actions = gated.check(t)
        assert actions == reference.check(t), t
        assert gated.health == reference.health, t
        if gated.health.fault:
            faults.add(gated.health.fault)
    # The traffic did exercise the faults the quiet interval could hide.
    assert {"encoder_stale", "heartbeat_lost", "axis_error"} <= faults
