"""One ODrive axis as a state machine: what the drive emulator runs per wheel.

Pure (no bus, no physics): the emulator feeds it the commands it decoded and the sim
time, and asks for the velocity setpoint (turns/s, motor side) to put on the wheel.

* States IDLE and CLOSED_LOOP_CONTROL. Closed loop is entered ``arm_time`` s after it
  was requested, and only with no error active (a real ODrive refuses too).
* Velocity control: the setpoint follows ``Set_Input_Vel`` clamped to ``vel_limit``. In
  input mode PASSTHROUGH (what the CAN interface selects) it takes the input at once; in
  VEL_RAMP it slews towards it at ``vel_ramp_rate`` (turns/s²); INACTIVE ignores the input
  (the setpoint holds), like an ODrive's ``controller.config.input_mode``. The torque loop
  under it is MuJoCo's velocity actuator with its force limit.
* The watchdog: in closed loop, no ``Set_Input_Vel`` for ``watchdog_timeout`` s raises
  WATCHDOG_TIMER_EXPIRED and drops to IDLE (0 disables it). Entering closed loop feeds it.
* Errors latch until ``Clear_Errors``; any error disarms (IDLE, setpoint 0). Estop
  raises ESTOP_REQUESTED. A measured speed over ``overspeed_factor * vel_limit`` raises
  VELOCITY_LIMIT_VIOLATION.
"""

from __future__ import annotations

import math

from otonav.hal.can._protocol import AxisError, AxisState, ControlMode, InputMode
from otonav.params import AxisParams

__all__ = ["AxisModel", "AxisParams"]

_CLOSED_LOOP = AxisState.CLOSED_LOOP_CONTROL
_VELOCITY_CONTROL = ControlMode.VELOCITY_CONTROL
_PASSTHROUGH = InputMode.PASSTHROUGH
_VEL_RAMP = InputMode.VEL_RAMP


class AxisModel:
    """The state machine of one axis. Times are sim seconds."""

    def __init__(self, params: AxisParams) -> None:
        self.params = params
        self.state = AxisState.IDLE
        self.error = AxisError.NONE
        self.control_mode = ControlMode.VELOCITY_CONTROL
        self.input_mode = InputMode.PASSTHROUGH
        self.input_vel = 0.0
        self.setpoint = 0.0
        self._arm_at: float | None = None
        self._fed_at = -math.inf
        self._updated_at: float | None = None
        # update() runs for both axes every 10 ms: its thresholds, computed once (the
        # same float operations as before, so the same results).
        self._watchdog_after = params.watchdog_timeout + 1e-12
        self._overspeed = params.overspeed_factor * params.vel_limit

    # -- commands ------------------------------------------------------------------------

    def request_state(self, state: int, now: float) -> None:
        if state == AxisState.CLOSED_LOOP_CONTROL:
            if self.state != AxisState.CLOSED_LOOP_CONTROL and not self.error:
                self._arm_at = now + self.params.arm_time
        elif state == AxisState.IDLE:
            self._disarm()

    def set_controller_mode(self, control: int, inp: int) -> None:
        if control in ControlMode._value2member_map_:
            self.control_mode = ControlMode(control)
        if inp in InputMode._value2member_map_:
            self.input_mode = InputMode(inp)

    def set_input_vel(self, vel: float, now: float) -> bool:
        """Take a Set_Input_Vel (it feeds the watchdog). True if the setpoint follows it
        at once (input mode PASSTHROUGH): the caller should :meth:`update` now."""
        if math.isfinite(vel):
            self.input_vel = vel
        self._fed_at = now
        return self.input_mode == _PASSTHROUGH

    def estop(self) -> None:
        self.raise_error(AxisError.ESTOP_REQUESTED)

    def clear_errors(self) -> None:
        self.error = AxisError.NONE

    def raise_error(self, code: int) -> None:
        self.error |= AxisError(code)
        self._disarm()

    def _disarm(self) -> None:
        self.state = AxisState.IDLE
        self._arm_at = None
        self.setpoint = 0.0

    # -- time ----------------------------------------------------------------------------

    def update(self, now: float, measured_vel: float) -> float:
        """Advance to ``now``: arm, watchdog, overspeed, the setpoint ramp. Returns the
        velocity setpoint for the wheel, turns/s (0 unless in closed loop).

        The clamps are written out (``v if v < hi else hi``), not ``min``/``max``: the
        same comparisons in the same order, so the same floats, without two builtin
        calls per clamp (this runs for both axes every 10 ms)."""
        p = self.params
        last = self._updated_at
        elapsed = 0.0 if last is None else now - last
        dt = elapsed if elapsed > 0.0 else 0.0
        self._updated_at = now
        if self._arm_at is not None and now >= self._arm_at - 1e-12 and not self.error:
            self.state = AxisState.CLOSED_LOOP_CONTROL
            self._arm_at = None
            self._fed_at = now  # entering closed loop feeds the watchdog
        if self.state != _CLOSED_LOOP:
            self.setpoint = 0.0
            return 0.0
        if p.watchdog_timeout > 0 and now - self._fed_at > self._watchdog_after:
            self.raise_error(AxisError.WATCHDOG_TIMER_EXPIRED)
            return 0.0
        if abs(measured_vel) > self._overspeed:
            self.raise_error(AxisError.VELOCITY_LIMIT_VIOLATION)
            return 0.0
        mode = self.input_mode
        if self.control_mode != _VELOCITY_CONTROL:
            target = 0.0
        elif mode in (_PASSTHROUGH, _VEL_RAMP):
            limit, wanted = p.vel_limit, self.input_vel
            target = wanted if wanted < limit else limit
            target = target if target > -limit else -limit
        else:  # INACTIVE: the input is ignored, the setpoint holds
            return self.setpoint
        if mode == _VEL_RAMP:
            step = p.vel_ramp_rate * dt
            change = target - self.setpoint
            change = change if change < step else step
            self.setpoint += change if change > -step else -step
        else:
            self.setpoint = target
        return self.setpoint
