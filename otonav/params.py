"""The parameter models, each default written once (ADR 0085): the dataclasses the nav
math takes (``DwaParams``, ...) and the config sections that set them (``NavConfig``,
...: bounds, units, YAML names). A leaf (pydantic and the standard library): reading a
config loads no numpy. Everything else refers to a default's one home; the static test
``test_defaults_once`` fails on a literal written twice.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, PositiveFloat

from otonav import limits

__all__ = (
    "CONFIG_KEYS",
    "LIDAR_BEAMS",
    "LIDAR_RANGE",
    "AxisParams",
    "BaseConfig",
    "DwaConfig",
    "DwaParams",
    "GoToGoalParams",
    "GuardConfig",
    "GuardParams",
    "LocalizationConfig",
    "LocalizerParams",
    "MapConfig",
    "MatchParams",
    "MonitorLimits",
    "NavConfig",
    "NavigationParams",
    "RatesConfig",
    "RecoveryConfig",
    "SafetyConfig",
    "SafetyParams",
    "Section",
)


LIDAR_BEAMS = 360
"""The default lidar's beams over its field of view (``world.lidar_beams``, the hal's
``LidarSpec``)."""
LIDAR_RANGE = (0.12, 8.0)
"""The default lidar's range, m: (``world.lidar_range_min``, ``world.lidar_range_max``)."""


class Section(BaseModel):
    """A section of the stack config: frozen, no unknown keys, strict, finite."""

    # strict: "yes" is not 1.0 and "3" is not 3 (a number in YAML is still a number).
    # allow_inf_nan=False: '.inf' is a YAML float, and an infinite rate is a zero period.
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class BaseConfig(Section):
    """Base controller: rate, watchdog, velocity and acceleration limits."""

    rate_hz: PositiveFloat = 50.0
    cmd_timeout: PositiveFloat = 0.5
    """s of sim time without a valid /cmd_vel before the wheels stop (watchdog)."""
    # Bounded so that wheel speeds stay finite and the limits still limit (limits.py).
    max_v: PositiveFloat = Field(0.5, le=limits.MAX_BASE_V)
    """m/s, the fastest the base drives, whatever /cmd_vel asks (``robot.max_v``, when
    stated, sets it)."""
    max_omega: PositiveFloat = Field(1.5, le=limits.MAX_BASE_OMEGA)
    """rad/s, the fastest the base turns."""
    max_accel: PositiveFloat = Field(1.0, le=limits.MAX_BASE_ACCEL)
    """m/s², linear acceleration limit."""
    max_alpha: PositiveFloat = Field(3.0, le=limits.MAX_BASE_ALPHA)
    """rad/s², angular acceleration limit."""


class RatesConfig(Section):
    """Bridge publishing rates, Hz. Each at most the physics tick rate (1 / timestep):
    a timer cannot fire more often than the world ticks."""

    clock_hz: PositiveFloat = 100.0
    odom_hz: PositiveFloat = 100.0
    imu_hz: PositiveFloat = 100.0
    scan_hz: PositiveFloat = 10.0


@dataclass(frozen=True, slots=True)
class MonitorLimits:
    """The CAN drive monitor's limits (``hal.can``): seconds of sim time, and the
    tolerated encoder frame loss (0..1)."""

    startup_timeout: float = 1.0
    heartbeat_timeout: float = 0.25
    encoder_timeout: float = 0.05
    encoder_period: float = 0.01
    max_frame_loss: float = 0.2
    loss_window: float = 0.5
    recovery_delay: float = 0.3
    max_recovery_attempts: int = 3
    recovery_reset: float = 5.0
    """s of running without a fault after which each drive's attempts count from 0."""


