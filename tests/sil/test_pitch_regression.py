"""The seeds' pitch bug: with no caster and an unlimited-torque drive the nose dives,
forward beams hit the floor, and the guard stops the robot for a wall that is not
there. The shipped model must never show a floor hit."""

from __future__ import annotations

import math

import anyio
import pytest

from otonav.actors import topics
from otonav.hal import RobotHardwareInterface
from otonav.hal.mujoco import MujocoInterface
from otonav.msgs import LaserScan, NavState, PoseStamped
from otonav.msgs._geometry import Point, Pose
from otonav.runtime import LATCHED_QOS, Actor, Input
from otonav.scenario import ScenarioConfig
from otonav.stack import GuardConfig, NavConfig, StackConfig, WorldConfig
from otonav.stack._config import RobotConfig
from otonav.testing import running_stack

pytestmark = pytest.mark.sil


class FloorWatch(Actor):
    """Counts, for every scan as it is published, the beams that hit the floor, and the
    nav states reported while the true clearance ahead is wide open."""

    scan = Input(topics.SCAN, LaserScan, topics.SENSOR_QOS)
    nav_state = Input(topics.NAV_STATE, NavState, topics.COMMAND_QOS)

    def __init__(self) -> None:
        super().__init__("floor_watch")
        self.hal: RobotHardwareInterface | None = None
        self.scans = 0
        self.floor_hits = 0
        self.false_blocks = 0
        self.max_pitch = 0.0

    async def run(self) -> None:
        async with anyio.create_task_group() as tg:
            tg.start_soon(self._scans)
            async for state in self.nav_state:
                if state.state == "blocked" and self._true_clearance() > 1.0:
                    self.false_blocks += 1

    async def _scans(self) -> None:
        async for _scan in self.scan:
            assert isinstance(self.hal, MujocoInterface)
            self.scans += 1
            self.floor_hits += int(self.hal.scan_floor_mask().sum())
            self.max_pitch = max(self.max_pitch, abs(self.hal.ground_truth().pitch))

    def _true_clearance(self) -> float:
        assert self.hal is not None
        truth = self.hal.ground_truth()
        boxes = self.hal.obstacles() + self.hal.walls()
        return min((b.distance_to(truth.x, truth.y) for b in boxes), default=math.inf)


# The seeds' guard looked 1 m ahead: a floor hit at ~0.9 m (the nose-down bug at rest)
# reads as a wall there.
SEEDS_GUARD = GuardConfig(stop_distance=1.0)


async def _drive(
    scene: str,
    goal: tuple[float, float],
    robot: RobotConfig | None,
    seconds: float,
    guard: GuardConfig = GuardConfig(),
) -> FloorWatch:
    watch = FloorWatch()
    # The stop-only planner: its front-sector guard is what the floor hits fooled.
    config = StackConfig(
        world=WorldConfig(scene=scene),
        guard=guard,
        nav=NavConfig(planner="stop"),
        robot=robot or RobotConfig(),
    )
    async with running_stack(config, extra_actors=[watch]) as stack:
        watch.hal = stack.hal
        publisher = stack.system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS)
        await publisher.publish(PoseStamped(pose=Pose(position=Point(x=goal[0], y=goal[1]))))
        await stack.system.clock.sleep(seconds)
    return watch


@pytest.mark.sim(wall_ceiling=120)
async def test_no_caster_unlimited_torque_dives_and_the_guard_falsely_blocks(
    sabotaged_robot_config: RobotConfig,
) -> None:
    watch = await _drive("empty", (3.0, 0.0), sabotaged_robot_config, 6.0, SEEDS_GUARD)
    assert watch.scans >= 50
    assert watch.floor_hits > 0
    assert watch.max_pitch > math.radians(5)
    assert watch.false_blocks > 0  # stopped by the floor, more than 1 m from any wall


@pytest.mark.sim(wall_ceiling=120)
async def test_same_guard_on_the_shipped_model_is_never_falsely_blocked() -> None:
    watch = await _drive("empty", (3.0, 0.0), None, 6.0, SEEDS_GUARD)
    assert watch.scans >= 50
    assert watch.floor_hits == 0
    assert watch.false_blocks == 0


@pytest.mark.sim(wall_ceiling=120)
async def test_shipped_model_never_sees_the_floor_during_the_acceptance_run() -> None:
    scenario = ScenarioConfig()
    scene = scenario.scene or StackConfig().world.scene
    watch = await _drive(scene, (scenario.goal.x, scenario.goal.y), None, 15.0)
    assert watch.scans >= 140
    assert watch.floor_hits == 0
    assert watch.false_blocks == 0
    assert watch.max_pitch < math.radians(2)
