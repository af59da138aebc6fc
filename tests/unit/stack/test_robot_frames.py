"""/tf's frame ids come from the model (issue 38): the base body, the lidar's and the
IMU's site or body; ``robot.frames`` overrides each; otonav's own robot keeps
base_link, laser, imu_link."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.actors._topics import FRAMES, Frames
from otonav.stack._config import RobotConfig
from otonav.stack._loading import load_stack_file
from otonav.stack._overrides import apply_overrides
from otonav.stack._robot import robot_frames

pytestmark = pytest.mark.unit

ROBOTS = Path(__file__).resolve().parents[3] / "examples" / "robots"


def test_otonavs_robot_keeps_its_frames() -> None:
    assert robot_frames(RobotConfig()) == FRAMES


def test_a_models_frames_are_its_own_names() -> None:
    assert robot_frames(RobotConfig(model="burger")) == Frames("base_link", "base_scan", "imu_link")
    tb3 = load_stack_file(ROBOTS / "turtlebot3_burger.yaml")
    assert robot_frames(tb3.robot) == Frames("base_footprint", "base_scan", "imu_link")


def test_robot_frames_overrides_the_models_names() -> None:
    tb3 = load_stack_file(ROBOTS / "turtlebot3_burger.yaml")
    tb3 = apply_overrides(tb3, ["robot.frames.base=base_link", "robot.frames.laser=lds"])
    assert robot_frames(tb3.robot) == Frames("base_link", "lds", "imu_link")
