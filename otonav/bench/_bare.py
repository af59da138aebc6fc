"""The bare loops: the physical limit of this model in Python, with no framework.

Both run the same MJCF, physics step and sensors at the same rates (odometry + IMU reads
at 100 Hz, a 360-beam scan at 10 Hz), inline: no actors, no messages, no loop, no
recording.

- :func:`run_bare_stack`, **(a)**: the same pure functions the stack's actors call (the
  default navigator's map, A* and DWA, the safety check, the base's limits and
  kinematics). The stack over this is the cost of the framework (ADR 0027).
- :func:`run_bare`, **(a0)**: the old go-to-goal + guard law (ADR 0025's baseline),
  kept so a change of baseline shows instead of moving the goalposts quietly.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from otonav.control import (
    DiffDriveGeometry,
    Pose2D,
    integrate_odometry,
    limit_twist,
    twist_to_wheels,
)
from otonav.hal import RobotHardwareInterface, WheelSetpoint
from otonav.nav import GoToGoalParams, GuardParams, go_to_goal, guard_blocked
from otonav.nav._navigate import Navigation
from otonav.nav._safety import safe_command, stopping_reach
from otonav.nav._scan import scan_points, to_frame
from otonav.stack import BaseConfig, StackConfig
from otonav.stack._build import navigation_params, safety_params


def _drive(
    hal: RobotHardwareInterface,
    want_v: float,
    want_omega: float,
    v: float,
    omega: float,
    dt: float,
    base: BaseConfig,
    kin: DiffDriveGeometry,
) -> tuple[float, float]:
    """The base controller's step inline: limit the wanted twist, command the wheels;
    returns the twist commanded."""
    v, omega = limit_twist(
        want_v,
        want_omega,
        prev_v=v,
        prev_omega=omega,
        dt=dt,
        max_v=base.max_v,
        max_omega=base.max_omega,
        max_accel=base.max_accel,
        max_alpha=base.max_alpha,
    )
    left, right = twist_to_wheels(v, omega, kin)
    hal.write(WheelSetpoint(left, right))
    return v, omega


def run_bare(
    hal: RobotHardwareInterface, stack: StackConfig, goal: tuple[float, float], duration: float
) -> None:
    """(a0): drive ``hal`` toward ``goal`` for ``duration`` s of sim time with the old
    go-to-goal law and guard, inline."""
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
            v, omega = _drive(hal, want_v, want_omega, v, omega, base_every * tick, base, kin)


def run_bare_stack(
    hal: RobotHardwareInterface, stack: StackConfig, goal: tuple[float, float], duration: float
) -> None:
    """(a): the stack's own pure functions, called inline at the stack's rates.

    What the actors call, in the order they call it: odometry (wheel encoders + gyro,
    :func:`integrate_odometry`) at ``odom_hz``; the scan at ``scan_hz``, turned into
    points once (:func:`scan_points`, float32 angles as on the wire) and shared by the
    navigator and the safety check; the default navigator
    (:meth:`Navigation.observe` when the robot moved since the last scan,
    :meth:`Navigation.step` with the last scan moved into the current base_link) at
    ``nav.rate_hz``; the safety check (the nearest-return shortcut, else
    :func:`safe_command`) at ``safety.rate_hz``; limits and kinematics at
    ``base.rate_hz``. No actors, no messages, no loop, no recording: the ratio of the
    stack to this measures the framework, not the planner (ADR 0027).
    """
    if stack.nav.planner != "dwa" or not stack.safety.enabled:
        raise ValueError(
            "the bare loop mirrors the default stack (nav.planner=dwa, safety.enabled=true)"
        )
    tick = hal.tick
    rates, base = stack.rates, stack.base
    steps = round(duration / tick)
    odom_every = max(1, round(1 / rates.odom_hz / tick))
    imu_every = max(1, round(1 / rates.imu_hz / tick))
    scan_every = max(1, round(1 / rates.scan_hz / tick))
    base_every = max(1, round(1 / base.rate_hz / tick))
    nav_every = max(1, round(1 / stack.nav.rate_hz / tick))
    safety_every = max(1, round(1 / stack.safety.rate_hz / tick))
    every = math.gcd(odom_every, imu_every, scan_every, base_every, nav_every, safety_every)
    geometry = hal.geometry
    kin = DiffDriveGeometry(geometry.wheel_radius, geometry.wheel_separation)
    offset = geometry.laser_offset_x
    nav = Navigation(navigation_params(stack, geometry), (0.0, 0.0))
    nav.set_goal(goal)
    safety = safety_params(stack, geometry)
    nav_scan_timeout, safety_cfg = 0.5, stack.safety
    f32 = np.float32
    pose = Pose2D(0.0, 0.0, 0.0)
    odom_v = odom_omega = 0.0
    wheels = hal.read_wheels()
    last = (wheels.left_position, wheels.right_position)
    nav_v = nav_omega = want_v = want_omega = v = omega = 0.0
    nav_at = -math.inf
    points = np.empty((0, 2))
    points_pose: tuple[float, float, float] | None = None
    observed_pose: tuple[float, float, float] | None = None
    scan_at = -math.inf
    nearest = math.inf
    new_scan = False
    for t in range(0, steps, every):
        hal.advance(every)
        k = t + every
        now = k * tick
        if k % odom_every == 0:
            wheels = hal.read_wheels()
            odom_omega = hal.read_imu().angular_velocity[2]
            dl, dr = wheels.left_position - last[0], wheels.right_position - last[1]
            last = (wheels.left_position, wheels.right_position)
            dt = odom_every * tick
            odom_v = geometry.wheel_radius * (dl + dr) / 2 / dt
            pose = integrate_odometry(pose, odom_v, odom_omega, dt)
        if k % imu_every == 0 and imu_every != odom_every:
            hal.read_imu()
        if k % scan_every == 0:
            scan = hal.read_scan()
            seen = scan_points(
                np.asarray(scan.ranges, dtype=np.float64),
                float(f32(scan.angle_min)),
                float(f32(scan.angle_increment)),
                float(f32(scan.range_min)),
                float(f32(scan.range_max)),
                offset,
            )
            points, points_pose, scan_at = seen.xy, (pose.x, pose.y, pose.yaw), now
            xy = seen.xy
            nearest = float(np.hypot(xy[:, 0], xy[:, 1]).min()) if xy.shape[0] else math.inf
            new_scan = True
        here = (pose.x, pose.y, pose.yaw)
        if k % nav_every == 0:
            if new_scan and points_pose is not None:
                new_scan = False
                moved = observed_pose is None or (
                    abs(points_pose[0] - observed_pose[0]) + abs(points_pose[1] - observed_pose[1])
                    > 1e-3
                    or abs(points_pose[2] - observed_pose[2]) > 1e-3
                )
                observed_pose = points_pose
                if moved:
                    nav.observe(to_frame(points, points_pose))
            if points_pose is None or now - scan_at > nav_scan_timeout:
                nav_v = nav_omega = 0.0
            else:
                out = nav.step(
                    now,
                    here,
                    odom_v,
                    odom_omega,
                    functools.partial(to_frame, points, points_pose, here),
                )
                nav_v, nav_omega = out.v, out.omega
            nav_at = now
        if k % safety_every == 0:
            v_in, w_in = (
                (nav_v, nav_omega) if now - nav_at <= safety_cfg.cmd_timeout else (0.0, 0.0)
            )
            if points_pose is None or now - scan_at > safety_cfg.scan_timeout:
                want_v = want_omega = 0.0
            else:
                moved_by = math.hypot(here[0] - points_pose[0], here[1] - points_pose[1])
                fastest = max(abs(v_in), abs(odom_v))
                reach = stopping_reach(fastest, safety)
                if nearest - moved_by > safety.radius + reach:
                    want_v, want_omega = v_in, w_in
                else:
                    moved_points = to_frame(points, points_pose, here)
                    result = safe_command(v_in, w_in, odom_v, odom_omega, moved_points, safety)
                    want_v, want_omega = result.v, result.omega
        if k % base_every == 0:
            v, omega = _drive(hal, want_v, want_omega, v, omega, base_every * tick, base, kin)