@dataclass(frozen=True, slots=True)
class AxisParams:
    """An emulated ODrive's configuration (``hal.sim``: what ``odrivetool`` would have
    saved on the drive)."""

    node_id: int
    vel_limit: float = 20.0
    """turns/s."""
    vel_ramp_rate: float = 200.0
    """turns/s²: how fast the setpoint may change."""
    watchdog_timeout: float = 0.2
    """s; 0 disables the watchdog."""
    arm_time: float = 0.01
    """s from the closed-loop request to closed loop."""
    overspeed_factor: float = 1.5

    def __post_init__(self) -> None:
        for name in ("vel_limit", "vel_ramp_rate"):
            if not getattr(self, name) > 0:
                raise ValueError(f"AxisParams.{name} must be > 0, got {getattr(self, name)}")
        if self.watchdog_timeout < 0 or self.arm_time < 0:
            raise ValueError("AxisParams.watchdog_timeout and arm_time must be >= 0")


_BASE = BaseConfig()


def _finite(params: object, low: str, *names: str) -> None:
    """Each field ``names`` of ``params`` is finite and ``low`` ("> 0" or ">= 0")."""
    for name in names:
        value = getattr(params, name)
        if not (math.isfinite(value) and (value > 0.0 if low == "> 0" else value >= 0.0)):
            kind = type(params).__name__
            raise ValueError(f"{kind}.{name} must be finite and {low}, got {value!r}")


def _integer(params: object, low: int, *names: str) -> None:
    """Each field ``names`` of ``params`` is an integer >= ``low``."""
    for name in names:
        value = getattr(params, name)
        if not (isinstance(value, int) and value >= low):
            kind = type(params).__name__
            raise ValueError(f"{kind}.{name} must be an integer >= {low}, got {value!r}")


@dataclass(frozen=True, slots=True)
class GoToGoalParams:
    """Gains and limits of the go-to-goal controller.

    Attributes:
        kp_lin: forward speed per metre of distance to goal, 1/s (>= 0).
        kp_ang: yaw rate per radian of heading error, 1/s (>= 0).
        max_v: forward speed limit, m/s (>= 0).
        max_omega: yaw-rate limit, rad/s (>= 0).
        tolerance: goal counts as reached at or below this distance, m (>= 0).
        turn_in_place_threshold: above this absolute heading error, rad, the robot
            turns in place (v = 0); at or below it, it drives with v scaled by
            cos(heading error).
    """

    kp_lin: float = 0.8
    kp_ang: float = 2.0
    max_v: float = _BASE.max_v
    max_omega: float = _BASE.max_omega
    tolerance: float = 0.1
    turn_in_place_threshold: float = 0.6

    def __post_init__(self) -> None:
        _finite(self, ">= 0", *(f.name for f in fields(self)))


_GOAL = GoToGoalParams()


@dataclass(frozen=True, slots=True)
class GuardParams:
    """Obstacle guard settings.

    Attributes:
        sector_half_angle: half-width of the guarded sector around straight ahead,
            rad, in [0, pi].
        stop_distance: blocked when a valid return in the sector is at or below this
            range, m (>= 0).
    """

    sector_half_angle: float = 0.5
    stop_distance: float = 0.35

    def __post_init__(self) -> None:
        if not (math.isfinite(self.sector_half_angle) and 0.0 <= self.sector_half_angle <= math.pi):
            raise ValueError(
                f"GuardParams.sector_half_angle must be in [0, pi], got {self.sector_half_angle!r}"
            )
        _finite(self, ">= 0", "stop_distance")


