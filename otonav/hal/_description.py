"""A robot description: which model file, the names of its base and wheels, where its
sensors sit, and any value that overrides what the HAL derives from the model.

Plain data, no simulator imports. ``otonav.hal.mujoco`` builds the robot from it (the
ROS 2 analogue is a URDF plus the ``ros2_control`` names of the wheel joints); the
stack config's ``robot`` section becomes one (``otonav.stack._robot``).
"""

from __future__ import annotations

import atexit
import shutil
import tempfile
from dataclasses import dataclass, field, replace
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
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


BUILTIN_ROBOTS: Final[dict[str, RobotDescription]] = {
    # otonav's robot: 2.5 kg, wheels r 0.05 m 0.22 m apart, 360-beam lidar
    "otonav": RobotDescription(
        "robot.xml", "otonav", "chassis", "left_wheel", "right_wheel", Mount("lidar"), Mount("imu")
    ),
    # a TurtleBot3 Burger's dimensions: wheels r 0.033 m 0.160 m apart, 0.22 m/s
    "burger": RobotDescription(
        "robots/burger.xml",
        "burger",
        "base_link",
        "wheel_left_joint",
        "wheel_right_joint",
        Mount("base_scan"),
        Mount("imu_link"),
        max_v=0.22,
        max_omega=2.84,
    ),
}
"""The robots shipped in ``otonav/hal/assets`` by name (``model`` relative to it)."""


def _shipped() -> Traversable:
    return resources.files("otonav.hal").joinpath("assets")


_copy: list[Path] = []  # the one copy, removed at exit


def assets_dir() -> Path:
    """``otonav/hal/assets`` as a real folder: the package's own, or, when the package is
    not on a filesystem (zipped), a copy of the whole tree made once per process (MuJoCo
    reads files, and a scene's ``<include>`` and a robot's ``robots/`` need their
    neighbours)."""
    root = _shipped()
    if isinstance(root, Path):
        return root
    if not _copy:
        tmp = Path(tempfile.mkdtemp(prefix="otonav-assets-"))
        atexit.register(shutil.rmtree, tmp, ignore_errors=True)
        _copy_tree(root, tmp)
        _copy.append(tmp)
    return _copy[0]


def _copy_tree(source: Traversable, target: Path) -> None:
    for entry in source.iterdir():
        if entry.is_dir():
            (target / entry.name).mkdir()
            _copy_tree(entry, target / entry.name)
        else:
            with entry.open("rb") as src, (target / entry.name).open("wb") as dst:
                shutil.copyfileobj(src, dst)


def builtin_robot(name: str) -> RobotDescription:
    """The description of a built-in robot (``KeyError`` for an unknown name)."""
    shipped = BUILTIN_ROBOTS[name]
    return replace(shipped, model=str(assets_dir() / shipped.model), overrides={})
