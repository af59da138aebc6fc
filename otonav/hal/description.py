"""A robot description: which model file, the names of its base and wheels, where its
sensors sit, and any value that overrides what the HAL derives from the model.

Plain data, no simulator imports. ``otonav.hal.mujoco`` builds the robot from it (the
ROS 2 analogue is a URDF plus the ``ros2_control`` names of the wheel joints); the
stack config's ``robot`` section becomes one (``otonav.stack.robot``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import resources
from importlib.resources.abc import Traversable
from typing import Final

__all__ = [
    "BUILTIN_ROBOTS",
    "Mount",
    "RobotDescription",
    "builtin_robot",
]


@dataclass(frozen=True, slots=True)
class Mount:
    """A sensor's place: an existing ``site`` of the model, or ``pos`` (m) in the frame
    of ``body`` (None: the robot's base). A mounted sensor's axes are the base's."""

    site: str | None = None
    body: str | None = None
    pos: tuple[float, float, float] | None = None


@dataclass(frozen=True, slots=True)
class RobotDescription:
    """Everything the HAL needs to put a robot into a world.

    ``model`` is the MJCF or URDF file (a real path); ``label`` names the robot in
    messages (a built-in name or the path as the user wrote it). ``key`` prefixes the
    names in error messages (``robot.`` for the stack config's section). The optional
    values override what is derived from the model; ``max_v`` / ``max_omega`` are the
    robot's top speeds (None: not stated).
    """

    model: str
    label: str
    base: str
    left_wheel: str
    right_wheel: str
    lidar: Mount | None = None
    imu: Mount | None = None
    wheel_radius: float | None = None
    wheel_separation: float | None = None
    footprint: tuple[tuple[float, float], ...] | None = None
    max_v: float | None = None
    max_omega: float | None = None
    key: str = "robot."
    overrides: dict[str, str] = field(default_factory=dict)
    """How each name or value was chosen (for the provenance record)."""


@dataclass(frozen=True, slots=True)
class _Builtin:
    file: str
    base: str
    left_wheel: str
    right_wheel: str
    lidar: Mount
    imu: Mount
    max_v: float | None = None
    max_omega: float | None = None
    what: str = ""


BUILTIN_ROBOTS: Final[dict[str, _Builtin]] = {
    "otonav": _Builtin(
        file="robot.xml",
        base="chassis",
        left_wheel="left_wheel",
        right_wheel="right_wheel",
        lidar=Mount(site="lidar"),
        imu=Mount(site="imu"),
        what="otonav's robot: 2.5 kg, wheels r 0.05 m 0.22 m apart, 360-beam lidar",
    ),
    "burger": _Builtin(
        file="robots/burger.xml",
        base="base_link",
        left_wheel="wheel_left_joint",
        right_wheel="wheel_right_joint",
        lidar=Mount(site="base_scan"),
        imu=Mount(site="imu_link"),
        max_v=0.22,
        max_omega=2.84,
        what="a TurtleBot3 Burger's dimensions: wheels r 0.033 m 0.160 m apart, 0.22 m/s",
    ),
}
"""The robots shipped in ``otonav/hal/assets`` by name."""


def _assets() -> Traversable:
    return resources.files("otonav.hal").joinpath("assets")


def builtin_robot(name: str) -> RobotDescription:
    """The description of a built-in robot (``KeyError`` for an unknown name)."""
    spec = BUILTIN_ROBOTS[name]
    return RobotDescription(
        model=str(_assets().joinpath(spec.file)),
        label=name,
        base=spec.base,
        left_wheel=spec.left_wheel,
        right_wheel=spec.right_wheel,
        lidar=spec.lidar,
        imu=spec.imu,
        max_v=spec.max_v,
        max_omega=spec.max_omega,
    )