@dataclass(frozen=True, slots=True)
class DwaParams:
    """Settings of :func:`~otonav.nav._dwa.dwa_step`. A field ``nav.dwa.*`` sets means
    what that key says (:class:`DwaConfig`), and:

    Attributes:
        max_v: forward speed limit, m/s (> 0).
        max_omega: yaw-rate limit, rad/s (> 0).
        max_accel: linear acceleration limit (the base's), m/s^2 (> 0).
        max_alpha: angular acceleration limit (the base's), rad/s^2 (> 0).
        period: control period: the window is what the limits reach in it, s (> 0).
        radius: centre clearance to keep (footprint.centre_clearance), m (>= 0).
        rotate_threshold: with the target farther off the heading than this, rad, the
            window's speeds shrink to its lowest (slow down and turn toward it first,
            like Nav2's rotation shim) (>= 0).
    """

    max_v: float = 0.4
    max_omega: float = 1.2
    max_accel: float = _BASE.max_accel
    max_alpha: float = _BASE.max_alpha
    period: float = 0.05
    horizon: float = 1.6
    dt: float = 0.2
    v_samples: int = 5
    omega_samples: int = 13
    radius: float = 0.33
    latency: float = 0.1
    clearance_cap: float = 0.25
    w_heading: float = 1.0
    w_progress: float = 2.0
    w_clearance: float = 0.6
    w_speed: float = 0.3
    rotate_threshold: float = _GOAL.turn_in_place_threshold
    fast_path: bool = True
    fast_margin: float = 0.2

    def __post_init__(self) -> None:
        _finite(self, "> 0", "max_v", "max_omega", "max_accel", "max_alpha", "period")
        _finite(self, "> 0", "horizon", "dt", "clearance_cap")
        _integer(self, 1, "v_samples", "omega_samples")
        _finite(self, ">= 0", "radius", "latency", "w_heading", "w_progress", "w_clearance")
        _finite(self, ">= 0", "w_speed", "rotate_threshold", "fast_margin")
        if not isinstance(self.fast_path, bool):
            raise ValueError(f"DwaParams.fast_path must be a bool, got {self.fast_path!r}")
        if self.dt > self.horizon:
            raise ValueError(f"DwaParams.dt ({self.dt} s) must be <= horizon ({self.horizon} s)")


_DWA = DwaParams()


@dataclass(frozen=True, slots=True)
class SafetyParams:
    """Settings of :func:`~otonav.nav._safety.safe_command`.

    Attributes:
        radius: centre clearance to keep (footprint.centre_clearance), m (> 0).
        max_accel: the base's linear acceleration/deceleration limit, m/s^2 (> 0).
        max_alpha: the base's angular acceleration limit, rad/s^2 (> 0).
        latency: delay before braking starts, s (>= 0).
        dt: integration step of the stopping path, s (> 0).
        scales: forward-speed scales tried, from 1 down to 0 (>= 2).
    """

    radius: float = _DWA.radius
    max_accel: float = _BASE.max_accel
    max_alpha: float = _BASE.max_alpha
    latency: float = 0.12
    dt: float = 0.02
    scales: int = 6

    def __post_init__(self) -> None:
        _finite(self, "> 0", "radius", "max_accel", "max_alpha", "dt")
        _finite(self, ">= 0", "latency")
        _integer(self, 2, "scales")


@dataclass(frozen=True, slots=True)
class MatchParams:
    """Settings of :func:`~otonav.nav._scan_match.match_scan` (stack config ``nav.localization.*``).

    Attributes:
        linear_window: the correlative search spans +- this in x and y, m.
        linear_step: its spacing in x and y, m.
        angular_window: it spans +- this in yaw, rad.
        angular_step: its spacing in yaw, rad.
        max_distance: a point this far or farther from the map is not matched, m.
        prior: weight of the pull toward the prediction, per m^2 (the scan's own
            term is a sum of squared metres over its points). With 0, a scan that
            constrains nothing leaves the refinement where it started.
        yaw_scale: m of the prior per rad of yaw.
        iterations: Gauss-Newton steps at most.
        min_inliers: fraction of the points that must lie within ``max_distance``.
    """

    linear_window: float = 0.1
    linear_step: float = 0.05
    angular_window: float = 0.06
    angular_step: float = 0.02
    max_distance: float = 0.3
    prior: float = 1.0
    yaw_scale: float = 1.0
    iterations: int = 10
    min_inliers: float = 0.3

    def __post_init__(self) -> None:
        _finite(self, ">= 0", "linear_window", "angular_window", "prior", "yaw_scale")
        _finite(self, "> 0", "linear_step", "angular_step", "max_distance")
        _integer(self, 0, "iterations")
        if not 0.0 <= self.min_inliers <= 1.0:
            raise ValueError(f"MatchParams.min_inliers must be in [0, 1], got {self.min_inliers}")


