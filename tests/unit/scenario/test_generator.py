"""The seeded world generator: determinism, path-existence labels on hand-built worlds,
budgets, and properties every generated world must have."""

from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import replace
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from otonav.hal import BoxObstacle
from otonav.scenario import ScenarioConfig
from otonav.scenario._generator import (
    DENSE,
    EMPTY_WALLS,
    SPARSE,
    WALLED_IN,
    budget_for,
    generate_world,
    generate_worlds,
    plan_path,
    walled_in,
)
from otonav.scenario._generator_grid import occupancy, shortest_path

pytestmark = pytest.mark.unit

INFLATION = SPARSE.inflation  # 0.543 m: footprint radius + clearance
SEEDS = st.integers(min_value=0, max_value=2**32 - 1)
# The property tests run a grid search per example: a coarser grid keeps them cheap.
COARSE = 0.1


def _wall_with_gap(gap: float | None, centre: float = 0.0) -> tuple[BoxObstacle, ...]:
    """A 0.2 m wall across the 10 m arena at x = 0, with a gap of ``gap`` m centred on
    y = ``centre`` (None: no gap)."""
    if gap is None:
        return (BoxObstacle(0.0, 0.0, 0.1, 5.0),)
    low_top, high_bottom = centre - gap / 2, centre + gap / 2
    return (
        BoxObstacle(0.0, (-5.0 + low_top) / 2, 0.1, (low_top + 5.0) / 2),
        BoxObstacle(0.0, (high_bottom + 5.0) / 2, 0.1, (5.0 - high_bottom) / 2),
    )


# -- the grid search on hand-built worlds --------------------------------------------------


def test_a_wall_without_a_gap_has_no_path_even_for_a_point() -> None:
    assert plan_path(_wall_with_gap(None), (-3.0, 0.0), (3.0, 0.0), 0.0) is None


@pytest.mark.parametrize("gap", [1.0, 1.08])
def test_a_gap_narrower_than_the_inflated_footprint_is_closed(gap: float) -> None:
    assert gap < 2 * INFLATION
    assert plan_path(_wall_with_gap(gap), (-3.0, 0.0), (3.0, 0.0), INFLATION) is None
    # ... and open for a point, which shows the wall, not the search, is what closes it
    assert plan_path(_wall_with_gap(gap), (-3.0, 0.0), (3.0, 0.0), 0.0) is not None


def test_a_gap_wider_than_the_inflated_footprint_is_open_and_the_path_goes_through_it() -> None:
    path = plan_path(_wall_with_gap(1.2, centre=2.0), (-3.0, 0.0), (3.0, 0.0), INFLATION)
    assert path is not None
    # Every path crosses x = 0 in the band the inflated gap leaves (y = 2 +- 0.057),
    # so none is shorter than two straight legs to its lower edge; the grid's answer
    # (string-pulled) is within a few per cent of that.
    bound = 2 * math.hypot(3.0, 2.0 - 0.057)
    assert bound - 1e-6 <= path.length_m <= 1.03 * bound
    assert any(abs(x) < 0.2 and abs(y - 2.0) < 0.06 for x, y in path.points)


def test_a_straight_open_path_is_the_straight_line() -> None:
    path = plan_path((), (-3.0, -1.0), (2.0, 2.0), INFLATION)
    assert path is not None
    assert path.length_m == pytest.approx(math.hypot(5.0, 3.0))
    assert path.points == ((-3.0, -1.0), (2.0, 2.0))


def test_a_diagonal_pinch_between_two_boxes_does_not_let_a_point_through() -> None:
    # Two boxes meeting at one corner (0, 0): the only way from lower left to upper
    # right that is not around them would cut that corner.
    boxes = (BoxObstacle(-2.5, 2.5, 2.5, 2.5), BoxObstacle(2.5, -2.5, 2.5, 2.5))
    assert plan_path(boxes, (-2.0, -2.0), (2.0, 2.0), 0.0) is None


def test_start_or_goal_inside_the_inflation_means_no_path() -> None:
    box = (BoxObstacle(0.0, 0.0, 0.5, 0.5),)
    assert plan_path(box, (0.8, 0.0), (3.0, 0.0), INFLATION) is None
    assert plan_path(box, (1.1, 0.0), (3.0, 0.0), INFLATION) is not None


