"""The ODrive "CAN Simple" protocol: arbitration ids and payloads, as plain functions.

No python-can here: frames are ``(arbitration_id, data)`` pairs, so the drive emulator
(``otonav.hal.sim``) and the tests share one codec with the interface.

* 11-bit id = ``node_id << 5 | cmd_id``; node ids 0..63 (ODrive docs, can-protocol).
* Payloads are little-endian; floats are IEEE-754 float32; velocities in turns/s,
  positions in turns (motor side: the interface converts to wheel radians).
* Worked example from the ODrive docs: node 1, ``Set_Input_Vel(-2.5, 0.25)`` is id 0x02D
  with data ``00 00 20 c0 00 00 80 3e`` (a unit test checks exactly this).

The codec is :mod:`struct` with precompiled layouts, not cantools + a DBC: the six
messages are fixed little-endian layouts, and the hot path (300+ frames per simulated
second) cannot afford a general codec (see docs/adr, "CAN interface").
"""

from __future__ import annotations

import enum
import struct
from dataclasses import dataclass
from typing import Final

__all__ = [
    "CMD_CLEAR_ERRORS",
    "CMD_ESTOP",
    "CMD_GET_ENCODER_ESTIMATES",
    "CMD_HEARTBEAT",
    "CMD_SET_AXIS_STATE",
    "CMD_SET_CONTROLLER_MODE",
    "CMD_SET_INPUT_VEL",
    "MAX_NODE_ID",
    "AxisError",
    "AxisState",
    "ControlMode",
    "EncoderEstimates",
    "Heartbeat",
    "InputMode",
    "arbitration_id",
    "clear_errors",
    "decode_encoder_estimates",
    "decode_heartbeat",
    "decode_set_axis_state",
    "decode_set_controller_mode",
    "decode_set_input_vel",
    "encode_encoder_estimates",
    "encode_heartbeat",
    "error_names",
    "estop",
    "pack_heartbeat",
    "pack_two_f32",
    "set_axis_state",
    "set_controller_mode",
    "set_input_vel",
    "split_id",
    "unpack_heartbeat",
    "unpack_two_f32",
]

CMD_HEARTBEAT: Final = 0x001
CMD_ESTOP: Final = 0x002
CMD_SET_AXIS_STATE: Final = 0x007
CMD_GET_ENCODER_ESTIMATES: Final = 0x009
CMD_SET_CONTROLLER_MODE: Final = 0x00B
CMD_SET_INPUT_VEL: Final = 0x00D
CMD_CLEAR_ERRORS: Final = 0x018

MAX_NODE_ID: Final = 0x3F
"""Node ids are 6 bits (0..63)."""


class AxisState(enum.IntEnum):
    """ODrive axis states (the two an otonav wheel uses, and the boot state)."""

    UNDEFINED = 0
    IDLE = 1
    CLOSED_LOOP_CONTROL = 8


class ControlMode(enum.IntEnum):
    VOLTAGE_CONTROL = 0
    TORQUE_CONTROL = 1
    VELOCITY_CONTROL = 2
    POSITION_CONTROL = 3


class InputMode(enum.IntEnum):
    INACTIVE = 0
    PASSTHROUGH = 1
    VEL_RAMP = 2


class AxisError(enum.IntFlag):
    """ODrive (firmware 0.6) ``ODriveError`` bits, as reported in the heartbeat."""

    NONE = 0
    INITIALIZING = 0x1
    SYSTEM_LEVEL = 0x2
    TIMING_ERROR = 0x4
    MISSING_ESTIMATE = 0x8
    BAD_CONFIG = 0x10
    DRV_FAULT = 0x20
    MISSING_INPUT = 0x40
    DC_BUS_OVER_VOLTAGE = 0x100
    DC_BUS_UNDER_VOLTAGE = 0x200
    DC_BUS_OVER_CURRENT = 0x400
    DC_BUS_OVER_REGEN_CURRENT = 0x800
    CURRENT_LIMIT_VIOLATION = 0x1000
    MOTOR_OVER_TEMP = 0x2000
    INVERTER_OVER_TEMP = 0x4000
    VELOCITY_LIMIT_VIOLATION = 0x8000
    POSITION_LIMIT_VIOLATION = 0x10000
    WATCHDOG_TIMER_EXPIRED = 0x1000000
    ESTOP_REQUESTED = 0x2000000
    SPINOUT_DETECTED = 0x4000000
    BRAKE_RESISTOR_DISARMED = 0x8000000
    THERMISTOR_DISCONNECTED = 0x10000000
    CALIBRATION_ERROR = 0x40000000


def error_names(code: int) -> str:
    """``0x2000040`` -> ``"MISSING_INPUT|ESTOP_REQUESTED"``; unknown bits in hex."""
    names = [flag.name for flag in AxisError if flag and code & flag and flag.name]
    known = 0
    for flag in AxisError:
        if code & flag:
            known |= flag
    if code & ~known:
        names.append(f"0x{code & ~known:x}")
    return "|".join(names) or "NONE"


