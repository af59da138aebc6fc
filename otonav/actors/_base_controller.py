"""The base controller: /cmd_vel -> limits -> diff-drive kinematics -> /wheel_cmd."""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass

import anyio

from otonav.actors import _topics as topics
from otonav.control import DiffDriveGeometry, limit_twist, twist_to_wheels
from otonav.msgs import HardwareStatus, Header, Log, Time, Twist, WheelCommand
from otonav.msgs._flat import FlatLayout
from otonav.msgs._std import split_seconds
from otonav.params import BaseConfig
from otonav.runtime import Actor, Input, Output

_DEFAULT = BaseConfig()

WHEEL_COMMAND = FlatLayout(
    WheelCommand.fast(
        header=Header.fast(stamp=Time.fast(sec=0, nanosec=0), frame_id="base_link"),
        left=0.0,
        right=0.0,
    ),
    ("header.stamp.sec", "header.stamp.nanosec", "left", "right"),
)
"""/wheel_cmd as a fixed layout (otonav.msgs._flat): sec, nanosec, left, right."""


@dataclass(frozen=True, slots=True)
class BaseLimits:
    """Velocity (m/s, rad/s) and acceleration (m/s², rad/s²) limits."""

    max_v: float = _DEFAULT.max_v
    max_omega: float = _DEFAULT.max_omega
    max_accel: float = _DEFAULT.max_accel
    max_alpha: float = _DEFAULT.max_alpha


class BaseController(Actor):
    """At ``rate_hz``: take the newest /cmd_vel, clamp it to velocity and acceleration
    limits, convert to wheel speeds, publish /wheel_cmd. With no /cmd_vel for
    ``cmd_timeout`` s of sim time the target falls to zero (the watchdog).

    While /hardware/status says the hardware is not drivable (a fault, or starting or
    recovering), it commands zero at once, bypassing the acceleration limits, and
    counts it in ``hardware_stops``; when it is drivable again it ramps up from rest.

    A /cmd_vel that is not finite (NaN, inf) is dropped: the base keeps the last good
    command (the watchdog still counts from it), counts it in ``rejected_commands`` and
    says so on /rosout, at most once per second of sim time. One bad message from one
    publisher must not stop the robot's whole stack."""

    cmd_vel = Input(topics.CMD_VEL, Twist, topics.COMMAND_QOS)
    wheel_cmd = Output(topics.WHEEL_CMD, WheelCommand, topics.COMMAND_QOS)
    hardware = Input(topics.HARDWARE_STATUS, HardwareStatus, topics.HARDWARE_QOS)
    rosout = Output(topics.ROSOUT, Log, topics.ROSOUT_QOS)

    LOG_EVERY = 1.0
    """s of sim time between two warnings about rejected commands."""

    def __init__(
        self,
        geometry: DiffDriveGeometry,
        limits: BaseLimits = BaseLimits(),
        *,
        rate_hz: float = _DEFAULT.rate_hz,
        cmd_timeout: float = _DEFAULT.cmd_timeout,
        deadband: float = 0.0,
        name: str = "base",
    ) -> None:
        super().__init__(name)
        if not rate_hz > 0 or not cmd_timeout > 0:
            raise ValueError(
                f"base.rate_hz and base.cmd_timeout must be > 0, got {rate_hz}, {cmd_timeout}"
            )
        self.geometry = geometry
        self.limits = limits
        self.rate_hz = rate_hz
        self.cmd_timeout = cmd_timeout
        self.deadband = deadband
        """rad/s added to a turning wheel's command, in its direction: what the wheel's
        servo loses to friction whatever the speed (identified, ADR 0066), so a small
        command still turns the wheel; 0: none."""
        self.watchdog_trips = 0
        self.rejected_commands = 0
        self._logged_at = -math.inf
        self._logged_count = 0
        self.hardware_stops = 0

    async def run(self) -> None:
        rate = self.clock.rate(self.rate_hz)
        limits = self.limits
        v = omega = 0.0
        target: Twist | None = None
        received_at = -math.inf
        timed_out = False
        drivable = True
        while True:
            await rate.sleep()
            now = self.clock.now()
            status = self.hardware.take_latest()
            if status is not None:
                if drivable and not status.drivable:
                    self.hardware_stops += 1
                drivable = status.drivable
            latest = self.cmd_vel.take_latest()
            if latest is not None:
                if math.isfinite(latest.linear.x) and math.isfinite(latest.angular.z):
                    target, received_at, timed_out = latest, now, False
                else:
                    self._reject(latest, now)
            # received_at is the control tick that picked the command up, up to one
            # period after it arrived: trip at >= so the stop starts within
            # cmd_timeout + one period of the last command, never before cmd_timeout.
            silent = now - received_at
            if target is not None and not timed_out and silent >= self.cmd_timeout - 1e-9:
                self.watchdog_trips += 1
                timed_out = True
            want_v, want_omega = (
                (target.linear.x, target.angular.z)
                if target is not None and not timed_out
                else (0.0, 0.0)
            )
            if not drivable:
                v = omega = want_v = want_omega = 0.0
            v, omega = limit_twist(
                want_v,
                want_omega,
                prev_v=v,
                prev_omega=omega,
                dt=rate.period,
                max_v=limits.max_v,
                max_omega=limits.max_omega,
                max_accel=limits.max_accel,
                max_alpha=limits.max_alpha,
            )
            left, right = twist_to_wheels(v, omega, self.geometry)
            if self.deadband:
                left += math.copysign(self.deadband, left) if left else 0.0
                right += math.copysign(self.deadband, right) if right else 0.0
            sec, nanosec = split_seconds(now)
            command = WHEEL_COMMAND(sec, nanosec, left, right)
            try:
                self.wheel_cmd.publish_nowait(command)
            except anyio.WouldBlock:
                await self.wheel_cmd.publish(command)

    async def on_stop(self) -> None:
        """Command zero as the base stops, whatever stopped it (the end of a run, any
        actor's crash, a signal): the wheels must not keep turning at the last setpoint
        (issue 27 item 8: a MuJoCo run's recording ended at 7.7 and 8.3 rad/s). The
        bridge, which stops after the base, applies it; the recording shows it. The CAN
        path also sets the drives IDLE after that (``CanFrameTap.on_stop``)."""
        sec, nanosec = split_seconds(self.clock.now())
        command = WHEEL_COMMAND(sec, nanosec, 0.0, 0.0)
        try:
            self.wheel_cmd.publish_nowait(command)
        except anyio.WouldBlock:
            # A full reliable mailbox: wait for room, at most one period of sim time
            # (the bridge zeroes the hardware on its own stop in any case).
            with anyio.move_on_after(1.0 / self.rate_hz):
                await self.wheel_cmd.publish(command)

    def _reject(self, command: Twist, now: float) -> None:
        self.rejected_commands += 1
        if now - self._logged_at < self.LOG_EVERY - 1e-9:
            return
        since = self.rejected_commands - self._logged_count - 1
        more = f" ({since} more since the last warning)" if since else ""
        text = (
            f"rejected a /cmd_vel that is not finite (linear.x={command.linear.x}, "
            f"angular.z={command.angular.z}); keeping the last good command{more}"
        )
        self._logged_at, self._logged_count = now, self.rejected_commands
        log = Log.fast(
            stamp=Time.from_seconds(now),
            level=Log.WARN,
            name=self.name,
            msg=text,
            file="",
            function="",
            line=0,
        )
        with contextlib.suppress(anyio.WouldBlock):  # never stall control for a log line
            self.rosout.publish_nowait(log)
