"""A scenario: the world it runs in, the goal, and what counts as passing."""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

from pydantic import BaseModel, ConfigDict, Field, PositiveFloat

if TYPE_CHECKING:  # imported in to_obstacle: reading a scenario file needs no numpy
    from otonav.hal.types import BoxObstacle


class BoxSpec(BaseModel):
    """An extra box obstacle: centre (m), full size (m), yaw (rad)."""

    # strict: "yes" is not 1.0 (files are validated in JSON mode, where lists are tuples)
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)
    x: float
    y: float
    size_x: PositiveFloat
    size_y: PositiveFloat
    yaw: float = 0.0

    def to_obstacle(self) -> BoxObstacle:
        from otonav.hal.types import BoxObstacle

        return BoxObstacle(self.x, self.y, self.size_x / 2, self.size_y / 2, self.yaw)


class GoalSpec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)
    x: float
    y: float


class StartSpec(BaseModel):
    """The robot's start pose in the world: position (m), heading (rad, CCW from +x)."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0

    def as_tuple(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.yaw)


class ScenarioConfig(BaseModel):
    """What to run and how to judge it. Defaults: the acceptance scenario."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)
    name: str = "acceptance"
    scene: str | None = None
    """Built-in scene name or MJCF path; None: the stack's ``world.scene`` (obstacles)."""
    obstacles: tuple[BoxSpec, ...] = ()
    start: StartSpec = StartSpec()
    """Where the robot starts; odometry starts there too (odom = world frame)."""
    goal: GoalSpec = GoalSpec(x=4.0, y=1.5)
    goal_tolerance: PositiveFloat = 0.15
    """m: reached when the true position is this close to the goal."""
    sim_budget: PositiveFloat = 20.0
    """s of sim time to reach the goal."""
    min_clearance: PositiveFloat = 0.3
    """m: the robot centre must never come closer than this to an obstacle or wall."""
    seed: int = Field(0, ge=0)
    expect: Literal["reached", "unreachable"] = "reached"
    """The outcome that passes: ``reached`` (the goal within tolerance inside the budget)
    or ``unreachable`` (the navigator reports ``unreachable`` on /nav/state inside the
    budget, e.g. a walled-in goal). Either way the clearance must hold."""