@dataclass(frozen=True, slots=True)
class LocalizerParams:
    """Settings of :class:`~otonav.actors._localizer.Localizer`: ``match``, the scan
    matcher's; each other field means what ``nav.localization.*`` of its name says
    (:class:`LocalizationConfig`)."""

    match: MatchParams = field(default_factory=MatchParams)
    resolution: float = 0.05
    half_size: float = 10.0
    update_distance: float = 0.1
    update_angle: float = 0.1
    map_period: float = 5.0


@dataclass(frozen=True, slots=True)
class NavigationParams:
    """Settings of :class:`otonav.nav.Navigation`. Each field means what the
    config key that sets it says (:data:`CONFIG_KEYS`: ``nav.map.*``, ``nav.recovery.*``,
    ``nav.tolerance``, ...), and:

    Attributes:
        dwa: the local planner's settings (its ``radius`` is the centre clearance).
        hull_margin: once the goal lies inside the convex hull of what the robot has
            observed (returns, free beam ends, laser positions), A* routes only within
            this distance of it, m (:mod:`otonav.nav._observed_hull`).
    """

    dwa: DwaParams = field(default_factory=DwaParams)
    tolerance: float = 0.08
    map_half_size: float = 10.0
    map_resolution: float = 0.05
    plan_resolution: float = 0.1
    plan_penalty: float = 2.0
    replan_period: float = 0.5
    lookahead: float = 0.8
    max_expansions: int = 60_000
    expansions_per_tick: int = 600
    clear_range: float = 3.0
    hull_margin: float = 0.25
    progress_distance: float = 0.3
    progress_window: float = 3.5
    goal_progress_window: float = 30.0
    spin_angle: float = math.pi / 2
    spin_speed: float = 1.0
    backup_distance: float = 0.3
    backup_speed: float = 0.15
    follow_time: float = 5.0
    follow_speed: float = 0.2
    follow_distance: float = 0.45
    clear_radius: float = 1.0
    approach_radius: float = 0.25
    kp_lin: float = _GOAL.kp_lin
    kp_ang: float = _GOAL.kp_ang


_NAV = NavigationParams()
_GUARD = GuardParams()
_SAFETY = SafetyParams()
_LOC = LocalizerParams()


class GuardConfig(Section):
    """Obstacle guard: front sector half-angle (rad) and stop distance (m)."""

    sector_half_angle: float = Field(_GUARD.sector_half_angle, gt=0.0, le=math.pi)
    """rad either side of straight ahead that the guard watches."""
    stop_distance: PositiveFloat = _GUARD.stop_distance
    """m: stop when a valid return in the sector is this close."""


class DwaConfig(Section):
    """The DWA local planner (``nav.planner = dwa``; otonav.nav._dwa). Its window is
    what the base's ``max_accel`` / ``max_alpha`` reach in one nav period."""

    horizon: float = Field(_DWA.horizon, gt=0.0, le=10.0)
    """s, rollout length, in (0, 10]."""
    dt: float = Field(_DWA.dt, gt=0.0, le=1.0)
    """s, spacing of the rollout poses, in (0, 1] and <= horizon."""
    v_samples: int = Field(_DWA.v_samples, ge=1, le=50)
    """speed samples across the window, in [1, 50]."""
    omega_samples: int = Field(_DWA.omega_samples, ge=1, le=100)
    """yaw-rate samples across the window, in [1, 100]."""
    latency: float = Field(_DWA.latency, ge=0.0, le=2.0)
    """s, command delay assumed before braking (admissibility), in [0, 2]."""
    clearance_cap: float = Field(_DWA.clearance_cap, gt=0.0, le=5.0)
    """m, clearance beyond the centre clearance that stops scoring, in (0, 5]."""
    w_heading: float = Field(_DWA.w_heading, ge=0.0, le=100.0)
    """score weight of heading to the target at the rollout's end, in [0, 100]."""
    w_progress: float = Field(_DWA.w_progress, ge=0.0, le=100.0)
    """score weight of distance gained toward the target, in [0, 100]."""
    w_clearance: float = Field(_DWA.w_clearance, ge=0.0, le=100.0)
    """score weight of clearance along the rollout, in [0, 100]."""
    w_speed: float = Field(_DWA.w_speed, ge=0.0, le=100.0)
    """score weight of forward speed, in [0, 100]."""
    fast_path: bool = _DWA.fast_path
    """try the pure-pursuit arc to the target first and skip the sampling when it
    provably keeps ``fast_margin`` beyond the centre clearance (otonav.nav._dwa)."""
    fast_margin: float = Field(_DWA.fast_margin, ge=0.0, le=5.0)
    """m, clearance beyond the centre clearance the fast path's arc keeps, in [0, 5]."""


