"""Seeded, BARN-like obstacle worlds: families of scenarios in which a success rate
means something.

Pure Python and numpy (no MuJoCo): a world is a :class:`ScenarioConfig` on the
``empty`` scene (a 10 x 10 m arena, inner wall faces at x, y = +-5 m) with box
obstacles, a start and a goal. Every draw comes from one ``numpy.random.Generator``
seeded with the world's seed, so the same ``(seed, params)`` always gives the same
config, on any machine and in any process (a sweep's workers rebuild worlds from seeds).

Each world is labelled by a grid search (:mod:`otonav.scenario._generator_grid`): is
there a path for the robot's footprint with the clearance kept all round, i.e. through
the arena with every box inflated by ``footprint_radius + clearance``, and how long is
the shortest one. Its time budget follows from that length (:func:`budget_for`).

API (what a sweep consumes)::

    world = generate_world(seed, SPARSE)        # -> GeneratedWorld
    world.scenario                              # a ScenarioConfig to run
    world.reachable, world.shortest_path_m, world.optimal_time_s
    worlds = generate_worlds(200, DENSE, seed0=1000)   # seeds 1000 .. 1199

``SPARSE`` and ``DENSE`` are the presets; ``WALLED_IN`` (or ``replace(params,
walled_in=True)``) closes a ring of walls around the goal: such worlds are
unreachable by construction and expect the navigator to say so (``expect:
unreachable``) within the budget the world would have without the ring.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from otonav.hal import BoxObstacle
from otonav.scenario._config import BoxSpec, GoalSpec, ScenarioConfig, StartSpec
from otonav.scenario._generator_grid import CELL, GridPath, occupancy, shortest_path

__all__ = (
    "DENSE",
    "EMPTY_ARENA_HALF",
    "EMPTY_WALLS",
    "FOOTPRINT_RADIUS",
    "PRESETS",
    "SPARSE",
    "WALLED_IN",
    "GeneratedWorld",
    "WorldParams",
    "budget_for",
    "generate_world",
    "generate_worlds",
    "plan_path",
    "walled_in",
)

EMPTY_ARENA_HALF = 5.0
"""m: the ``empty`` scene's walls have their inner faces at x, y = +-5 m."""
EMPTY_WALLS: tuple[BoxObstacle, ...] = (
    BoxObstacle(5.05, 0.0, 0.05, 5.1),
    BoxObstacle(-5.05, 0.0, 0.05, 5.1),
    BoxObstacle(0.0, 5.05, 5.1, 0.05),
    BoxObstacle(0.0, -5.05, 5.1, 0.05),
)
"""The ``empty`` scene's walls as in ``otonav/hal/assets/empty.xml`` (a static test
compares them with what the MuJoCo HAL reads)."""
FOOTPRINT_RADIUS = math.hypot(0.21, 0.1225)
"""m (0.243): the circle about base_link that holds the robot's outline (chassis box
reaching 0.21 m ahead of the axle, wheels at y = +-0.1225 m; ``robot.xml``)."""

_SCENARIO = ScenarioConfig()


