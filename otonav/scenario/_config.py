"""A scenario: the world it runs in, the goal, and what counts as passing."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, PositiveFloat

from otonav import limits

if TYPE_CHECKING:  # imported in to_obstacle: reading a scenario file needs no numpy
    from otonav.hal._types import BoxObstacle


# Bounds: what the stack can honour, and why (otonav/limits.py).
Coordinate = Annotated[float, Field(ge=-limits.MAX_COORDINATE_M, le=limits.MAX_COORDINATE_M)]
"""m, a position in the world plane."""
Size = Annotated[float, Field(gt=0.0, le=limits.MAX_COORDINATE_M)]
"""m, a full box size."""
Yaw = Annotated[float, Field(ge=-limits.MAX_YAW_RAD, le=limits.MAX_YAW_RAD)]
"""rad, CCW from +x."""
Distance = Annotated[float, Field(gt=0.0, le=limits.MAX_DISTANCE_M)]
"""m, a tolerance or clearance."""


class BoxSpec(BaseModel):
    """An extra box obstacle: centre (m), full size (m), yaw (rad)."""

    # strict: "yes" is not 1.0 (files are validated in JSON mode, where lists are tuples)
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)
    x: Coordinate
    y: Coordinate
    size_x: Size
    size_y: Size
    yaw: Yaw = 0.0

    def to_obstacle(self) -> BoxObstacle:
        from otonav.hal._types import BoxObstacle

        return BoxObstacle(self.x, self.y, self.size_x / 2, self.size_y / 2, self.yaw)


class GoalSpec(BaseModel):
    """The goal of a scenario: where the robot must get to, in the world frame (m)."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)
    x: Coordinate
    y: Coordinate


class StartSpec(BaseModel):
    """The robot's start pose in the world: position (m), heading (rad, CCW from +x)."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)
    x: Coordinate = 0.0
    y: Coordinate = 0.0
    yaw: Yaw = 0.0

    def as_tuple(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.yaw)


class ScenarioConfig(BaseModel):
    """What to run and how to judge it. Defaults: the acceptance scenario."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)
    name: Annotated[
        str,
        Field(min_length=1, max_length=limits.MAX_NAME_CHARS),
        AfterValidator(limits.one_printable_line),
    ] = "acceptance"
    """One line of printable text, at most 128 characters: a title and a label."""
    scene: str | None = Field(None, min_length=1, max_length=limits.MAX_PATH_CHARS)
    """Built-in scene name or MJCF path; None: the stack's ``world.scene`` (obstacles)."""
    obstacles: tuple[BoxSpec, ...] = Field((), max_length=limits.MAX_OBSTACLES)
    start: StartSpec = StartSpec()
    """Where the robot starts; odometry starts there too (odom = world frame)."""
    goal: GoalSpec = GoalSpec(x=4.0, y=1.5)
    goal_tolerance: Distance = 0.15
    """m: reached when the true position is this close to the goal (see ``arrival``)."""
    arrival: Literal["stop", "enter"] = "stop"
    """What counts as arriving: ``stop`` (within the tolerance, stopped, and the navigator
    says ``reached``, 2 s after the first entry) or ``enter`` (the first entry into the
    tolerance, as BARN counts success; issue 42)."""
    sim_budget: PositiveFloat = Field(20.0, le=limits.MAX_SIM_BUDGET_S)
    """s of sim time to reach the goal, at most half an hour (and see
    :func:`~otonav.scenario._validate.check_cost`)."""
    min_clearance: Distance = 0.3
    """m: the robot centre must never come closer than this to an obstacle or wall."""
    seed: int = Field(0, ge=0, le=limits.MAX_SEED)
    expect: Literal["reached", "unreachable"] = "reached"
    """The outcome that passes: ``reached`` (the goal within tolerance inside the budget)
    or ``unreachable`` (the navigator reports ``unreachable`` on /nav/state inside the
    budget, e.g. a walled-in goal). Either way the clearance must hold."""
