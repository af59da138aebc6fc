"""Compose the robot stack from a :class:`StackConfig`: the world, then the actors."""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import fields
from functools import reduce
from typing import TYPE_CHECKING, Any, TypeVar

from otonav.actors import (
    EXTERNAL_COMMAND_WAIT,
    AvoidingNavigator,
    BaseController,
    BaseLimits,
    Bridge,
    CommandWatch,
    Navigator,
    SafetyLayer,
    topics,
)
from otonav.actors._localized_navigator import LocalizedNavigator
from otonav.actors._localizer import Localizer
from otonav.actors._odometry_error import OdometryError
from otonav.control import DiffDriveGeometry
from otonav.hal import BoxObstacle, RobotGeometry, RobotHardwareInterface
from otonav.hal._types import Reach
from otonav.hal.mujoco import MujocoInterface
from otonav.nav._footprint import centre_clearance
from otonav.params import (
    CONFIG_KEYS,
    DwaParams,
    GoToGoalParams,
    GuardParams,
    LocalizerParams,
    MatchParams,
    NavigationParams,
    SafetyParams,
)
from otonav.runtime import Actor
from otonav.stack._config import StackConfig
from otonav.stack._files import ConfigFileError
from otonav.stack._launch import launch
from otonav.stack._robot import (
    deadband,
    describe_robot,
    nav_speeds,
    reached,
    robot_base,
    robot_frames,
    slower,
)

if TYPE_CHECKING:
    from otonav.hal.can import CanBusInterface

P = TypeVar("P")

_VIRTUAL_BUSES = itertools.count()
"""Each stack's virtual CAN channel is private: concurrent stacks never hear each other."""