@dataclass(frozen=True, slots=True)
class WorldParams:
    """How to draw a world. Lengths in m, times in s, angles in rad. Ranges are
    ``(low, high)``, inclusive for counts.

    Attributes:
        name: prefix of each scenario's name (``{name}-{seed}``).
        arena: side of the square the world uses, centred on the origin, in (2, 10]
            (the ``empty`` scene is 10 m; a smaller arena adds walls as boxes).
        obstacle_count: how many boxes, drawn uniformly.
        obstacle_size: side lengths of each box, each drawn uniformly; yaw uniform.
        start_goal_distance: straight-line start-goal distance, drawn uniformly.
        start_yaw_noise: the robot starts facing the goal +- up to this.
        keepout: no obstacle within this of the start or the goal (room to turn in
            place and to stop at the goal); also their margin from the arena's edge.
        footprint_radius: the robot's radius about its centre (see FOOTPRINT_RADIUS).
        clearance: the judge's minimum clearance; the scenario's ``min_clearance``.
        goal_tolerance: the scenario's goal tolerance.
        max_speed: the navigator's top speed (``nav.max_v``): optimal time = shortest
            path / max_speed.
        budget_factor, budget_slack: budget = factor * optimal time + slack (see
            :func:`budget_for`).
        resolution: grid cell size for the path search.
        walled_in: close a square ring of walls around the goal.
        ring_inner: half side of the ring's inside, drawn uniformly (> clearance).
        ring_thickness: the ring's wall thickness.
        resample_unreachable: redraw (from the same stream) until a path exists, at
            most ``max_attempts`` times; otherwise label the world and keep it. Ignored
            for ``walled_in`` worlds (the ring is redrawn with the world instead).
    """

    name: str = "world"
    arena: float = 10.0
    obstacle_count: tuple[int, int] = (8, 12)
    obstacle_size: tuple[float, float] = (0.3, 0.8)
    start_goal_distance: tuple[float, float] = (6.0, 8.0)
    start_yaw_noise: float = 0.5
    keepout: float = 0.9
    footprint_radius: float = FOOTPRINT_RADIUS
    clearance: float = 0.3
    goal_tolerance: float = _SCENARIO.goal_tolerance
    max_speed: float = 0.4
    budget_factor: float = 3.0
    budget_slack: float = 30.0
    resolution: float = CELL
    walled_in: bool = False
    ring_inner: tuple[float, float] = (0.7, 1.0)
    ring_thickness: float = 0.2
    resample_unreachable: bool = True
    max_attempts: int = 50

    def __post_init__(self) -> None:
        def need(ok: bool, what: str) -> None:
            if not ok:
                raise ValueError(f"WorldParams.{what}")

        def span(lo: float, hi: float) -> bool:
            return math.isfinite(lo) and math.isfinite(hi) and 0 <= lo <= hi

        need(
            2.0 < self.arena <= 2 * EMPTY_ARENA_HALF,
            f"arena must be in (2, 10] m, got {self.arena}",
        )
        need(
            span(*self.obstacle_count) and isinstance(self.obstacle_count[0], int),
            f"obstacle_count must be 0 <= low <= high, got {self.obstacle_count}",
        )
        need(
            span(*self.obstacle_size) and self.obstacle_size[0] > 0,
            f"obstacle_size must be 0 < low <= high, got {self.obstacle_size}",
        )
        need(
            span(*self.start_goal_distance) and self.start_goal_distance[0] > 0,
            f"start_goal_distance must be 0 < low <= high, got {self.start_goal_distance}",
        )
        reach = self.arena - 2 * self.keepout
        need(
            self.start_goal_distance[1] < reach * math.sqrt(2),
            f"start_goal_distance up to {self.start_goal_distance[1]} m does not fit an "
            f"arena of {self.arena} m with keepout {self.keepout} m "
            f"(at most {reach * math.sqrt(2):.2f} m)",
        )
        need(
            self.keepout >= self.footprint_radius + self.clearance,
            f"keepout must be >= footprint_radius + clearance "
            f"({self.footprint_radius + self.clearance:.3f} m), got {self.keepout}",
        )
        need(0 <= self.start_yaw_noise <= math.pi, "start_yaw_noise must be in [0, pi]")
        for key in ("footprint_radius", "clearance", "goal_tolerance", "max_speed"):
            value = getattr(self, key)
            need(math.isfinite(value) and value > 0, f"{key} must be > 0, got {value}")
        need(self.budget_factor >= 1.0, f"budget_factor must be >= 1, got {self.budget_factor}")
        need(self.budget_slack >= 0.0, f"budget_slack must be >= 0, got {self.budget_slack}")
        need(0 < self.resolution <= 0.2, f"resolution must be in (0, 0.2] m, got {self.resolution}")
        need(
            span(*self.ring_inner) and self.ring_inner[0] > self.clearance + self.goal_tolerance,
            f"ring_inner must be > clearance + goal_tolerance, got {self.ring_inner}",
        )
        need(self.ring_thickness > 0, f"ring_thickness must be > 0, got {self.ring_thickness}")
        need(self.max_attempts >= 1, f"max_attempts must be >= 1, got {self.max_attempts}")

    @property
    def inflation(self) -> float:
        """m: what every box is grown by for the path search."""
        return self.footprint_radius + self.clearance


SPARSE = WorldParams(name="sparse", obstacle_count=(8, 12))
"""About 3 % of the arena covered (mean 3 m^2): a few boxes to go around; every world
drawn has a path (40 of 40 seeds before redrawing)."""
DENSE = WorldParams(name="dense", obstacle_count=(40, 50))
"""About 13 % covered (mean 13 m^2, the boxes kept 0.9 m from start and goal): gaps
near the footprint, detours up to 2.5 x the straight line (median 1.12), dead ends;
59 of 100 first draws have no path for the inflated footprint and are redrawn (2.3
draws per world on average, at most 9 in seeds 0-99)."""
WALLED_IN = WorldParams(name="walled_in", obstacle_count=(8, 12), walled_in=True)
"""Sparse clutter and the goal inside a closed ring: the navigator must give up."""
PRESETS: dict[str, WorldParams] = {"sparse": SPARSE, "dense": DENSE, "walled_in": WALLED_IN}