class MapConfig(Section):
    """The navigator's map of the scans and its global planner (A*)."""

    half_size: float = Field(_NAV.map_half_size, gt=0.0, le=100.0)
    """m, the map spans this far from the start pose in x and y, in (0, 100]."""
    resolution: float = Field(_NAV.map_resolution, ge=0.005, le=0.2)
    """m, map cell, in [0.005, 0.2]. Clearances read from the map are lower bounds,
    short by up to resolution * sqrt(2); 5 cm marks 4x fewer kernel cells per return
    than 2.5 cm (the map update was the planner's largest cost)."""
    plan_resolution: float = Field(_NAV.plan_resolution, ge=0.005, le=1.0)
    """m, global planner cell (a multiple of ``resolution``), in [0.005, 1]."""
    plan_penalty: float = Field(_NAV.plan_penalty, ge=0.0, le=100.0)
    """extra path cost per cell near obstacles (0: shortest path), in [0, 100]."""
    replan_period: float = Field(_NAV.replan_period, gt=0.0, le=60.0)
    """s, how often the path ahead is checked for new obstacles, in (0, 60]."""
    lookahead: float = Field(_NAV.lookahead, gt=0.0, le=10.0)
    """m, the DWA heads for the path point this far ahead at full speed (2 s of the
    current speed when slower, at least 0.4 m: Nav2 RPP's scaled lookahead), in (0, 10]."""
    max_expansions: int = Field(_NAV.max_expansions, ge=100, le=10_000_000)
    """A* gives up (no proof either way) after this many cells, in [100, 1e7]."""
    expansions_per_tick: int = Field(_NAV.expansions_per_tick, ge=10, le=10_000_000)
    """A* expands at most this many cells per navigator step; a longer search goes on
    at the next step (bounded tick time, ADR 0043), in [10, 1e7]."""
    clear_range: float = Field(_NAV.clear_range, ge=0.0, le=100.0)
    """m, before a replan the map frees the cells within this range that the last
    scan saw through (a moved obstacle, a misread); 0: never, in [0, 100]."""


class RecoveryConfig(Section):
    """Progress checker and recovery ladder (spin, backup, follow, then unreachable):
    with the defaults the whole ladder, stuck robot to ``unreachable``, takes at most
    4 x 3.5 s of windows + 2.1 + 2.5 + 5 s of rungs = 23.6 s of sim time."""

    progress_distance: float = Field(_NAV.progress_distance, gt=0.0, le=10.0)
    """m, progress that counts, in (0, 10]."""
    progress_window: float = Field(_NAV.progress_window, gt=0.0, le=600.0)
    """s of sim time to shrink the distance to go along the path by
    ``progress_distance`` (what the robot does, not what the planner says), in (0, 600]."""
    goal_progress_window: float = Field(_NAV.goal_progress_window, gt=0.0, le=3600.0)
    """s of sim time to get ``progress_distance`` closer to the goal, in (0, 3600]."""
    spin_angle: float = Field(_NAV.spin_angle, gt=0.0, le=2 * math.pi)
    """rad, the look-around turn, in (0, 2 pi]."""
    spin_speed: float = Field(_NAV.spin_speed, gt=0.0, le=10.0)
    """rad/s, in (0, 10]."""
    backup_distance: float = Field(_NAV.backup_distance, gt=0.0, le=5.0)
    """m, in (0, 5]."""
    backup_speed: float = Field(_NAV.backup_speed, gt=0.0, le=2.0)
    """m/s, in (0, 2]."""
    follow_time: float = Field(_NAV.follow_time, gt=0.0, le=600.0)
    """s, the longest boundary following, in (0, 600]."""
    follow_speed: float = Field(_NAV.follow_speed, gt=0.0, le=2.0)
    """m/s, in (0, 2]."""
    follow_distance: float = Field(_NAV.follow_distance, gt=0.0, le=5.0)
    """m, robot centre to the boundary while following, in (0, 5]."""
    clear_radius: float = Field(_NAV.clear_radius, ge=0.0, le=20.0)
    """m, the spin rung first clears the map within this distance of the robot (0:
    never), in [0, 20]."""


