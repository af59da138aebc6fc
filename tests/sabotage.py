"""The seeds' pitch bug as a robot model, for the regression tests that must show it:
otonav's robot with its caster removed and its wheel drives made stiff (kv 10) with no
torque limit. Test equipment, not a variant the HAL offers (ADR 0056): the edited MJCF
is written next to the test and loaded as any user's robot is."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Final

from otonav.hal._description import RobotDescription, builtin_robot
from otonav.stack._config import MountConfig, RobotConfig

BUG_KV: Final = 10.0
"""Velocity-actuator gain (N m s/rad) of the sabotaged drives."""

_CASTER = re.compile(r'\s*<geom name="caster"[^>]*/>', re.S)
_MOTOR = '<velocity kv="5" forcelimited="true" forcerange="-0.5 0.5"/>'


def sabotaged_model(folder: Path) -> Path:
    """Write the sabotaged copy of otonav's robot.xml into ``folder``; its path."""
    text = Path(builtin_robot("otonav").model).read_text()
    assert len(_CASTER.findall(text)) == 1, "otonav's robot.xml has no single caster geom"
    assert _MOTOR in text, "otonav's robot.xml changed its motor class"
    text = _CASTER.sub("", text).replace(
        _MOTOR, f'<velocity kv="{BUG_KV:g}" forcelimited="false" forcerange="-0.5 0.5"/>'
    )
    path = folder / "robot_no_caster_unlimited_torque.xml"
    path.write_text(text)
    return path


def sabotaged_robot(folder: Path) -> RobotDescription:
    """otonav's robot description with the sabotaged model (for ``MujocoInterface``)."""
    return dataclasses.replace(builtin_robot("otonav"), model=str(sabotaged_model(folder)))


def sabotaged_robot_config(folder: Path) -> RobotConfig:
    """The same as a stack config's ``robot`` section (for ``running_stack``)."""
    robot = builtin_robot("otonav")
    return RobotConfig(
        model=str(sabotaged_model(folder)),
        base=robot.base,
        left_wheel=robot.left_wheel,
        right_wheel=robot.right_wheel,
        lidar=MountConfig(site="lidar"),
        imu=MountConfig(site="imu"),
    )
