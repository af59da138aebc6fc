"""Built-in scenarios (defaults in code, so an installed wheel has them; each one's file
in ``config/scenarios/`` documents it and a static test keeps the two equal).

The avoidance courses all use the ``empty`` scene (a 10 x 10 m arena, inner wall
faces at x, y = +-5 m) plus boxes, the robot starting at (-3, 0) or so facing +x. The
footprint is a 0.243 m disc about the robot's centre and the judge wants the centre
0.3 m from every surface, so a passage the robot can take with its footprint and the
clearance kept on both sides is wider than 2 x (0.243 + 0.3) = 1.086 m. A static test
checks each course with the world generator's grid search: start and goal clear of
every box and wall by the clearance, a path for the inflated footprint where the goal
is expected to be reached, none where it is not, and a budget no shorter than the
generator would give that path.
"""

from __future__ import annotations

from otonav.scenario._config import BoxSpec, GoalSpec, ScenarioConfig, StartSpec

_WALL = 0.2
"""m: thickness of the walls the courses build from boxes."""


def _wall_x(x: float, y0: float, y1: float) -> BoxSpec:
    """A wall along y at ``x``, from ``y0`` to ``y1``."""
    return BoxSpec(x=x, y=round((y0 + y1) / 2, 4), size_x=_WALL, size_y=round(y1 - y0, 4))


def _wall_y(y: float, x0: float, x1: float) -> BoxSpec:
    """A wall along x at ``y``, from ``x0`` to ``x1``."""
    return BoxSpec(x=round((x0 + x1) / 2, 4), y=y, size_x=round(x1 - x0, 4), size_y=_WALL)


_START = StartSpec(x=-3.0, y=0.0, yaw=0.0)

BOX = ScenarioConfig(
    name="box",
    scene="empty",
    obstacles=(BoxSpec(x=0.0, y=0.0, size_x=0.8, size_y=0.8),),
    start=_START,
    goal=GoalSpec(x=3.0, y=0.0),
    sim_budget=80.0,
)
"""A 0.8 m box on the straight line halfway from start to goal: the stop-only
navigator waits in front of it until the budget runs out."""

SLALOM = ScenarioConfig(
    name="slalom",
    scene="empty",
    obstacles=(
        _wall_x(-2.0, -0.4, 1.6),
        _wall_x(0.0, -1.6, 0.4),
        _wall_x(2.0, -0.4, 1.6),
    ),
    start=StartSpec(x=-4.0, y=0.0, yaw=0.0),
    goal=GoalSpec(x=4.0, y=0.0),
    sim_budget=100.0,
)
"""Three 2 m barriers across the straight line, each sticking out 0.4 m past it on
alternate sides: the way weaves below, above, below."""

GAP = ScenarioConfig(
    name="gap",
    scene="empty",
    obstacles=(
        _wall_x(0.0, -5.0, 0.225),
        _wall_x(0.0, 1.375, 5.0),
    ),
    start=_START,
    goal=GoalSpec(x=3.0, y=0.0),
    sim_budget=80.0,
)
"""A wall right across the arena at x = 0 with one gap 1.15 m wide (y from 0.225 to
1.375): wider than footprint + 2 x clearance (1.086 m), under 1.2 m, and off the
straight line (which meets the wall 0.225 m below the gap)."""

U_TRAP = ScenarioConfig(
    name="u_trap",
    scene="empty",
    obstacles=(
        _wall_x(1.0, -1.5, 1.5),
        _wall_y(1.4, -1.0, 0.9),
        _wall_y(-1.4, -1.0, 0.9),
    ),
    start=_START,
    goal=GoalSpec(x=3.0, y=0.0),
    sim_budget=100.0,
)
"""A U 2.6 m wide and 1.9 m deep inside, opening towards the robot, the goal 2 m behind its
bottom: heading for the goal leads into the U, the way is around an arm."""