class LocalizationConfig(Section):
    """Scan-to-map localization (``otonav.actors._localizer``, ADR 0053): a map built
    from the scans at their corrected poses, each scan matched to it; publishes
    ``map -> odom`` on /tf and the map on /map; the ``dwa`` navigator then works in the
    map frame (its ``reached`` is judged on the localized pose)."""

    enabled: bool = False
    """Run the localizer and navigate on its pose (false: odometry alone)."""
    resolution: float = Field(_LOC.resolution, ge=0.01, le=0.2)
    """m, the map's cell, in [0.01, 0.2]."""
    half_size: float = Field(_LOC.half_size, gt=0.0, le=100.0)
    """m, the map spans this far from the start pose in x and y, in (0, 100]."""
    linear_window: float = Field(_LOC.match.linear_window, ge=0.0, le=1.0)
    """m, the correlative search spans +- this in x and y around the odometry's
    prediction, in [0, 1]."""
    angular_window: float = Field(_LOC.match.angular_window, ge=0.0, le=0.5)
    """rad, it spans +- this in yaw, in [0, 0.5]."""
    max_distance: float = Field(_LOC.match.max_distance, gt=0.0, le=2.0)
    """m, a return farther than this from the map is not matched (new ground), in
    (0, 2]."""
    update_distance: float = Field(_LOC.update_distance, ge=0.0, le=5.0)
    """m the robot moves before a scan is added to the map, in [0, 5]."""
    update_angle: float = Field(_LOC.update_angle, ge=0.0, le=math.pi)
    """rad it turns before a scan is added to the map, in [0, pi]."""
    map_period: float = Field(_LOC.map_period, gt=0.0, le=600.0)
    """s of sim time between /map messages (only when the map changed), in (0, 600]."""


class SafetyConfig(Section):
    """The safety layer between the planner (/cmd_vel_nav) and the base (/cmd_vel)."""

    enabled: bool = True
    """False: the planner drives /cmd_vel directly (nothing checks it)."""
    rate_hz: float = Field(20.0, ge=1.0, le=1000.0)
    """Hz, how often the command is checked and sent, in [1, 1000]."""
    clearance: float = Field(0.32, gt=0.0, le=5.0)
    """m, robot centre (base_link) to any return: the robot can always stop before
    coming closer, in (0, 5]. Keep it above the judge's min_clearance."""
    footprint_padding: float = Field(0.03, ge=0.0, le=1.0)
    """m, gap kept between the footprint and any return, in [0, 1]: the centre keeps
    max(clearance, footprint radius + padding)."""
    drive_lag: float = Field(0.05, ge=0.0, le=2.0)
    """s, the drives' lag behind the base's command; the braking delay assumed is
    1/rate_hz + 1/base.rate_hz + drive_lag, in [0, 2]."""
    cmd_timeout: float = Field(0.25, gt=0.0, le=10.0)
    """s without /cmd_vel_nav before the command counts as zero, in (0, 10]."""
    scan_timeout: float = Field(0.35, gt=0.0, le=10.0)
    """s without /scan (or /odom) before the layer stops the robot (blind), in (0, 10]."""
    scales: int = Field(_SAFETY.scales, ge=2, le=100)
    """forward-speed scales tried from 1 down to 0, in [2, 100]."""


_SAFETY_LAYER = SafetyConfig()


