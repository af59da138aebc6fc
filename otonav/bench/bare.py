"""(a) The bare loop: the physical limit of this model in Python.

The same MJCF, physics step, sensors at the same rates (odometry + IMU reads at 100 Hz,
a 360-beam scan at 10 Hz) and the same control law (go-to-goal + guard at 20 Hz, limits
and kinematics at 50 Hz), called inline: no actors, no messages, no recording.
"""

from __future__ import annotations

import math

import numpy as np

from otonav.control import (
    DiffDriveGeometry,
    Pose2D,
    integrate_odometry,
    limit_twist,
    twist_to_wheels,
)
from otonav.hal import RobotHardwareInterface, WheelCommand
from otonav.nav import GoToGoalParams, GuardParams, go_to_goal, guard_blocked
from otonav.stack import StackConfig


def run_bare(
    hal: RobotHardwareInterface, stack: StackConfig, goal: tuple[float, float], duration: float
) -> None:
    """Drive ``hal`` toward ``goal`` for ``duration`` s of sim time, inline."""
    tick = hal.tick
    rates, base, nav, guard_cfg = stack.rates, stack.base, stack.nav, stack.guard
    steps = round(duration / tick)
    # Periods in ticks (the stack's defaults are whole numbers of ticks).
    odom_every = max(1, round(1 / rates.odom_hz / tick))
    imu_every = max(1, round(1 / rates.imu_hz / tick))
    scan_every = max(1, round(1 / rates.scan_hz / tick))
    base_every = max(1, round(1 / base.rate_hz / tick))
    nav_every = max(1, round(1 / nav.rate_hz / tick))
    every = math.gcd(odom_every, imu_every, scan_every, base_every, nav_every)
    geometry = hal.geometry
    kin = DiffDriveGeometry(geometry.wheel_radius, geometry.wheel_separation)
    params = GoToGoalParams(
        nav.kp_lin, nav.kp_ang, nav.max_v, nav.max_omega, nav.tolerance, nav.turn_in_place_threshold
    )
    guard = GuardParams(guard_cfg.sector_half_angle, guard_cfg.stop_distance)
    pose = Pose2D(0.0, 0.0, 0.0)
    wheels = hal.read_wheels()
    last = (wheels.left_position, wheels.right_position)
    want_v = want_omega = v = omega = 0.0
    ranges = np.empty(0, np.float32)
    scan = None
    for t in range(0, steps, every):
        hal.advance(every)
        k = t + every
        if k % odom_every == 0:
            wheels = hal.read_wheels()
            gyro = hal.read_imu().angular_velocity[2]
            dl, dr = wheels.left_position - last[0], wheels.right_position - last[1]
            last = (wheels.left_position, wheels.right_position)
            dt = odom_every * tick
            pose = integrate_odometry(pose, geometry.wheel_radius * (dl + dr) / 2 / dt, gyro, dt)
        if k % imu_every == 0 and imu_every != odom_every:
            hal.read_imu()
        if k % scan_every == 0:
            scan = hal.read_scan()
            ranges = scan.ranges
        if k % nav_every == 0:
            cmd = go_to_goal(pose, goal[0], goal[1], params)
            blocked = (
                scan is None
                or guard_blocked(ranges, scan.angle_min, scan.angle_increment, guard)[0]
            )
            want_v, want_omega = (
                (0.0, 0.0) if cmd.reached or (blocked and cmd.v > 0) else (cmd.v, cmd.omega)
            )
        if k % base_every == 0:
            v, omega = limit_twist(
                want_v,
                want_omega,
                prev_v=v,
                prev_omega=omega,
                dt=base_every * tick,
                max_v=base.max_v,
                max_omega=base.max_omega,
                max_accel=base.max_accel,
                max_alpha=base.max_alpha,
            )
            left, right = twist_to_wheels(v, omega, kin)
            hal.write(WheelCommand(left, right))
