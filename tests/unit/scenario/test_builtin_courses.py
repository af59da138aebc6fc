"""The built-in avoidance courses are geometrically what they claim to be (checked with
the world generator's grid search, no simulation): start and goal clear of every box
and wall by the clearance, a path for the footprint with the clearance kept where the
goal is expected to be reached and none where it is not, and a budget no shorter than
the generator would give that path."""

from __future__ import annotations

import pytest

from otonav.hal import BoxObstacle
from otonav.hal.mujoco import MujocoInterface
from otonav.scenario import ScenarioConfig
from otonav.scenario._builtin import AVOIDANCE, BUILTIN, GAP, describe
from otonav.scenario._generator import (
    EMPTY_WALLS,
    FOOTPRINT_RADIUS,
    SPARSE,
    budget_for,
    plan_path,
)

pytestmark = pytest.mark.unit

IDS = [s.name for s in AVOIDANCE]


def _boxes(s: ScenarioConfig) -> tuple[BoxObstacle, ...]:
    return tuple(b.to_obstacle() for b in s.obstacles) + EMPTY_WALLS


def test_the_generators_walls_are_the_empty_scenes() -> None:
    hal = MujocoInterface("empty")
    try:
        walls = sorted((w.x, w.y, w.half_x, w.half_y, w.yaw) for w in hal.walls())
    finally:
        hal.close()
    expected = sorted((w.x, w.y, w.half_x, w.half_y, w.yaw) for w in EMPTY_WALLS)
    assert len(walls) == len(expected)
    for got, want in zip(walls, expected, strict=True):
        assert got == pytest.approx(want, abs=1e-6)


def test_the_footprint_radius_is_the_robots() -> None:
    # The outline's farthest corner from base_link (chassis front corner is nearer).
    assert pytest.approx(0.2431, abs=1e-4) == FOOTPRINT_RADIUS


def test_every_course_is_built_in_and_on_the_empty_scene() -> None:
    for s in AVOIDANCE:
        assert BUILTIN[s.name] is s
        assert s.scene == "empty"
        assert describe(s.name)
    assert [s.name for s in AVOIDANCE if s.expect == "unreachable"] == ["walled_in"]


@pytest.mark.parametrize("scenario", AVOIDANCE, ids=IDS)
def test_start_and_goal_are_clear_of_boxes_and_walls(scenario: ScenarioConfig) -> None:
    for x, y in ((scenario.start.x, scenario.start.y), (scenario.goal.x, scenario.goal.y)):
        gap = min(b.distance_to(x, y) for b in _boxes(scenario))
        # room to turn in place with the footprint, and the clearance
        assert gap >= FOOTPRINT_RADIUS + scenario.min_clearance, (x, y, gap)


@pytest.mark.parametrize("scenario", AVOIDANCE, ids=IDS)
def test_a_path_exists_exactly_when_the_goal_should_be_reached(scenario: ScenarioConfig) -> None:
    start, goal = (scenario.start.x, scenario.start.y), (scenario.goal.x, scenario.goal.y)
    path = plan_path(_boxes(scenario), start, goal, FOOTPRINT_RADIUS + scenario.min_clearance)
    if scenario.expect == "unreachable":
        assert path is None
        # closed for a point too: no gap anywhere
        assert plan_path(_boxes(scenario), start, goal, 0.0) is None
        return
    assert path is not None
    assert scenario.sim_budget >= budget_for(path.length_m, SPARSE)
    # and driving the straight line would hit something: each course needs avoidance
    closest = min(
        b.distance_to(start[0] + t * (goal[0] - start[0]), start[1] + t * (goal[1] - start[1]))
        for t in (k / 400 for k in range(401))
        for b in _boxes(scenario)
    )
    assert closest < FOOTPRINT_RADIUS


def test_the_gap_is_wider_than_footprint_and_clearances_and_under_1_2_m() -> None:
    low, high = GAP.obstacles  # walls below and above the gap, along y at x = 0
    gap = (high.y - high.size_y / 2) - (low.y + low.size_y / 2)
    assert 2 * FOOTPRINT_RADIUS + 2 * GAP.min_clearance < gap < 1.2
