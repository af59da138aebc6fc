"""Checks of a scenario against its world: a goal the robot can never reach is a
configuration error (exit 2), not a failed run."""

from __future__ import annotations

import math

from otonav import limits
from otonav.hal import BoxObstacle
from otonav.scenario._config import ScenarioConfig
from otonav.stack import StackConfig
from otonav.stack._files import ConfigFileError


def arena_bounds(walls: tuple[BoxObstacle, ...]) -> tuple[float, float, float, float] | None:
    """The inner rectangle (x_min, x_max, y_min, y_max) enclosed by axis-aligned walls
    around the origin; None when the scene has no walls on every side."""
    x_min, x_max, y_min, y_max = -math.inf, math.inf, -math.inf, math.inf
    for wall in walls:
        if wall.half_x <= wall.half_y:  # a wall along y, at some x
            if wall.x < 0:
                x_min = max(x_min, wall.x + wall.half_x)
            else:
                x_max = min(x_max, wall.x - wall.half_x)
        elif wall.y < 0:
            y_min = max(y_min, wall.y + wall.half_y)
        else:
            y_max = min(y_max, wall.y - wall.half_y)
    bounds = (x_min, x_max, y_min, y_max)
    return bounds if all(math.isfinite(b) for b in bounds) else None


def check_goal(
    scenario: ScenarioConfig,
    scene: str,
    obstacles: tuple[BoxObstacle, ...],
    walls: tuple[BoxObstacle, ...],
    *,
    source: str,
) -> None:
    """Raise :class:`ConfigFileError` when the goal or the start is outside the arena or
    closer to an obstacle than the clearance the scenario demands."""
    bounds = arena_bounds(walls)
    points = (
        ("goal", scenario.goal.x, scenario.goal.y),
        ("start", scenario.start.x, scenario.start.y),
    )
    for key, px, py in points:
        if bounds is not None:
            x_min, x_max, y_min, y_max = bounds
            if not (x_min < px < x_max and y_min < py < y_max):
                raise ConfigFileError(
                    f"{source}: {key}: ({px:g}, {py:g}) is outside the arena of scene "
                    f"'{scene}' (valid: x in ({x_min:g}, {x_max:g}), "
                    f"y in ({y_min:g}, {y_max:g}))"
                )
        # Walls too: the judge measures clearance to both, so a start or goal closer
        # than min_clearance to a wall fails every run (or starts it failed).
        boxes = [("obstacle", box) for box in obstacles] + [("wall", box) for box in walls]
        for kind, box in boxes:
            gap = box.distance_to(px, py)
            if gap < scenario.min_clearance:
                where = "inside" if gap == 0 else f"{gap:.2f} m from"
                raise ConfigFileError(
                    f"{source}: {key}: ({px:g}, {py:g}) is {where} the {kind} at "
                    f"({box.x:g}, {box.y:g}); it needs at least min_clearance = "
                    f"{scenario.min_clearance:g} m from every obstacle and wall"
                )


def check_cost(scenario: ScenarioConfig, stack: StackConfig, boxes: int, *, source: str) -> None:
    """Raise :class:`ConfigFileError` when a run of this scenario on this stack is
    estimated to take more wall time than :data:`~otonav.limits.WALL_BUDGET_S`
    (each value within its own bound, together too much: a tiny timestep and a long
    budget, a dense lidar at a high rate, ...). ``boxes``: obstacles and walls."""
    rates = stack.rates_hz()
    estimate = limits.estimated_wall_s(
        sim_budget=scenario.sim_budget,
        timestep=stack.world.timestep,
        rates_hz=sum(rates.values()),
        scan_hz=stack.rates.scan_hz,
        lidar_beams=stack.world.lidar_beams,
        boxes=boxes,
    )
    if estimate > limits.WALL_BUDGET_S:
        raise ConfigFileError(
            f"{source}: sim_budget = {scenario.sim_budget:g} s with world.timestep = "
            f"{stack.world.timestep:g} s, {sum(rates.values()):g} Hz of actor rates and "
            f"{stack.world.lidar_beams} lidar beams at {stack.rates.scan_hz:g} Hz is an "
            f"estimated {estimate:.0f} s of wall time, over the {limits.WALL_BUDGET_S:.0f} s "
            "a run may take; shorten sim_budget or lighten the stack"
        )
