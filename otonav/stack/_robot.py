"""The stack config's ``robot`` section as a :class:`~otonav.hal._description.RobotDescription`:
a built-in robot's names and mounts, the user's keys over them, a model path resolved
against the config file it was written in."""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Final

from otonav.actors._topics import FRAMES, Frames
from otonav.hal._description import BUILTIN_ROBOTS, Mount, RobotDescription, builtin_robot
from otonav.hal._interface import RobotHardwareInterface
from otonav.hal._types import Reach
from otonav.params import BaseConfig, NavConfig
from otonav.stack._config import MountConfig, RobotConfig, StackConfig
from otonav.stack._files import ConfigFileError

__all__ = [
    "deadband",
    "describe_robot",
    "nav_speeds",
    "reached",
    "robot_base",
    "robot_frames",
    "slower",
]


def _mount(config: MountConfig | None) -> Mount | None:
    if config is None:
        return None
    return Mount(site=config.site, body=config.body, pos=config.pos)


def describe_robot(config: RobotConfig) -> RobotDescription:
    """The robot the HAL builds for ``config`` (``ConfigFileError`` naming the key when
    a model file needs names the config does not give)."""
    if config.model in BUILTIN_ROBOTS:
        base = builtin_robot(config.model)
    else:
        if not Path(config.model).is_file():
            raise ConfigFileError(
                f"robot.model: {config.model!r} is neither a built-in robot "
                f"({', '.join(BUILTIN_ROBOTS)}) nor an existing MJCF or URDF file"
            )
        missing = [k for k in ("base", "left_wheel", "right_wheel") if getattr(config, k) is None]
        if missing:
            raise ConfigFileError(
                f"robot.{missing[0]}: required with robot.model: {config.model} "
                "(name the model's base body and its two wheel joints: robot.base, "
                "robot.left_wheel, robot.right_wheel)"
            )
        base = RobotDescription(
            model=config.model, label=config.model, base="", left_wheel="", right_wheel=""
        )
    return RobotDescription(
        model=base.model,
        label=base.label,
        base=config.base or base.base,
        left_wheel=config.left_wheel or base.left_wheel,
        right_wheel=config.right_wheel or base.right_wheel,
        lidar=_mount(config.lidar) or base.lidar,
        imu=_mount(config.imu) or base.imu,
        wheel_radius=config.wheel_radius,
        wheel_separation=config.wheel_separation,
        footprint=config.footprint,
        max_v=config.max_v if config.max_v is not None else base.max_v,
        max_omega=config.max_omega if config.max_omega is not None else base.max_omega,
    )


def _frame(mount: Mount | None, default: str) -> str:
    if mount is None:
        return default
    return mount.site or mount.body or default


def robot_frames(config: RobotConfig) -> Frames:
    """The frame ids otonav stamps: ``robot.frames`` where set, else the model's names
    (the base body; the lidar's and the IMU's site or body), else otonav's."""
    given = config.frames
    if config.model == "otonav":
        model = FRAMES
    else:
        robot = describe_robot(config)
        model = Frames(
            base=robot.base,
            laser=_frame(robot.lidar, FRAMES.laser),
            imu=_frame(robot.imu, FRAMES.imu),
        )
    return Frames(
        base=given.base or model.base,
        laser=given.laser or model.laser,
        imu=given.imu or model.imu,
    )


def _one_speed(key: str, stated: float | None, values: dict[str, tuple[float, float]]) -> float:
    """The limit a section uses for ``key`` (``max_v``, ``max_omega``) given the robot's
    stated top speed: the robot's; a section's key set away from its default (``values``:
    section -> (set, default)) lowers it, with a warning that it overrides the robot's
    (issue 42: one key for the top speed). With no stated speed, the section's own."""
    section = next(iter(values))
    value, default = values[section]
    if stated is None:
        return value
    if value == default:
        return stated
    if value != stated:
        warnings.warn(
            f"{section}.{key} {value:g} overrides robot.{key} {stated:g}"
            + ("" if value < stated else f" (capped at robot.{key})"),
            stacklevel=3,
        )
    return min(value, stated)


def robot_base(stack: StackConfig) -> BaseConfig:
    """``stack.base`` with the robot's top speeds (``robot.max_v`` / ``robot.max_omega``,
    or a built-in description's) as its speed limits, in either direction; a
    ``base.max_v`` / ``base.max_omega`` set away from its default lowers them (a warning
    says so)."""
    robot = describe_robot(stack.robot)
    base = stack.base
    defaults = BaseConfig()
    updates = {
        key: _one_speed(
            key, getattr(robot, key), {"base": (getattr(base, key), getattr(defaults, key))}
        )
        for key in ("max_v", "max_omega")
    }
    return base.model_copy(update=updates)


def nav_speeds(stack: StackConfig) -> tuple[float, float]:
    """The navigator's top speed and yaw rate: the robot's stated ones (``nav.max_v`` /
    ``nav.max_omega`` set away from their defaults lower them), within the base's."""
    robot = describe_robot(stack.robot)
    base, nav, defaults = robot_base(stack), stack.nav, NavConfig()
    v = _one_speed("max_v", robot.max_v, {"nav": (nav.max_v, defaults.max_v)})
    w = _one_speed("max_omega", robot.max_omega, {"nav": (nav.max_omega, defaults.max_omega)})
    return min(v, base.max_v), min(w, base.max_omega)


REACHED: Final = 0.95
"""A robot that reaches this share of the asked speed is taken at the asked figure (the
identification's few percent are not worth a different navigator; ADR 0066)."""


def reached(stack: StackConfig, hal: RobotHardwareInterface) -> Reach | None:
    """What ``hal``'s robot really reaches when the navigator asks its top speeds (the
    nav's, capped by the base's and the robot's); None when the HAL cannot tell."""
    return hal.reach(*nav_speeds(stack))


def slower(reach: Reach | None) -> float:
    """The share of the asked speed the robot reaches: 1.0 when it reaches at least
    :data:`REACHED` of it, none of it, or nobody measured."""
    if reach is None:
        return 1.0
    share = reach.v / reach.asked_v
    return share if 0.0 < share < REACHED else 1.0  # 0: it never moved; nothing to scale


def deadband(reach: Reach | None) -> float:
    """rad/s the base adds to each turning wheel's command (ADR 0066): the robot's
    identified deadband when it is slower than asked, else 0 (a robot that reaches its
    speed is driven exactly as before)."""
    return reach.deadband if reach is not None and slower(reach) < 1.0 else 0.0