def test_the_arena_edge_is_inflated_too() -> None:
    assert plan_path((), (4.6, 0.0), (-3.0, 0.0), INFLATION) is None
    assert plan_path((), (4.4, 0.0), (-3.0, 0.0), INFLATION) is not None


def test_occupancy_refuses_nonsense() -> None:
    with pytest.raises(ValueError, match="inflation"):
        occupancy((), 5.0, -0.1)


@settings(max_examples=40, deadline=None)
@given(
    sx=st.floats(-4.0, 4.0),
    sy=st.floats(-4.0, 4.0),
    gx=st.floats(-4.0, 4.0),
    gy=st.floats(-4.0, 4.0),
)
def test_a_path_is_never_shorter_than_the_straight_line(
    sx: float, sy: float, gx: float, gy: float
) -> None:
    # One box in the middle of the arena splits nothing: a path exists exactly when
    # both ends are in free cells.
    grid = occupancy((BoxObstacle(0.0, 0.0, 1.0, 0.3, 0.4),), 5.0, 0.3, COARSE)
    path = shortest_path(grid, (sx, sy), (gx, gy))
    assert (path is not None) == (grid.free_at(sx, sy) and grid.free_at(gx, gy))
    if path is None:
        return
    assert path.length_m >= math.dist((sx, sy), (gx, gy)) - 1e-9
    assert path.points[0] == (sx, sy)
    assert path.points[-1] == (gx, gy)
    # every way-point is in free space
    assert all(grid.free_at(x, y) for x, y in path.points)


# -- generated worlds ----------------------------------------------------------------------


def test_the_same_seed_gives_the_same_world_and_another_seed_another() -> None:
    a, b = generate_world(7, DENSE), generate_world(7, DENSE)
    assert a == b
    assert a.scenario.model_dump_json() == b.scenario.model_dump_json()
    assert generate_world(8, DENSE).scenario != a.scenario
    assert [w.scenario for w in generate_worlds(3, SPARSE, seed0=5)] == [
        generate_world(s, SPARSE).scenario for s in (5, 6, 7)
    ]


def test_a_world_survives_a_round_trip_through_json() -> None:
    # What a sweep's worker or a YAML file gets back must be the same world.
    scenario = generate_world(3, DENSE).scenario
    assert ScenarioConfig.model_validate_json(scenario.model_dump_json()) == scenario


def test_generated_worlds_are_in_the_empty_scene_and_named_by_seed() -> None:
    world = generate_world(42, SPARSE)
    assert world.scenario.scene == "empty"
    assert world.scenario.name == "sparse-42"
    assert world.scenario.seed == 42
    assert world.scenario.expect == "reached"


def test_unreachable_draws_are_redrawn_or_labelled() -> None:
    # Find a seed whose first dense draw has no path (about one in five)...
    lone = replace(DENSE, resample_unreachable=False)
    labelled = next(w for w in generate_worlds(60, lone) if not w.reachable)
    assert labelled.shortest_path_m is None
    assert labelled.scenario.expect == "unreachable"
    boxes = tuple(b.to_obstacle() for b in labelled.scenario.obstacles) + EMPTY_WALLS
    s, g = labelled.scenario.start, labelled.scenario.goal
    assert plan_path(boxes, (s.x, s.y), (g.x, g.y), DENSE.inflation) is None
    # ... redrawn from the same seed by default: a later draw of the same stream
    redrawn = generate_world(labelled.seed, DENSE)
    assert redrawn.reachable
    assert redrawn.attempts > 1