CORRIDOR = ScenarioConfig(
    name="corridor",
    scene="empty",
    obstacles=(
        _wall_y(0.7, -2.0, 2.0),
        _wall_y(-0.7, -2.0, 2.0),
        _wall_x(-2.1, 0.6, 5.0),
        _wall_x(-2.1, -5.0, -0.6),
    ),
    start=StartSpec(x=-4.0, y=-1.0, yaw=0.0),
    goal=GoalSpec(x=4.0, y=1.0),
    sim_budget=100.0,
)
"""The only way through a wall across the arena is a corridor 4 m long and 1.2 m wide
(the centre line 0.6 m from each side), entered from an offset start."""

CLUTTERED = ScenarioConfig(
    name="cluttered",
    scene="empty",
    obstacles=(
        BoxSpec(x=-2.5, y=0.85, size_x=0.5, size_y=0.5, yaw=0.3),
        BoxSpec(x=-2.1, y=-1.4, size_x=0.6, size_y=0.4),
        BoxSpec(x=-0.8, y=-0.15, size_x=0.5, size_y=0.7, yaw=0.6),
        BoxSpec(x=-0.25, y=2.25, size_x=0.7, size_y=0.4),
        BoxSpec(x=0.4, y=-2.1, size_x=0.5, size_y=0.5, yaw=0.8),
        BoxSpec(x=1.05, y=1.0, size_x=0.4, size_y=0.6),
        BoxSpec(x=1.7, y=-0.7, size_x=0.6, size_y=0.4, yaw=1.1),
        BoxSpec(x=2.6, y=1.7, size_x=0.5, size_y=0.5),
        BoxSpec(x=2.85, y=-2.25, size_x=0.4, size_y=0.7, yaw=0.4),
        BoxSpec(x=-1.3, y=3.6, size_x=0.6, size_y=0.5),
        BoxSpec(x=1.3, y=-3.9, size_x=0.6, size_y=0.5, yaw=0.2),
        BoxSpec(x=3.1, y=0.15, size_x=0.3, size_y=0.5),
    ),
    start=StartSpec(x=-4.0, y=0.0, yaw=0.0),
    goal=GoalSpec(x=4.2, y=0.3),
    sim_budget=105.0,
)
"""Twelve boxes, 0.3 to 0.7 m, strewn between start and goal, 1.1 to 1.6 m apart."""

WALLED_IN = ScenarioConfig(
    name="walled_in",
    scene="empty",
    obstacles=(
        _wall_x(2.1, -1.0, 1.0),
        _wall_x(3.9, -1.0, 1.0),
        _wall_y(0.9, 2.0, 4.0),
        _wall_y(-0.9, 2.0, 4.0),
    ),
    start=_START,
    goal=GoalSpec(x=3.0, y=0.0),
    sim_budget=80.0,
    expect="unreachable",
)
"""The goal inside a closed square of walls (inside 1.6 x 1.6 m): passing means the
navigator reports ``unreachable`` within the budget, without breaking the clearance;
timing out is a failure."""

AVOIDANCE: tuple[ScenarioConfig, ...] = (BOX, SLALOM, GAP, U_TRAP, CORRIDOR, CLUTTERED, WALLED_IN)
"""The courses that need avoidance (issue 10), each run by the SIL layer."""

BUILTIN: dict[str, ScenarioConfig] = {
    "acceptance": ScenarioConfig(),
    "empty": ScenarioConfig(name="empty", scene="empty", goal=GoalSpec(x=3.0, y=-1.0)),
    **{s.name: s for s in AVOIDANCE},
}
"""name -> scenario. ``acceptance`` is the gate's scenario (obstacle scene, goal (4, 1.5))."""


def describe(name: str) -> str:
    s = BUILTIN[name]
    extra = f", {len(s.obstacles)} boxes" if s.obstacles else ""
    expect = ", expect unreachable" if s.expect == "unreachable" else ""
    return (
        f"scene {s.scene or 'of the stack (obstacles)'}{extra}, "
        f"goal ({s.goal.x:g}, {s.goal.y:g}) within {s.goal_tolerance:g} m, "
        f"{s.sim_budget:g} s budget, clearance {s.min_clearance:g} m{expect}"
    )