def arbitration_id(node_id: int, cmd: int) -> int:
    """The 11-bit id of ``cmd`` for ``node_id`` (0..63)."""
    if not 0 <= node_id <= MAX_NODE_ID:
        raise ValueError(f"ODrive node id must be 0..{MAX_NODE_ID}, got {node_id}")
    return node_id << 5 | cmd


def split_id(arbitration_id: int) -> tuple[int, int]:
    """``(node_id, cmd)`` of an 11-bit CAN Simple id."""
    return arbitration_id >> 5 & MAX_NODE_ID, arbitration_id & 0x1F


_U32: Final = struct.Struct("<I")
_TWO_U32: Final = struct.Struct("<II")
_TWO_F32: Final = struct.Struct("<ff")
_HEARTBEAT: Final = struct.Struct("<IBBBx")
_HEARTBEAT_HEAD: Final = struct.Struct("<IB")


# -- host -> drive --------------------------------------------------------------------


def set_axis_state(node_id: int, state: AxisState) -> tuple[int, bytes]:
    return arbitration_id(node_id, CMD_SET_AXIS_STATE), _U32.pack(state)


def decode_set_axis_state(data: bytes) -> int:
    return int(_U32.unpack_from(data)[0])


def set_controller_mode(node_id: int, control: ControlMode, inp: InputMode) -> tuple[int, bytes]:
    return arbitration_id(node_id, CMD_SET_CONTROLLER_MODE), _TWO_U32.pack(control, inp)


def decode_set_controller_mode(data: bytes) -> tuple[int, int]:
    control, inp = _TWO_U32.unpack_from(data)
    return int(control), int(inp)


def set_input_vel(node_id: int, vel: float, torque_ff: float = 0.0) -> tuple[int, bytes]:
    """Velocity setpoint, turns/s (motor side), and a torque feed-forward, N m."""
    return arbitration_id(node_id, CMD_SET_INPUT_VEL), _TWO_F32.pack(vel, torque_ff)


def decode_set_input_vel(data: bytes) -> tuple[float, float]:
    vel, torque = _TWO_F32.unpack_from(data)
    return float(vel), float(torque)


def estop(node_id: int) -> tuple[int, bytes]:
    return arbitration_id(node_id, CMD_ESTOP), b""


def clear_errors(node_id: int) -> tuple[int, bytes]:
    """Clear_Errors with ``Identify = 0`` (firmware 0.6 takes one byte)."""
    return arbitration_id(node_id, CMD_CLEAR_ERRORS), b"\x00"


# -- drive -> host ---------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Heartbeat:
    """Axis_Error (u32), Axis_State (u8), Procedure_Result (u8), Trajectory_Done (u8)."""

    axis_error: int
    axis_state: int
    procedure_result: int = 0
    trajectory_done: int = 0


def encode_heartbeat(node_id: int, beat: Heartbeat) -> tuple[int, bytes]:
    data = _HEARTBEAT.pack(
        beat.axis_error, beat.axis_state, beat.procedure_result, beat.trajectory_done
    )
    return arbitration_id(node_id, CMD_HEARTBEAT), data


def decode_heartbeat(data: bytes) -> Heartbeat:
    if len(data) < 5:
        raise ValueError(f"heartbeat needs at least 5 bytes, got {len(data)}")
    error, state = struct.unpack_from("<IB", data)
    rest = data[5:8] + bytes(3 - len(data[5:8]))
    return Heartbeat(int(error), int(state), rest[0], rest[1])


@dataclass(frozen=True, slots=True)
class EncoderEstimates:
    """Pos_Estimate (turns) and Vel_Estimate (turns/s), motor side."""

    position: float
    velocity: float


def encode_encoder_estimates(node_id: int, est: EncoderEstimates) -> tuple[int, bytes]:
    return arbitration_id(node_id, CMD_GET_ENCODER_ESTIMATES), _TWO_F32.pack(
        est.position, est.velocity
    )


def decode_encoder_estimates(data: bytes) -> EncoderEstimates:
    pos, vel = _TWO_F32.unpack_from(data)
    return EncoderEstimates(float(pos), float(vel))


pack_two_f32 = _TWO_F32.pack
"""Two little-endian float32 (the hot-path encoder of encoder estimates)."""

unpack_two_f32 = _TWO_F32.unpack_from
"""``(a, b)`` from two little-endian float32: the hot-path decoder of encoder estimates
and Set_Input_Vel (a frozen dataclass per frame cost 9 us of a 10 ms instant)."""


def pack_heartbeat(axis_error: int, axis_state: int) -> bytes:
    """A heartbeat payload with no procedure result and no trajectory (the emulator's
    cyclic frame): the bytes of :func:`encode_heartbeat`, without a ``Heartbeat``."""
    return _HEARTBEAT.pack(axis_error, axis_state, 0, 0)


unpack_heartbeat = _HEARTBEAT_HEAD.unpack_from
"""``(axis_error, axis_state)`` of a heartbeat payload (the host's receive path);
``struct.error`` if it is shorter than 5 bytes."""
