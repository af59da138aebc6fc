"""The launch file as data: pydantic models are the schema, defaults live here (an
installed wheel runs with no checkout); YAML files in ``config/`` override them."""

from __future__ import annotations

import math
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, PositiveFloat, PositiveInt, model_validator

from otonav import limits


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
    the fastest timer (the judge's 100 Hz) above: see ``otonav.limits``."""
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


class CanAxisConfig(_Section):
    """One wheel's drive as the host sees it: CAN node id, direction sign, gearing."""

    node_id: int = Field(0, ge=0, le=63)
    sign: Literal[1, -1] = 1
    """+1 if positive motor turns drive the wheel forward, -1 if the motor is mirrored."""
    gear_ratio: PositiveFloat = 1.0
    """Motor turns per wheel revolution (wheel rad = sign * 2 pi * turns / gear_ratio)."""


class CanConfig(_Section):
    """The wheel bus (``hal.kind: can``): python-can interface and channel, the two
    ODrive axes, and the fault-detection limits (s of sim time)."""

    interface: str = "virtual"
    """python-can interface: ``virtual`` (in-process, with the drive emulator) or
    ``socketcan`` (a Linux CAN link such as ``can0`` or ``vcan0``)."""
    channel: str = "can0"
    emulate: bool = True
    """Run the drive emulator at the far end of the bus (false: real drives)."""
    left: CanAxisConfig = CanAxisConfig(node_id=0, sign=-1)
    right: CanAxisConfig = CanAxisConfig(node_id=1, sign=1)
    encoder_period: PositiveFloat = 0.01
    """The drives' Get_Encoder_Estimates period (ODrive ``encoder_msg_rate_ms``)."""
    startup_timeout: PositiveFloat = 1.0
    heartbeat_timeout: PositiveFloat = 0.25
    encoder_timeout: PositiveFloat = 0.05
    max_frame_loss: float = Field(0.2, ge=0.0, le=1.0)
    """Fraction of encoder frames that may be lost over ``loss_window`` s."""
    loss_window: PositiveFloat = 0.5
    recovery_delay: float = Field(0.3, ge=0.0)
    """s a fault's cause must stay clear before recovery starts."""
    max_recovery_attempts: int = Field(3, ge=0)
    record_frames: bool = True
    """Publish every frame on /can/frames (and so into the recording)."""

    @model_validator(mode="after")
    def _distinct(self) -> CanConfig:
        if self.left.node_id == self.right.node_id:
            raise ValueError(
                f"hal.can.left.node_id and hal.can.right.node_id must differ "
                f"(both {self.left.node_id})"
            )
        return self


class DriveSimConfig(_Section):
    """The emulated drives (``otonav.hal.sim``): how they are configured, which can
    differ from what the host expects (a wrong node id is a fault to detect)."""

    left_node_id: int = Field(0, ge=0, le=63)
    right_node_id: int = Field(1, ge=0, le=63)
    heartbeat_period: PositiveFloat = 0.1
    encoder_period: PositiveFloat = 0.01
    vel_limit: PositiveFloat = 20.0
    """turns/s."""
    vel_ramp_rate: PositiveFloat = 200.0
    """turns/s^2."""
    watchdog_timeout: float = Field(0.2, ge=0.0)
    """s without Set_Input_Vel before the axis stops (0: off)."""
    arm_time: float = Field(0.01, ge=0.0)
    seed: int = Field(0, ge=0)
    """Seeds the injected faults' random numbers."""

    @model_validator(mode="after")
    def _distinct(self) -> DriveSimConfig:
        if self.left_node_id == self.right_node_id:
            raise ValueError("hal.sim.left_node_id and hal.sim.right_node_id must differ")
        return self


class HalConfig(_Section):
    """Which hardware is under the HAL: the MuJoCo world directly, or the wheels over a
    CAN bus (drives emulated on MuJoCo's wheels, or real drives)."""

    kind: Literal["mujoco", "can"] = "mujoco"
    can: CanConfig = CanConfig()
    sim: DriveSimConfig = DriveSimConfig()


class StackConfig(_Section):
    """Everything needed to bring the robot stack up."""

    world: WorldConfig = WorldConfig()
    rates: RatesConfig = RatesConfig()
    base: BaseConfig = BaseConfig()
    nav: NavConfig = NavConfig()
    guard: GuardConfig = GuardConfig()
    hal: HalConfig = HalConfig()

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
