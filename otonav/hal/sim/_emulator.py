"""Two ODrive-like drives at the far end of a CAN bus, turning the MuJoCo wheels.

Everything runs on sim time, driven by whoever steps the world (the CAN interface's
``advance``): :meth:`DriveEmulator.exchange` is called at every instant the world
stopped at, and :meth:`DriveEmulator.next_event_tick` says the next instant it needs
(its next cyclic frame or a delayed frame coming due). No thread, no wall clock.

At each exchange: receive frames (Set_Axis_State, Set_Controller_Mode, Set_Input_Vel,
Estop, Clear_Errors), update both axes (:class:`~otonav.hal.sim._odrive.AxisModel`),
put their velocity setpoints on the world's wheels (rad/s), then send what is due:
Get_Encoder_Estimates every ``encoder_period`` and the heartbeat every
``heartbeat_period`` (``hal.sim``: 10 ms and 100 ms) of sim time, on whole ticks
counted from tick 0.

The wheels are the world's: a drive's encoder reads the wheel joint, converted to motor
turns through its mounting ``sign`` and ``gear_ratio`` (the physical robot).

Faults (:class:`BusFaults` and the methods below) are injected here, on the bus or in a
drive: dropped and delayed frames (seeded, so deterministic), bus-off, a drive whose
heartbeat stops, an axis error. This package is test equipment: robot code never
imports it (an import-linter contract).
"""

from __future__ import annotations

import heapq
import math
import struct
from dataclasses import dataclass

import numpy as np

from otonav.hal._interface import RobotHardwareInterface
from otonav.hal._types import WheelSetpoint
from otonav.hal.can import _protocol as p
from otonav.hal.can._bus import CAN_ERR_BUSOFF, CAN_ERR_RESTARTED, CanEndpoint, RawFrame
from otonav.hal.sim._odrive import AxisModel, AxisParams
from otonav.hal.sim._schedule import BusFaults, FaultPlan

__all__ = ["BusFaults", "DriveEmulator", "DriveMount"]

_TWO_PI = 2.0 * math.pi
_pack_two_f32 = p.pack_two_f32


@dataclass(frozen=True, slots=True)
class DriveMount:
    """How a drive's motor is mounted on its wheel: wheel rad = sign * 2 pi * turns / gear."""

    sign: int
    gear_ratio: float
    """Motor turns per wheel revolution."""

    def __post_init__(self) -> None:
        if self.sign not in (1, -1) or not self.gear_ratio > 0:
            raise ValueError(f"DriveMount needs sign +-1 and gear_ratio > 0, got {self}")


class _Drive:
    __slots__ = (
        "axis",
        "encoder_id",
        "gear",
        "heartbeat_id",
        "heartbeat_silent",
        "k",
        "node_id",
        "sign",
    )

    def __init__(self, params: AxisParams, mount: DriveMount) -> None:
        self.axis = AxisModel(params)
        self.sign, self.gear = mount.sign, mount.gear_ratio
        self.node_id = params.node_id
        self.heartbeat_silent = False
        # Precomputed for the 10 ms encoder frames: the id, and wheel rad -> motor turns.
        self.encoder_id = p.arbitration_id(params.node_id, p.CMD_GET_ENCODER_ESTIMATES)
        self.heartbeat_id = p.arbitration_id(params.node_id, p.CMD_HEARTBEAT)
        self.k = mount.sign * mount.gear_ratio / _TWO_PI