class NavConfig(Section):
    """Navigator: which planner, go-to-goal gains (``stop``), limits, footprint,
    clearance, and the avoiding planner's sections."""

    planner: Literal["stop", "dwa", "external"] = "dwa"
    """``dwa``: map + A* + DWA + recovery (avoids obstacles); ``stop``: go-to-goal that
    stops in front of an obstacle (the original behaviour); ``external``: no planner
    actor, your own node publishes /cmd_vel_nav (behind the safety layer)."""
    rate_hz: PositiveFloat = 1.0 / _DWA.period
    """Hz, how often the navigator plans: the DWA's window is what the base's
    accelerations reach in one period (``1 / rate_hz``)."""
    kp_lin: float = Field(_NAV.kp_lin, ge=0.0)
    """Proportional gain on the distance to the goal (``stop`` planner, and the final
    approach of ``dwa``), 1/s."""
    kp_ang: float = Field(_NAV.kp_ang, ge=0.0)
    """Proportional gain on the heading error, 1/s."""
    max_v: PositiveFloat = _NAV.dwa.max_v
    """m/s, the fastest the navigator asks for (``robot.max_v``, when stated, sets it)."""
    max_omega: PositiveFloat = _NAV.dwa.max_omega
    """rad/s, the fastest turn the navigator asks for."""
    tolerance: PositiveFloat = _NAV.tolerance
    """m: the navigator stops within this distance of the goal (by odometry)."""
    turn_in_place_threshold: PositiveFloat = _NAV.dwa.rotate_threshold
    """rad of heading error above which the robot turns in place first."""
    clearance: float = Field(0.35, ge=0.0, le=5.0)
    """m, robot centre (base_link, the judged point) to any return: what the planner
    keeps, in [0, 5]; at least ``safety.clearance``."""
    approach_radius: float = Field(_NAV.approach_radius, ge=0.0, le=5.0)
    """m (dwa planner): within this distance of the goal a proportional controller
    (``kp_lin``, ``kp_ang``) finishes, in reverse if the goal is behind, in [0, 5]."""
    footprint_padding: float = Field(_SAFETY_LAYER.footprint_padding, ge=0.0, le=1.0)
    """m, gap kept between the footprint (read from the MJCF) and any return, in [0, 1].
    The planner keeps its centre max(clearance, footprint radius + padding) away. The
    safety layer's by default (issue 42: 0.05 m, more than the layer that guarantees the
    stop, refused BARN passages a Jackal-sized robot passes; Nav2's is 0.01 m)."""
    dwa: DwaConfig = DwaConfig()
    map: MapConfig = MapConfig()
    recovery: RecoveryConfig = RecoveryConfig()
    localization: LocalizationConfig = LocalizationConfig()


_SPEEDS = {name: f"base.{name}" for name in ("max_v", "max_omega")}
_ACCELERATIONS = {name: f"base.{name}" for name in ("max_accel", "max_alpha")}
CONFIG_KEYS: dict[type, dict[str, str]] = {
    GoToGoalParams: {
        **{name: f"nav.{name}" for name in ("kp_lin", "kp_ang", "tolerance")},
        "turn_in_place_threshold": "nav.turn_in_place_threshold",
        **_SPEEDS,
    },
    DwaParams: {
        **{name: f"nav.dwa.{name}" for name in DwaConfig.model_fields},
        "rotate_threshold": "nav.turn_in_place_threshold",
        **_SPEEDS,
        **_ACCELERATIONS,
    },
    SafetyParams: {"radius": "safety.clearance", "scales": "safety.scales", **_ACCELERATIONS},
    NavigationParams: {
        **{name: f"nav.{name}" for name in ("tolerance", "approach_radius", "kp_lin", "kp_ang")},
        # nav.map.half_size and .resolution are map_half_size and map_resolution here
        **{
            f"map_{name}" if name in ("half_size", "resolution") else name: f"nav.map.{name}"
            for name in MapConfig.model_fields
        },
        **{name: f"nav.recovery.{name}" for name in RecoveryConfig.model_fields},
    },
}
"""Per nav dataclass, field -> the config key that sets it, or for one capped by the
robot's base (a speed, an acceleration) the base's key; the safety radius, a centre
clearance, has ``safety.clearance``'s. ``stack.build`` reads each field it does not
derive from its key; a value set while the robot runs must pass that key's bounds
(``otonav.stack._live_parameters``). A field with no key (a period or a latency derived
from several keys) is read-only while the robot runs."""
