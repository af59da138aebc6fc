"""The launch file as data: pydantic models are the schema, defaults live here (an
installed wheel runs with no checkout); YAML files in ``config/`` override them."""

from __future__ import annotations

import math

from pydantic import BaseModel, ConfigDict, Field, PositiveFloat, PositiveInt, model_validator

from otonav.stack import limits


class _Section(BaseModel):
    # strict: "yes" is not 1.0 and "3" is not 3 (a number in YAML is still a number).
    # allow_inf_nan=False: '.inf' is a YAML float, and an infinite rate is a zero period.
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class WorldConfig(_Section):
    """The simulated world (``otonav.hal.mujoco``)."""

    scene: str = Field("obstacles", min_length=1, max_length=limits.MAX_PATH_CHARS)
    """Built-in scene name (``empty``, ``obstacles``) or a path to an MJCF file."""
    timestep: float = Field(0.002, ge=limits.MIN_TIMESTEP_S, le=limits.MAX_TIMESTEP_S)
    """Physics step, s: one tick of sim time. Bounded by the cost of a step below and by
    the fastest timer (the judge's 100 Hz) above: see ``otonav.stack.limits``."""
    lidar_beams: PositiveInt = Field(360, le=limits.MAX_LIDAR_BEAMS)
    """Beams over a full circle, at most 3600 (0.1 degree, the finest 2D lidars)."""
    lidar_range_min: float = Field(0.12, ge=0.0)
    lidar_range_max: PositiveFloat = Field(8.0, le=limits.MAX_LIDAR_RANGE_M)
    """m, at most 1 km: ranges are float32 in the recording."""


class RatesConfig(_Section):
    """Bridge publishing rates, Hz. Each at most the physics tick rate (1 / timestep):
    a timer cannot fire more often than the world ticks."""

    clock_hz: PositiveFloat = 100.0
    odom_hz: PositiveFloat = 100.0
    imu_hz: PositiveFloat = 100.0
    scan_hz: PositiveFloat = 10.0


class BaseConfig(_Section):
    """Base controller: rate, watchdog, velocity and acceleration limits."""

    rate_hz: PositiveFloat = 50.0
    cmd_timeout: PositiveFloat = 0.5
    # Bounded so that wheel speeds stay finite and the limits still limit (limits.py).
    max_v: PositiveFloat = Field(0.5, le=limits.MAX_BASE_V)
    max_omega: PositiveFloat = Field(1.5, le=limits.MAX_BASE_OMEGA)
    max_accel: PositiveFloat = Field(1.0, le=limits.MAX_BASE_ACCEL)
    max_alpha: PositiveFloat = Field(3.0, le=limits.MAX_BASE_ALPHA)


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
        tick_hz = 1.0 / self.world.timestep
        for key, hz in self.rates_hz().items():
            if hz > tick_hz * (1 + 1e-9):
                raise ValueError(
                    f"{key} = {hz:g} Hz is faster than the physics ticks: at most "
                    f"{tick_hz:g} Hz with world.timestep = {self.world.timestep:g} s "
                    "(lower the rate, or the timestep)"
                )
        return self

    def rates_hz(self) -> dict[str, float]:
        """Every periodic actor rate of the stack, by key path (Hz)."""
        rates = {f"rates.{key}": float(hz) for key, hz in self.rates.model_dump().items()}
        rates["base.rate_hz"] = self.base.rate_hz
        rates["nav.rate_hz"] = self.nav.rate_hz
        return rates