@dataclass(frozen=True, slots=True)
class GeneratedWorld:
    """One generated world and its labels.

    Attributes:
        scenario: what to run (scene ``empty``, obstacles, start, goal, budget,
            ``expect``).
        seed: the seed it was drawn from.
        params: how it was drawn.
        reachable: a path exists for the footprint with the clearance kept.
        shortest_path_m: that path's length (m); for a walled-in world, the length
            the path would have without the ring (what its budget is based on); None
            when no path exists at all.
        path: that path's way-points (m).
        attempts: draws it took (> 1 when unreachable draws were redrawn).
    """

    scenario: ScenarioConfig
    seed: int
    params: WorldParams
    reachable: bool
    shortest_path_m: float | None
    path: tuple[tuple[float, float], ...] = field(default=(), repr=False)
    attempts: int = 1

    @property
    def optimal_time_s(self) -> float | None:
        """Shortest path / max speed, s (BARN's optimal time); None without a path."""
        if self.shortest_path_m is None:
            return None
        return self.shortest_path_m / self.params.max_speed


def budget_for(path_m: float, params: WorldParams) -> float:
    """The sim-time budget (s) of a world whose shortest path is ``path_m``:
    ``budget_factor * path_m / max_speed + budget_slack``, rounded up to 1 s.

    Why this shape: the optimal time (path at top speed) scales with the path, and a
    careful planner is slower than that in proportion (it slows near obstacles and
    turns in place); the defaults allow an average speed of a third of the top speed.
    The slack is for what does not scale with the path: the first turn towards the
    goal, accelerating and stopping, and one round of recovery (a 2 pi spin at 1.2
    rad/s is 5 s; backing up and following a box's edge take 10-20 s). For a 7 m path
    at 0.4 m/s that is 3 * 17.5 + 30 = 83 s, comparable with BARN's 100 s for 10 m.
    Beyond 8 x optimal the BARN metric no longer distinguishes anyway."""
    return float(math.ceil(params.budget_factor * path_m / params.max_speed + params.budget_slack))


def plan_path(
    boxes: tuple[BoxObstacle, ...],
    start: tuple[float, float],
    goal: tuple[float, float],
    inflation: float,
    *,
    resolution: float = CELL,
    half: float = EMPTY_ARENA_HALF,
) -> GridPath | None:
    """The shortest path (m) for a disc of radius ``inflation`` from start to goal in
    the arena ``[-half, half]^2`` among ``boxes``, or None."""
    grid = occupancy(boxes, half, inflation, resolution)
    return shortest_path(grid, start, goal)


def _r(x: float) -> float:
    """Values stored in a config: millimetres, so files read back identical."""
    return round(float(x), 3)


def _start_goal(
    rng: np.random.Generator, p: WorldParams
) -> tuple[tuple[float, float, float], tuple[float, float]]:
    lo_d, hi_d = p.start_goal_distance
    limit = p.arena / 2 - p.keepout
    while True:
        d = rng.uniform(lo_d, hi_d)
        theta = rng.uniform(-math.pi, math.pi)
        ux, uy = d * math.cos(theta), d * math.sin(theta)
        # start in the box, and start + (ux, uy) in the box too
        x_lo, x_hi = max(-limit, -limit - ux), min(limit, limit - ux)
        y_lo, y_hi = max(-limit, -limit - uy), min(limit, limit - uy)
        if x_lo < x_hi and y_lo < y_hi:
            break
    sx, sy = _r(rng.uniform(x_lo, x_hi)), _r(rng.uniform(y_lo, y_hi))
    gx, gy = _r(sx + ux), _r(sy + uy)
    yaw = _r(theta + rng.uniform(-p.start_yaw_noise, p.start_yaw_noise))
    return (sx, sy, yaw), (gx, gy)


def _obstacles(
    rng: np.random.Generator,
    p: WorldParams,
    keep_clear: tuple[tuple[float, float], ...],
) -> list[BoxSpec]:
    count = int(rng.integers(p.obstacle_count[0], p.obstacle_count[1] + 1))
    boxes: list[BoxSpec] = []
    half = p.arena / 2
    for _ in range(count):
        for _try in range(100):
            sx = _r(rng.uniform(*p.obstacle_size))
            sy = _r(rng.uniform(*p.obstacle_size))
            yaw = _r(rng.uniform(0.0, math.pi))
            x = _r(rng.uniform(-half, half))
            y = _r(rng.uniform(-half, half))
            box = BoxSpec(x=x, y=y, size_x=sx, size_y=sy, yaw=yaw)
            obstacle = box.to_obstacle()
            if all(obstacle.distance_to(*q) >= p.keepout for q in keep_clear):
                boxes.append(box)
                break
    return boxes


