"""Compose the robot stack from a :class:`StackConfig`: the world, then the actors."""

from __future__ import annotations

from collections.abc import Sequence

from otonav.actors import BaseController, BaseLimits, Bridge, Navigator
from otonav.control import DiffDriveGeometry
from otonav.hal import BoxObstacle, RobotHardwareInterface
from otonav.hal.mujoco import MujocoInterface, Variant
from otonav.nav import GoToGoalParams, GuardParams
from otonav.runtime import Actor
from otonav.stack.config import StackConfig


def build_world(
    config: StackConfig,
    *,
    extra_obstacles: Sequence[BoxObstacle] = (),
    variant: Variant = "shipped",
    start: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> RobotHardwareInterface:
    """The simulated robot (MuJoCo) for ``config.world``, placed at ``start``."""
    world = config.world
    return MujocoInterface(
        world.scene,
        lidar_beams=world.lidar_beams,
        lidar_range_min=world.lidar_range_min,
        lidar_range_max=world.lidar_range_max,
        timestep=world.timestep,
        extra_obstacles=extra_obstacles,
        variant=variant,
        start=start,
    )


def build_actors(
    config: StackConfig,
    hal: RobotHardwareInterface,
    *,
    navigator: bool = True,
    goal: tuple[float, float] | None = None,
    initial_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> list[Actor]:
    """bridge + base controller (+ navigator) for ``hal``. ``initial_pose`` is where
    odometry starts (the known start pose: odom is then the world frame)."""
    geometry = hal.geometry
    rates, base, nav, guard = config.rates, config.base, config.nav, config.guard
    actors: list[Actor] = [
        Bridge(
            hal,
            clock_hz=rates.clock_hz,
            odom_hz=rates.odom_hz,
            imu_hz=rates.imu_hz,
            scan_hz=rates.scan_hz,
            initial_pose=initial_pose,
        ),
        BaseController(
            DiffDriveGeometry(geometry.wheel_radius, geometry.wheel_separation),
            BaseLimits(base.max_v, base.max_omega, base.max_accel, base.max_alpha),
            rate_hz=base.rate_hz,
            cmd_timeout=base.cmd_timeout,
        ),
    ]
    if navigator:
        actors.append(
            Navigator(
                GoToGoalParams(
                    kp_lin=nav.kp_lin,
                    kp_ang=nav.kp_ang,
                    max_v=nav.max_v,
                    max_omega=nav.max_omega,
                    tolerance=nav.tolerance,
                    turn_in_place_threshold=nav.turn_in_place_threshold,
                ),
                GuardParams(guard.sector_half_angle, guard.stop_distance),
                rate_hz=nav.rate_hz,
                goal=goal,
            )
        )
    return actors