@settings(max_examples=25, deadline=None)
@given(seed=SEEDS, dense=st.booleans())
def test_every_generated_world_keeps_its_promises(seed: int, dense: bool) -> None:
    params = replace(DENSE if dense else SPARSE, resolution=COARSE)
    world = generate_world(seed, params)
    s = world.scenario
    start, goal = (s.start.x, s.start.y), (s.goal.x, s.goal.y)
    lo, hi = params.start_goal_distance
    assert lo - 0.01 <= math.dist(start, goal) <= hi + 0.01
    boxes = [b.to_obstacle() for b in s.obstacles]
    for point in (start, goal):
        assert all(b.distance_to(*point) >= params.keepout for b in boxes)
        assert all(w.distance_to(*point) >= params.keepout - 0.001 for w in EMPTY_WALLS)
    _, hi_n = params.obstacle_count
    assert len(boxes) <= hi_n
    assert world.reachable == (world.shortest_path_m is not None)
    if world.reachable:
        assert world.shortest_path_m is not None
        assert world.shortest_path_m >= math.dist(start, goal) - 1e-9
        assert s.sim_budget == budget_for(world.shortest_path_m, params)
        assert world.optimal_time_s == pytest.approx(world.shortest_path_m / params.max_speed)


@settings(max_examples=8, deadline=None)
@given(seed=SEEDS)
def test_a_walled_in_goal_is_closed_even_to_a_point(seed: int) -> None:
    params = replace(WALLED_IN, resolution=COARSE)
    world = generate_world(seed, params)
    s = world.scenario
    assert not world.reachable
    assert s.expect == "unreachable"
    boxes = tuple(b.to_obstacle() for b in s.obstacles) + EMPTY_WALLS
    # a point (no inflation) on a 5 cm grid: the 0.2 m ring walls are 4 cells thick
    assert plan_path(boxes, (s.start.x, s.start.y), (s.goal.x, s.goal.y), 0.0) is None
    # the goal itself is clear by the clearance: the ring is around it, not on it
    assert all(b.distance_to(s.goal.x, s.goal.y) >= params.clearance for b in boxes)
    # the budget is the one the world would have without the ring
    assert world.shortest_path_m is not None
    assert s.sim_budget == budget_for(world.shortest_path_m, params)


def test_walled_in_keeps_the_density_of_its_base() -> None:
    params = walled_in(DENSE)
    assert params.walled_in
    assert params.obstacle_count == DENSE.obstacle_count
    assert not generate_world(1, params).reachable


def test_a_smaller_arena_is_walled_and_holds_the_world() -> None:
    params = replace(SPARSE, arena=6.0, start_goal_distance=(3.0, 4.0))
    world = generate_world(2, params)
    s = world.scenario
    for x, y in ((s.start.x, s.start.y), (s.goal.x, s.goal.y)):
        assert max(abs(x), abs(y)) <= 3.0 - params.keepout + 1e-3
    assert world.shortest_path_m is not None


# -- budgets and the BARN metric --------------------------------------------------------------


@settings(deadline=None)  # a shared, busy machine: no wall-clock deadline
@given(a=st.floats(0.0, 50.0), b=st.floats(0.0, 50.0))
def test_budgets_grow_with_the_path(a: float, b: float) -> None:
    low, high = sorted((a, b))
    assert budget_for(low, SPARSE) <= budget_for(high, SPARSE)
    assert budget_for(high, SPARSE) >= SPARSE.budget_factor * high / SPARSE.max_speed


def test_budget_example() -> None:
    # 7 m at 0.4 m/s: 17.5 s optimal; 3 x 17.5 + 30 = 82.5 -> 83 s
    assert budget_for(7.0, SPARSE) == 83.0


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("arena", 12.0),
        ("obstacle_count", (5, 2)),
        ("obstacle_size", (0.0, 0.5)),
        ("start_goal_distance", (6.0, 20.0)),
        ("keepout", 0.4),
        ("budget_factor", 0.5),
        ("ring_inner", (0.3, 0.5)),
        ("max_speed", 0.0),
    ],
)
def test_bad_params_name_the_field(field: str, value: Any) -> None:
    with pytest.raises(ValueError, match=f"WorldParams.{field}"):
        replace(SPARSE, **{field: value})


def test_the_generator_does_not_load_the_simulator() -> None:
    # A fresh interpreter: this one has imported everything already.
    code = (
        "import sys, otonav.scenario._generator as g; g.generate_world(0); "
        "print(sorted({m.split('.')[0] for m in sys.modules} & {'mujoco', 'anyio'}))"
    )
    child = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=False
    )
    assert child.returncode == 0, child.stderr
    assert child.stdout.strip() == "[]"
