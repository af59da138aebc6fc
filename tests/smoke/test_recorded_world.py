"""A recording made by ``running_stack`` (the pytest plugin's) says where its world's
obstacles and walls are, so the kept ``trajectory.png`` draws them, with the goal the
test published on /goal."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.actors import topics
from otonav.msgs import Point, Pose, PoseStamped
from otonav.runtime import LATCHED_QOS
from otonav.scenario._replay import recorded_plot
from otonav.testing import running_stack

pytestmark = pytest.mark.smoke


@pytest.mark.sim(wall_ceiling=60)
async def test_a_running_stack_recording_says_its_obstacles_and_goal(tmp_path: Path) -> None:
    recording = tmp_path / "run.mcap"
    async with running_stack(record_to=recording) as stack:
        boxes = stack.hal.obstacles() + stack.hal.walls()
        goal = stack.system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS)
        await goal.publish(PoseStamped(pose=Pose(position=Point(x=3.0, y=-0.5))))
        await stack.system.clock.sleep(0.5)
    plot = recorded_plot(recording)
    assert plot.goal == (3.0, -0.5)
    assert plot.obstacles is not None
    assert len(boxes) >= 8  # the obstacle scene: boxes and four walls
    assert plot.obstacles == boxes  # JSON keeps a float exactly
    assert len(plot.trajectory) >= 40
