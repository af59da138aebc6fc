"""The launch file as data: pydantic models are the schema, defaults live here (an
installed wheel runs with no checkout); YAML files in ``config/`` override them."""

from __future__ import annotations

import math

from pydantic import BaseModel, ConfigDict, Field, PositiveFloat, PositiveInt, model_validator


class _Section(BaseModel):
    # strict: "yes" is not 1.0 and "3" is not 3 (a number in YAML is still a number).
    # allow_inf_nan=False: '.inf' is a YAML float, and an infinite rate is a zero period.
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class WorldConfig(_Section):
    """The simulated world (``otonav.hal.mujoco``)."""

    scene: str = "obstacles"
    """Built-in scene name (``empty``, ``obstacles``) or a path to an MJCF file."""
    timestep: PositiveFloat = 0.002
    """Physics step, s: one tick of sim time."""
    lidar_beams: PositiveInt = 360
    lidar_range_min: float = Field(0.12, ge=0.0)
    lidar_range_max: PositiveFloat = 8.0


class RatesConfig(_Section):
    """Bridge publishing rates, Hz."""

    clock_hz: PositiveFloat = 100.0
    odom_hz: PositiveFloat = 100.0
    imu_hz: PositiveFloat = 100.0
    scan_hz: PositiveFloat = 10.0


class BaseConfig(_Section):
    """Base controller: rate, watchdog, velocity and acceleration limits."""

    rate_hz: PositiveFloat = 50.0
    cmd_timeout: PositiveFloat = 0.5
    max_v: PositiveFloat = 0.5
    max_omega: PositiveFloat = 1.5
    max_accel: PositiveFloat = 1.0
    max_alpha: PositiveFloat = 3.0


class NavConfig(_Section):
    """Navigator: go-to-goal gains and limits."""

    rate_hz: PositiveFloat = 20.0
    kp_lin: float = Field(0.8, ge=0.0)
    kp_ang: float = Field(2.0, ge=0.0)
    max_v: PositiveFloat = 0.4
    max_omega: PositiveFloat = 1.2
    tolerance: PositiveFloat = 0.08
    """m: the navigator stops within this distance of the goal (by odometry)."""
    turn_in_place_threshold: PositiveFloat = 0.6


class GuardConfig(_Section):
    """Obstacle guard: front sector half-angle (rad) and stop distance (m)."""

    sector_half_angle: float = Field(0.5, gt=0.0, le=math.pi)
    stop_distance: PositiveFloat = 0.35


class StackConfig(_Section):
    """Everything needed to bring the robot stack up."""

    world: WorldConfig = WorldConfig()
    rates: RatesConfig = RatesConfig()
    base: BaseConfig = BaseConfig()
    nav: NavConfig = NavConfig()
    guard: GuardConfig = GuardConfig()

    @model_validator(mode="after")
    def _consistent(self) -> StackConfig:
        if self.world.lidar_range_min >= self.world.lidar_range_max:
            raise ValueError(
                "world.lidar_range_min must be < world.lidar_range_max "
                f"(got {self.world.lidar_range_min} >= {self.world.lidar_range_max})"
            )
        return self
