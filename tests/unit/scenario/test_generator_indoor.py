"""The indoor families (issue 24): seeded, labelled at the robot's real limit, with
budgets of 3 x optimal + 10 s."""

from __future__ import annotations

import math

import pytest
from benchmark_module import load_benchmark

pytestmark = pytest.mark.unit

INDOOR = load_benchmark("indoor_worlds.py")  # the indoor families are nav_bench.py's
INDOOR_FAMILIES: tuple[str, ...] = INDOOR.INDOOR_FAMILIES
PLAN_CLEARANCE: float = INDOOR.PLAN_CLEARANCE
generate_indoor = INDOOR.generate_indoor


@pytest.mark.parametrize("family", INDOOR_FAMILIES)
def test_each_family_is_seeded_labelled_and_budgeted(family: str) -> None:
    worlds = [generate_indoor(seed, family) for seed in range(2)]
    again = generate_indoor(1, family)
    assert again.scenario == worlds[1].scenario
    assert worlds[0].scenario != worlds[1].scenario
    for w in worlds:
        assert w.shortest_path_m is not None  # open (a walled-in room: with its door)
        budget = math.ceil(3.0 * w.shortest_path_m / 0.4 + 10.0)
        assert w.scenario.sim_budget == budget
        closed = family.startswith("walled_in")
        assert w.reachable is not closed
        assert w.scenario.expect == ("unreachable" if closed else "reached")


def test_slaloms_reach_down_to_the_passable_limit() -> None:
    """Gaps between wall faces of a slalom go below 0.8 m (limit 0.75 m + a cell)."""
    narrowest = math.inf
    for seed in range(6):
        boxes = generate_indoor(seed, "slalom").scenario.obstacles
        for a in boxes:
            for b in boxes:
                if a.x == b.x and a.size_x == b.size_x and a.y < b.y:  # one wall along y
                    narrowest = min(narrowest, (b.y - b.size_y / 2) - (a.y + a.size_y / 2))
                if a.y == b.y and a.size_y == b.size_y and a.x < b.x:  # one wall along x
                    narrowest = min(narrowest, (b.x - b.size_x / 2) - (a.x + a.size_x / 2))
    assert 2 * PLAN_CLEARANCE + 0.05 < narrowest < 0.8


def test_a_door_just_over_the_limit_is_labelled_open() -> None:
    """The labels pass a disc of the centre clearance, not footprint + clearance
    (0.54 m, which closed every gap under ~1.09 m)."""
    from otonav.hal import BoxObstacle
    from otonav.scenario._generator import plan_path

    wall = (BoxObstacle(0.0, 2.9, 0.05, 2.5), BoxObstacle(0.0, -2.9, 0.05, 2.5))  # gap 0.8
    assert plan_path(wall, (-2.0, 0.0), (2.0, 0.0), PLAN_CLEARANCE) is not None