class DriveEmulator:
    """Two drives (left, right) on ``endpoint``, driving ``world``'s wheels.

    ``seed`` seeds the fault injection's random numbers (nothing else is random).
    """

    def __init__(
        self,
        endpoint: CanEndpoint,
        world: RobotHardwareInterface,
        left: AxisParams,
        right: AxisParams,
        *,
        left_mount: DriveMount,
        right_mount: DriveMount,
        heartbeat_period: float,
        encoder_period: float,
        seed: int = 0,
        schedule: FaultPlan | None = None,
    ) -> None:
        if left.node_id == right.node_id:
            raise ValueError(f"both drives have node id {left.node_id}")
        tick = world.tick
        self._hb_ticks = max(1, round(heartbeat_period / tick))
        self._enc_ticks = max(1, round(encoder_period / tick))
        self._endpoint = endpoint
        self._world = world
        self._tick = tick
        self.drives = (_Drive(left, left_mount), _Drive(right, right_mount))
        self._by_node = {d.node_id: d for d in self.drives}
        self.faults = BusFaults()
        # Faults on a timetable (hal.sim.faults); None: only what a caller injects.
        self._plan = schedule if schedule and not schedule.empty else None
        self._edges = self._plan.times() if self._plan else []  # each start and end, s
        self._next_edge = 0  # the first not yet applied
        self._axis_error_done = False
        for node in (schedule.axis_error_node, schedule.heartbeat_node) if schedule else ():
            if node is not None and node not in self._by_node:
                raise ValueError(
                    f"a scheduled fault names drive {node}; the drives are {sorted(self._by_node)}"
                )
        # Made at the first injected fault: numpy.random is imported for it alone
        # (~6 ms of CPU per run over CAN, measured; the MuJoCo stack never imports it).
        self._seed = seed
        self._rng: np.random.Generator | None = None
        self._bus_off = False
        self._sent_at = -1  # last tick whose cyclic frames went out
        self._updated_at = -1  # last tick the axes were updated and the wheels driven
        self._seq = 0
        # Delayed frames: (due tick, seq, outbound?, frame, sim time it was sent).
        self._held: list[tuple[int, int, bool, RawFrame, float]] = []
        self._last_cmd = (math.nan, math.nan)

    # -- fault injection -----------------------------------------------------------------

    def drive(self, node_id: int) -> AxisModel:
        """The axis answering on ``node_id`` (for tests and fault injection)."""
        return self._by_node[node_id].axis

    def silence_heartbeat(self, node_id: int, silent: bool = True) -> None:
        """Stop (or resume) the heartbeat of drive ``node_id``; it still obeys commands."""
        self._by_node[node_id].heartbeat_silent = silent

    def inject_axis_error(self, node_id: int, code: int = p.AxisError.DRV_FAULT) -> None:
        """Drive ``node_id`` reports ``code`` and disarms, until Clear_Errors."""
        self._by_node[node_id].axis.raise_error(code)

    def set_bus_off(self, off: bool) -> None:
        """The bus goes bus-off (nothing passes; the host's controller reports
        CAN_ERR_BUSOFF) or restarts (CAN_ERR_RESTARTED), like SocketCAN with restart-ms."""
        if off == self._bus_off:
            return
        t = self._world.ticks * self._tick
        error = CAN_ERR_BUSOFF if off else CAN_ERR_RESTARTED
        self._endpoint.send(RawFrame(error, bytes(8), is_error=True), t)
        self._bus_off = off

    def close(self) -> None:
        """Leave the bus. Idempotent."""
        self._endpoint.close()

    # -- time ----------------------------------------------------------------------------

    def next_event_tick(self, now: int) -> int:
        """The first tick after ``now`` at which this emulator must exchange frames."""
        nxt = (now // self._enc_ticks + 1) * self._enc_ticks
        if self._held and self._held[0][0] < nxt:
            nxt = max(now + 1, self._held[0][0])
        return nxt

    def exchange(self, now: int) -> None:
        """Receive, update the drives and the wheels, send what is due at tick ``now``.

        Called again at an instant already exchanged (the host sent commands since),
        the axes are updated again only if a command changed their state or a setpoint
        (a Set_Input_Vel in PASSTHROUGH); in VEL_RAMP a Set_Input_Vel alone moves
        nothing before time passes (the ramp is ``vel_ramp_rate * dt`` and dt is 0)."""
        t = now * self._tick
        if self._next_edge < len(self._edges) and t >= self._edges[self._next_edge]:
            self._apply_plan(t)
        changed = False
        incoming = self._endpoint.poll()
        if incoming and not self._bus_off:  # nothing crosses a bus-off bus
            lossy = self.faults.lossy
            for frame in incoming:
                if lossy and self._lose_or_hold(frame, now, outbound=False):
                    continue
                changed |= self._handle(frame, t)
        held = self._held
        while held and held[0][0] <= now:
            _, _, outbound, frame, sent_at = heapq.heappop(held)
            if self._bus_off:
                continue
            if outbound:
                # It keeps the time its drive sent it: the delay stands for a queue
                # between the controller that stamped the frame and the host (a USB
                # adapter's buffer, a socket nobody drains), which SocketCAN's receive
                # timestamps show. The host judges the data's age by it (issue 27).
                self._endpoint.send(frame, sent_at)
            else:
                changed |= self._handle(frame, t)
        if now == self._updated_at and not changed:
            return
        self._updated_at = now
        # The drives' update and the wheels' setpoints, inline: this runs at every 10 ms
        # instant. Wheel rad/s -> motor turns/s and back (the arithmetic is the
        # recording's bytes).
        wheels = self._world.wheel_values()
        left, right = self.drives
        turns_l = left.axis.update(t, left.sign * wheels[2] * left.gear / _TWO_PI)
        turns_r = right.axis.update(t, right.sign * wheels[3] * right.gear / _TWO_PI)
        cmd = (
            left.sign * turns_l * _TWO_PI / left.gear,
            right.sign * turns_r * _TWO_PI / right.gear,
        )
        if cmd != self._last_cmd:
            self._last_cmd = cmd
            self._world.write(WheelSetpoint(cmd[0], cmd[1]))
        if now == self._sent_at or self._bus_off:
            return
        self._sent_at = now
        if now % self._enc_ticks == 0:
            self._send_encoders(now, t, wheels)
        if now % self._hb_ticks == 0:
            self._send_heartbeats(now, t)

    # -- internals -----------------------------------------------------------------------

    def _apply_plan(self, t: float) -> None:
        """Bring the faults to what the plan says at ``t`` (an edge is due)."""
        while self._next_edge < len(self._edges) and self._edges[self._next_edge] <= t:
            self._next_edge += 1
        plan, faults = self._plan, self.faults
        assert plan is not None
        faults.drop_rate = plan.drop_rate if plan.drop.holds(t) else 0.0
        on = plan.delayed.holds(t)
        faults.delay, faults.jitter = (plan.delay, plan.jitter) if on else (0.0, 0.0)
        if plan.bus_off is not None:
            self.set_bus_off(plan.bus_off.holds(t))
        if plan.heartbeat_node is not None:
            self.silence_heartbeat(plan.heartbeat_node, plan.heartbeat_lost.holds(t))
        node = plan.axis_error_node
        if node is not None and not self._axis_error_done and t >= plan.axis_error_at:
            self._axis_error_done = True
            self.inject_axis_error(node, plan.axis_error_code)

    def _lose_or_hold(self, frame: RawFrame, now: int, *, outbound: bool) -> bool:
        """Apply drop/delay to ``frame``: True if it is not to be used now."""
        faults = self.faults
        rng = self._rng
        if rng is None:
            rng = self._rng = np.random.default_rng(self._seed)
        if faults.drop_rate > 0.0 and rng.random() < faults.drop_rate:
            faults.dropped += 1
            return True
        if faults.delay > 0.0 or faults.jitter > 0.0:
            extra = faults.jitter * rng.random() if faults.jitter > 0.0 else 0.0
            due = now + max(1, round((faults.delay + extra) / self._tick))
            self._seq += 1
            heapq.heappush(self._held, (due, self._seq, outbound, frame, now * self._tick))
            return True
        return False

    def _transmit(self, frame: RawFrame, now: int, t: float) -> None:
        if not (self.faults.lossy and self._lose_or_hold(frame, now, outbound=True)):
            self._endpoint.send(frame, t)

    def _handle(self, frame: RawFrame, t: float) -> bool:
        """Apply one command frame; True if it may have changed an axis' state or
        setpoint (any command but a Set_Input_Vel the ramp will follow later)."""
        if frame.is_error or frame.is_remote:
            return False
        ident = frame.arbitration_id
        drive = self._by_node.get(ident >> 5 & p.MAX_NODE_ID)
        if drive is None:
            return False
        cmd = ident & 0x1F
        axis, data = drive.axis, frame.data
        try:
            if cmd == p.CMD_SET_INPUT_VEL:
                # In PASSTHROUGH the setpoint takes the input now, like a real drive's
                # next control cycle (8 kHz): the wheels are driven at this instant.
                return axis.set_input_vel(p.unpack_two_f32(data)[0], t)
            if cmd == p.CMD_SET_AXIS_STATE:
                axis.request_state(p.decode_set_axis_state(data), t)
            elif cmd == p.CMD_ESTOP:
                axis.estop()
            elif cmd == p.CMD_CLEAR_ERRORS:
                axis.clear_errors()
            elif cmd == p.CMD_SET_CONTROLLER_MODE:
                axis.set_controller_mode(*p.decode_set_controller_mode(data))
            else:
                return False
        except (ValueError, struct.error):  # a short payload: ignored
            return False
        return True

    def _send_encoders(self, now: int, t: float, wheels: tuple[float, float, float, float]) -> None:
        left, right = self.drives
        position_l, position_r, velocity_l, velocity_r = wheels
        kl, kr = left.k, right.k
        data_l = _pack_two_f32(position_l * kl, velocity_l * kl)
        data_r = _pack_two_f32(position_r * kr, velocity_r * kr)
        if self.faults.lossy:
            self._transmit(RawFrame(left.encoder_id, data_l), now, t)
            self._transmit(RawFrame(right.encoder_id, data_r), now, t)
            return
        # The hot path (two frames every 10 ms): straight onto the bus, no RawFrame.
        send = self._endpoint.send_data
        send(left.encoder_id, data_l, t)
        send(right.encoder_id, data_r, t)

    def _send_heartbeats(self, now: int, t: float) -> None:
        for drive in self.drives:
            if drive.heartbeat_silent:
                continue
            axis = drive.axis
            data = p.pack_heartbeat(int(axis.error), int(axis.state))
            self._transmit(RawFrame(drive.heartbeat_id, data), now, t)