def _ring(rng: np.random.Generator, p: WorldParams, goal: tuple[float, float]) -> list[BoxSpec]:
    """Four walls closing a square around the goal (corners overlap: no gap)."""
    inner = rng.uniform(*p.ring_inner)
    yaw = rng.uniform(0.0, math.pi / 2)
    t = p.ring_thickness
    c, s = math.cos(yaw), math.sin(yaw)
    mid = inner + t / 2
    long = 2 * (inner + t)
    out = []
    sides = ((mid, 0.0, False), (-mid, 0.0, False), (0.0, mid, True), (0.0, -mid, True))
    for lx, ly, along_x in sides:
        out.append(
            BoxSpec(
                x=_r(goal[0] + c * lx - s * ly),
                y=_r(goal[1] + s * lx + c * ly),
                size_x=_r(long if along_x else t),
                size_y=_r(t if along_x else long),
                yaw=_r(yaw),
            )
        )
    return out


def _arena_walls(p: WorldParams) -> list[BoxSpec]:
    """Walls of a smaller arena inside the scene's (none for the full 10 m)."""
    if p.arena >= 2 * EMPTY_ARENA_HALF:
        return []
    h, t = p.arena / 2, 0.1
    long = _r(p.arena + 2 * t)
    return [
        BoxSpec(x=_r(h + t / 2), y=0.0, size_x=t, size_y=long),
        BoxSpec(x=_r(-h - t / 2), y=0.0, size_x=t, size_y=long),
        BoxSpec(x=0.0, y=_r(h + t / 2), size_x=long, size_y=t),
        BoxSpec(x=0.0, y=_r(-h - t / 2), size_x=long, size_y=t),
    ]


def generate_world(seed: int, params: WorldParams = SPARSE) -> GeneratedWorld:
    """One world drawn from ``seed`` (>= 0): the same seed and params always give the
    same world. See the module docstring."""
    if seed < 0:
        raise ValueError(f"generate_world: seed must be >= 0, got {seed}")
    p = params
    rng = np.random.default_rng(seed)
    walls = _arena_walls(p)
    attempts = 0
    while True:
        attempts += 1
        start, goal = _start_goal(rng, p)
        clutter = _obstacles(rng, p, ((start[0], start[1]), goal))
        ring = _ring(rng, p, goal) if p.walled_in else []
        open_boxes = tuple(b.to_obstacle() for b in (*walls, *clutter))
        open_path = plan_path(
            open_boxes, start[:2], goal, p.inflation, resolution=p.resolution, half=p.arena / 2
        )
        if p.walled_in:
            if open_path is not None or attempts >= p.max_attempts:
                break  # the ring closes the goal whatever the rest; budget from the open path
            continue
        if open_path is not None or not p.resample_unreachable or attempts >= p.max_attempts:
            break
    reachable = open_path is not None and not p.walled_in
    boxes = (*walls, *clutter, *ring)
    return make_world(p, seed, boxes, start, goal, open_path, reachable, attempts)


def make_world(
    params: WorldParams,
    seed: int,
    obstacles: tuple[BoxSpec, ...],
    start: tuple[float, float, float],
    goal: tuple[float, float],
    path: GridPath | None,
    reachable: bool,
    attempts: int,
) -> GeneratedWorld:
    """The world's scenario and labels; its budget from ``path`` (no path at all:
    twice the straight line)."""
    length = path.length_m if path is not None else None
    scenario = ScenarioConfig(
        name=f"{params.name}-{seed}",
        scene="empty",
        obstacles=obstacles,
        start=StartSpec(x=start[0], y=start[1], yaw=start[2]),
        goal=GoalSpec(x=goal[0], y=goal[1]),
        goal_tolerance=params.goal_tolerance,
        sim_budget=budget_for(math.dist(start[:2], goal) * 2 if length is None else length, params),
        min_clearance=params.clearance,
        seed=seed,
        expect="reached" if reachable else "unreachable",
    )
    return GeneratedWorld(
        scenario=scenario,
        seed=seed,
        params=params,
        reachable=reachable,
        shortest_path_m=length,
        path=path.points if path is not None else (),
        attempts=attempts,
    )


def generate_worlds(
    count: int, params: WorldParams = SPARSE, seed0: int = 0
) -> Iterator[GeneratedWorld]:
    """``count`` worlds from seeds ``seed0 .. seed0 + count - 1``, lazily (each world
    depends on its own seed only, so any slice can be rebuilt on its own)."""
    for seed in range(seed0, seed0 + count):
        yield generate_world(seed, params)


def walled_in(params: WorldParams) -> WorldParams:
    """``params`` with a ring around the goal (same clutter density)."""
    return replace(params, name=f"{params.name}-walled", walled_in=True)