def build_world(
    config: StackConfig,
    *,
    extra_obstacles: Sequence[BoxObstacle] = (),
    start: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> RobotHardwareInterface:
    """The robot for ``config``, placed at ``start``: the MuJoCo world, or with
    ``hal.kind: can`` the wheels over a CAN bus with the world as sensor source."""
    world = config.world
    robot = describe_robot(config.robot)
    sim = MujocoInterface(
        world.scene,
        lidar_beams=world.lidar_beams,
        lidar_range_min=world.lidar_range_min,
        lidar_range_max=world.lidar_range_max,
        lidar_fov=world.lidar_fov,
        timestep=world.timestep,
        extra_obstacles=extra_obstacles,
        start=start,
        robot=robot,
    )
    if config.hal.kind == "mujoco":
        return sim
    try:
        return _can_world(config, sim)
    except BaseException:
        sim.close()
        raise


def _can_world(config: StackConfig, world: MujocoInterface) -> CanBusInterface:
    """The CAN bus interface over ``world``, with the drive emulator when asked."""
    try:
        from otonav.hal.can import (
            BusError,
            CanBusInterface,
            MonitorLimits,
            WheelAxis,
            open_endpoint,
        )
        from otonav.hal.can._protocol import InputMode
        from otonav.hal.sim import AxisParams, DriveEmulator, DriveMount
        from otonav.stack._faults import fault_plan
    except ImportError as exc:  # python-can is an extra
        raise ConfigFileError(
            f"hal.kind: can needs python-can ({exc.name} is missing): pip install 'otonav[can]'"
        ) from None
    can, sim = config.hal.can, config.hal.sim
    channel = can.channel
    if can.interface == "virtual":
        channel = f"otonav-{can.channel}-{next(_VIRTUAL_BUSES)}"
    try:
        host = open_endpoint(can.interface, channel, label=can.channel)
    except BusError as exc:
        raise ConfigFileError(f"hal.can: {exc}") from None
    peer = None
    try:
        if can.emulate:
            params = {
                "vel_limit": sim.vel_limit,
                "vel_ramp_rate": sim.vel_ramp_rate,
                "watchdog_timeout": sim.watchdog_timeout,
                "arm_time": sim.arm_time,
            }
            peer = DriveEmulator(
                open_endpoint(can.interface, channel, label=can.channel),
                world,
                AxisParams(sim.left_node_id, **params),
                AxisParams(sim.right_node_id, **params),
                left_mount=DriveMount(can.left.sign, can.left.gear_ratio),
                right_mount=DriveMount(can.right.sign, can.right.gear_ratio),
                heartbeat_period=sim.heartbeat_period,
                encoder_period=sim.encoder_period,
                seed=sim.seed,
                schedule=fault_plan(sim.faults),
            )
        # hal.can's fault-detection keys are MonitorLimits' fields, by name.
        limits = MonitorLimits(**{f.name: getattr(can, f.name) for f in fields(MonitorLimits)})
        return CanBusInterface(
            host,
            world,
            WheelAxis(can.left.node_id, can.left.sign, can.left.gear_ratio, "left wheel"),
            WheelAxis(can.right.node_id, can.right.sign, can.right.gear_ratio, "right wheel"),
            limits,
            peer=peer,
            command_keepalive=can.command_keepalive,
            input_mode=InputMode[can.input_mode.upper()],
        )
    except BaseException:
        host.close()
        if peer is not None:
            peer.close()
        raise


def build_actors(
    config: StackConfig,
    hal: RobotHardwareInterface,
    *,
    goal: tuple[float, float] | None = None,
    initial_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> list[Actor]:
    """bridge + base controller, the planner ``nav.planner`` names and the safety layer
    (``safety.enabled``) for ``hal``. ``initial_pose`` is where odometry starts (the known
    start pose: odom is then the world frame)."""
    geometry = hal.geometry
    rates, base, nav, guard = config.rates, robot_base(config), config.nav, config.guard
    actors: list[Actor] = [
        Bridge(
            hal,
            **rates.model_dump(),
            initial_pose=initial_pose,
            odometry_error=odometry_error(config),
            frames=robot_frames(config.robot),
        ),
        BaseController(
            DiffDriveGeometry(geometry.wheel_radius, geometry.wheel_separation),
            BaseLimits(base.max_v, base.max_omega, base.max_accel, base.max_alpha),
            rate_hz=base.rate_hz,
            cmd_timeout=base.cmd_timeout,
            deadband=deadband(reached(config, hal)),
        ),
    ]
    if config.hal.kind == "can" and config.hal.can.record_frames:
        from otonav.hal.can import CanBusInterface
        from otonav.hal.can._tap import CanFrameTap

        if isinstance(hal, CanBusInterface):
            # First: actors stop in reverse order, so the tap stops after the bridge
            # and its on_stop records the drives' IDLE frames (ADR 0028).
            actors.insert(0, CanFrameTap(hal))
    if nav.localization.enabled:
        actors.append(
            Localizer(
                localizer_params(config),
                laser_offset_x=geometry.laser_offset_x,
                start=(initial_pose[0], initial_pose[1]),
            )
        )
    remap = {topics.CMD_VEL: topics.CMD_VEL_NAV} if config.safety.enabled else None
    if nav.planner == "stop":
        actors.append(
            Navigator(
                _from_config(
                    GoToGoalParams,
                    config,
                    max_v=nav_speeds(config)[0],
                    max_omega=nav_speeds(config)[1],
                ),
                GuardParams(guard.sector_half_angle, guard.stop_distance),
                rate_hz=nav.rate_hz,
                goal=goal,
                remap=remap,
            )
        )
    elif nav.planner == "dwa":
        navigator_class = LocalizedNavigator if nav.localization.enabled else AvoidingNavigator
        actors.append(
            navigator_class(
                navigation_params(config, geometry, reached(config, hal)),
                laser_offset_x=geometry.laser_offset_x,
                start=(initial_pose[0], initial_pose[1]),
                rate_hz=nav.rate_hz,
                goal=goal,
                remap=remap,
            )
        )
    if config.safety.enabled:
        actors.append(
            SafetyLayer(
                safety_params(config, geometry),
                laser_offset_x=geometry.laser_offset_x,
                rate_hz=config.safety.rate_hz,
                cmd_timeout=config.safety.cmd_timeout,
                scan_timeout=config.safety.scan_timeout,
            )
        )
    if nav.planner == "external":
        # Nobody may be publishing the planner's commands: say so early.
        topic = topics.CMD_VEL_NAV if config.safety.enabled else topics.CMD_VEL
        actors.append(CommandWatch(topic, within=EXTERNAL_COMMAND_WAIT))
    return launch(actors, config.actors)


def _from_config(cls: type[P], config: StackConfig, **derived: Any) -> P:
    """``cls`` with each field its config key sets (:data:`otonav.params.CONFIG_KEYS`)
    read from ``config``, but those ``derived`` here."""
    keys = CONFIG_KEYS[cls].items()
    read = {name: reduce(getattr, key.split("."), config) for name, key in keys}
    return cls(**{**read, **derived})


def navigation_params(
    config: StackConfig, geometry: RobotGeometry, reach: Reach | None = None
) -> NavigationParams:
    """The avoiding navigator's settings from ``nav.*`` and the base's limits: the
    ``nav.dwa``, ``nav.map`` and ``nav.recovery`` sections pass through by their keys
    (``otonav.params.CONFIG_KEYS``); what depends on the base or the footprint is
    derived here. ``reach``: what the robot really reaches (ADR
    0066): the DWA's window grows by the accelerations it really has, and a robot slower
    than asked gets a progress window as much longer as it is slower. The window's top
    stays the asked speed: a servo short of its setpoint reaches most when asked most."""
    nav, base = config.nav, robot_base(config)
    radius = centre_clearance(nav.clearance, geometry.footprint_radius, nav.footprint_padding)
    fastest_v, fastest_omega = nav_speeds(config)
    if reach is not None:  # no faster than the wheels' control range lets it ask
        fastest_v, fastest_omega = reach.asked_v, reach.asked_omega
    accel, alpha = base.max_accel, base.max_alpha
    if reach is not None:
        accel, alpha = min(accel, reach.accel), min(alpha, reach.alpha)
    dwa = _from_config(
        DwaParams,
        config,
        max_v=fastest_v,
        max_omega=fastest_omega,
        max_accel=accel,
        max_alpha=alpha,
        period=1.0 / nav.rate_hz,
        radius=radius,
    )
    recovery = nav.recovery
    return _from_config(
        NavigationParams,
        config,
        dwa=dwa,
        progress_window=recovery.progress_window / slower(reach),
        backup_speed=min(recovery.backup_speed, fastest_v),
        follow_speed=min(recovery.follow_speed, fastest_v),
        spin_speed=min(recovery.spin_speed, fastest_omega),
    )


def odometry_error(config: StackConfig) -> OdometryError | None:
    """The simulated odometry error of ``world.odometry_error`` (None when off)."""
    error = config.world.odometry_error
    if not error.enabled:
        return None
    return OdometryError(**error.model_dump())


def localizer_params(config: StackConfig) -> LocalizerParams:
    """The localizer's settings from ``nav.localization.*``."""
    loc = config.nav.localization
    return LocalizerParams(
        match=MatchParams(
            linear_window=loc.linear_window,
            linear_step=loc.resolution,
            angular_window=loc.angular_window,
            max_distance=loc.max_distance,
        ),
        resolution=loc.resolution,
        half_size=loc.half_size,
        update_distance=loc.update_distance,
        update_angle=loc.update_angle,
        map_period=loc.map_period,
    )


def safety_params(config: StackConfig, geometry: RobotGeometry) -> SafetyParams:
    """The safety layer's settings from ``safety.*``, the base's limits and rates."""
    safety, base = config.safety, config.base
    return _from_config(
        SafetyParams,
        config,
        radius=centre_clearance(
            safety.clearance, geometry.footprint_radius, safety.footprint_padding
        ),
        latency=1.0 / safety.rate_hz + 1.0 / base.rate_hz + safety.drive_lag,
    )
