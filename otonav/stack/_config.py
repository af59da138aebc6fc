"""The launch file as data: pydantic models are the schema, defaults live in them (an
installed wheel runs with no checkout); YAML files in ``config/`` override them. The
sections that set the robot's base, the navigator, the guard and the safety layer are
the parameter models' (:mod:`otonav.params`, numpy-free)."""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    ConfigDict,
    Field,
    PositiveFloat,
    PositiveInt,
    model_validator,
)

from otonav import limits
from otonav.params import (
    LIDAR_BEAMS,
    LIDAR_RANGE,
    AxisParams,
    BaseConfig,
    GuardConfig,
    MonitorLimits,
    NavConfig,
    RatesConfig,
    SafetyConfig,
    Section,
)


def _within(lo: float, hi: float, unit: str = "", *, open_low: bool = False) -> AfterValidator:
    """A bound whose one-line error names the whole valid range (the CAN sections)."""
    low = "(" if open_low else "["

    def check(value: float) -> float:
        if (value <= lo if open_low else value < lo) or value > hi:
            raise ValueError(f"must be in {low}{lo:g}, {hi:g}]{unit}")
        return value

    return AfterValidator(check)


_CanPeriod = Annotated[float, _within(limits.MIN_CAN_PERIOD_S, limits.MAX_CAN_PERIOD_S, " s")]
"""A cyclic frame period, s (see ``otonav.limits``)."""
_CanTimeout = Annotated[float, _within(0.0, limits.MAX_CAN_TIMEOUT_S, " s", open_low=True)]
"""A CAN wait that must be > 0, s."""
_CanDelay = Annotated[float, _within(0.0, limits.MAX_CAN_TIMEOUT_S, " s")]
"""A CAN wait where 0 means none (or off), s."""
_NodeId = Annotated[int, _within(0, 63)]
"""An ODrive CAN Simple node id: 6 bits."""

_MONITOR = MonitorLimits()
_DRIVE = AxisParams(0)


class OdometryErrorConfig(Section):
    """A deterministic odometry error model for simulation (all zero: off): what a
    mis-calibrated wheel radius and a biased, noisy gyro do to the bridge's /odom (and
    /tf odom -> base_link). /imu and ground truth are untouched."""

    scale: float = Field(0.0, ge=-0.2, le=0.2)
    """m added per m driven: every distance the wheels report is scaled by 1 + scale (a
    wheel radius off by that fraction), in [-0.2, 0.2]."""
    gyro_bias: float = Field(0.0, ge=-0.5, le=0.5)
    """rad/s added to the yaw rate odometry integrates (heading drifts by it), in
    [-0.5, 0.5]."""
    gyro_noise: float = Field(0.0, ge=0.0, le=1.0)
    """rad/s, standard deviation of white noise on that yaw rate, per odometry
    sample, in [0, 1]."""
    seed: int = Field(0, ge=0, le=limits.MAX_SEED)
    """Seeds the noise (the same seed, the same drift)."""

    @property
    def enabled(self) -> bool:
        return self.scale != 0.0 or self.gyro_bias != 0.0 or self.gyro_noise != 0.0


class WorldConfig(Section):
    """The simulated world (``otonav.hal.mujoco``)."""

    scene: str = Field("obstacles", min_length=1, max_length=limits.MAX_PATH_CHARS)
    """Built-in scene name (``empty``, ``obstacles``) or a path to an MJCF file."""
    timestep: float = Field(0.002, ge=limits.MIN_TIMESTEP_S, le=limits.MAX_TIMESTEP_S)
    """Physics step, s: one tick of sim time. Bounded by the cost of a step below and by
    the fastest timer (the judge's 100 Hz) above: see ``otonav.limits``."""
    lidar_beams: PositiveInt = Field(LIDAR_BEAMS, le=limits.MAX_LIDAR_BEAMS)
    """Beams over a full circle, at most 3600 (0.1 degree, the finest 2D lidars)."""
    lidar_range_min: float = Field(LIDAR_RANGE[0], ge=0.0)
    """m, returns closer than this read as -inf (below range), < ``lidar_range_max``."""
    lidar_range_max: PositiveFloat = Field(LIDAR_RANGE[1], le=limits.MAX_LIDAR_RANGE_M)
    """m, at most 1 km: ranges are float32 in the recording."""
    lidar_fov: float = Field(2.0 * math.pi, gt=0.0, le=2.0 * math.pi)
    """rad, the lidar's field of view, centred ahead, in (0, 2 pi] (BARN's Jackal: 4.71,
    270 degrees). Below a full circle the first and last beams are at -fov/2 and +fov/2,
    as /scan's ``angle_min`` and ``angle_max`` say."""
    odometry_error: OdometryErrorConfig = OdometryErrorConfig()
    """Simulated odometry drift (off by default): see :class:`OdometryErrorConfig`."""


class CanAxisConfig(Section):
    """One wheel's drive as the host sees it: CAN node id, direction sign, gearing."""

    node_id: _NodeId = 0
    sign: Literal[1, -1] = 1
    """+1 if positive motor turns drive the wheel forward, -1 if the motor is mirrored."""
    gear_ratio: Annotated[float, _within(limits.MIN_GEAR_RATIO, limits.MAX_GEAR_RATIO)] = 1.0
    """Motor turns per wheel revolution (wheel rad = sign * 2 pi * turns / gear_ratio)."""


class CanConfig(Section):
    """The wheel bus (``hal.kind: can``): python-can interface and channel, the two
    ODrive axes, and the fault-detection limits (s of sim time). Every number is
    bounded (``otonav.limits``, ADR 0019); the error names the valid range."""

    interface: str = Field("virtual", min_length=1, max_length=limits.MAX_CAN_NAME_CHARS)
    """python-can interface: ``virtual`` (in-process, with the drive emulator) or
    ``socketcan`` (a Linux CAN link such as ``can0`` or ``vcan0``)."""
    channel: str = Field("can0", min_length=1, max_length=limits.MAX_CAN_NAME_CHARS)
    """python-can channel, e.g. ``can0`` or ``vcan0`` for SocketCAN."""
    emulate: bool = True
    """Run the drive emulator at the far end of the bus (false: real drives)."""
    left: CanAxisConfig = CanAxisConfig(node_id=0, sign=-1)
    right: CanAxisConfig = CanAxisConfig(node_id=1, sign=1)
    encoder_period: _CanPeriod = _MONITOR.encoder_period
    """The drives' Get_Encoder_Estimates period (ODrive ``encoder_msg_rate_ms``)."""
    startup_timeout: _CanTimeout = _MONITOR.startup_timeout
    heartbeat_timeout: _CanTimeout = _MONITOR.heartbeat_timeout
    encoder_timeout: _CanTimeout = _MONITOR.encoder_timeout
    """s: an encoder estimate older than this (none arrived, or its frame's timestamp is
    that old) is a fault for as long as it lasts. Must be longer than ``encoder_period``."""
    max_frame_loss: Annotated[float, _within(0.0, 1.0)] = _MONITOR.max_frame_loss
    """Fraction of encoder frames that may be lost over ``loss_window`` s."""
    loss_window: _CanTimeout = _MONITOR.loss_window
    """At least ``encoder_period``."""
    recovery_delay: _CanDelay = _MONITOR.recovery_delay
    """s a fault's cause must stay clear before recovery starts."""
    max_recovery_attempts: Annotated[int, _within(0, limits.MAX_RECOVERY_ATTEMPTS)] = (
        _MONITOR.max_recovery_attempts
    )
    """Recovery attempts per drive, whatever the fault; then the fault is permanent and
    a scenario run ends on it."""
    recovery_reset: _CanTimeout = _MONITOR.recovery_reset
    """s a drive must run without a fault before its count of recovery attempts starts
    again from zero."""
    command_keepalive: _CanDelay = 0.1
    """s: an unchanged wheel setpoint is sent again only this often (0: at every base
    tick). Keep it well under the drives' watchdog timeout."""
    input_mode: Literal["passthrough", "vel_ramp"] = "passthrough"
    """The ODrive input mode the interface selects at startup (Set_Controller_Mode,
    velocity control): ``passthrough``, the setpoint follows each Set_Input_Vel at once
    (the base controller already limits acceleration), or ``vel_ramp``, the drive slews
    it at its own ``vel_ramp_rate`` (``hal.sim.vel_ramp_rate`` for emulated drives)."""
    record_frames: bool = True
    """Publish every frame on /can/frames (and so into the recording)."""


_FaultTime = Annotated[float, _within(0.0, limits.MAX_SIM_BUDGET_S, " s")]
"""s of sim time at which a fault starts or ends."""


class _Timed(Section):
    at: _FaultTime = 0.0
    """s of sim time the fault starts."""
    until: _FaultTime | None = None
    """s of sim time it ends (null: it lasts to the end of the run)."""

    @model_validator(mode="after")
    def _ordered(self) -> _Timed:
        if self.until is not None and self.until <= self.at:
            raise ValueError(f"until ({self.until:g} s) must be after at ({self.at:g} s)")
        return self


class DropFault(_Timed):
    """Frames lost at random, both ways."""

    rate: Annotated[float, _within(0.0, 1.0)] = 0.0
    """probability a frame is lost, in [0, 1] (0: off)."""


class DelayFault(_Timed):
    """Frames held back, both ways (with jitter they may arrive out of order)."""

    delay: _CanDelay = 0.0
    """s every frame is held back (0 and no jitter: off)."""
    jitter: _CanDelay = 0.0
    """s, up to this much more, uniform."""


class AxisErrorFault(Section):
    """A drive reports an axis error and disarms, until the host clears it."""

    node_id: _NodeId | None = None
    """the drive (null: off)."""
    code: Annotated[int, _within(1, 0xFFFFFFFF)] = 0x20
    """ODrive error bits (default DRV_FAULT, 0x20)."""
    at: _FaultTime = 0.0


class BusOffFault(Section):
    """The bus goes bus-off (nothing passes) and restarts."""

    at: _FaultTime | None = None
    """s it goes off (null: never)."""
    until: _FaultTime | None = None

    @model_validator(mode="after")
    def _ordered(self) -> BusOffFault:
        if self.at is None and self.until is not None:
            raise ValueError("until needs at (when the bus goes off)")
        if self.at is not None and self.until is not None and self.until <= self.at:
            raise ValueError(f"until ({self.until:g} s) must be after at ({self.at:g} s)")
        return self


class HeartbeatFault(_Timed):
    """A drive's heartbeat stops (it still obeys commands)."""

    node_id: _NodeId | None = None
    """the drive (null: off)."""


class FaultsConfig(Section):
    """Faults the emulated drives and bus inject, each from a time of the run (ADR 0046):
    e.g. ``--set hal.sim.faults.drop.rate=0.5 --set hal.sim.faults.drop.at=2``."""

    drop: DropFault = DropFault()
    delay: DelayFault = DelayFault()
    axis_error: AxisErrorFault = AxisErrorFault()
    bus_off: BusOffFault = BusOffFault()
    heartbeat: HeartbeatFault = HeartbeatFault()


class DriveSimConfig(Section):
    """The emulated drives (``otonav.hal.sim``): how they are configured, which can
    differ from what the host expects (a wrong node id, a slower heartbeat: faults to
    detect, not configs to refuse)."""

    left_node_id: _NodeId = 0
    right_node_id: _NodeId = 1
    heartbeat_period: _CanPeriod = 0.1
    encoder_period: _CanPeriod = _MONITOR.encoder_period
    """By default the drives send as often as the host expects (``hal.can``)."""
    vel_limit: Annotated[
        float, _within(0.0, limits.MAX_DRIVE_VEL_TURNS_S, " turns/s", open_low=True)
    ] = _DRIVE.vel_limit
    """turns/s."""
    vel_ramp_rate: Annotated[
        float, _within(0.0, limits.MAX_DRIVE_RAMP_TURNS_S2, " turns/s^2", open_low=True)
    ] = _DRIVE.vel_ramp_rate
    """turns/s^2: the setpoint's slew in input mode VEL_RAMP (``hal.can.input_mode``)."""
    watchdog_timeout: _CanDelay = _DRIVE.watchdog_timeout
    """s without Set_Input_Vel before the axis stops (0: off)."""
    arm_time: _CanDelay = _DRIVE.arm_time
    seed: int = Field(0, ge=0, le=limits.MAX_SEED)
    """Seeds the injected faults' random numbers."""
    faults: FaultsConfig = FaultsConfig()
    """Faults to inject, on a timetable (nothing by default)."""


class HalConfig(Section):
    """Which hardware is under the HAL: the MuJoCo world directly, or the wheels over a
    CAN bus (drives emulated on MuJoCo's wheels, or real drives)."""

    kind: Literal["mujoco", "can"] = "mujoco"
    """``mujoco``: the wheels are MuJoCo's actuators; ``can``: the wheels are drives on a
    CAN bus (``hal.can``)."""
    can: CanConfig = CanConfig()
    sim: DriveSimConfig = DriveSimConfig()


_Name = Annotated[
    str,
    Field(min_length=1, max_length=limits.MAX_NAME_CHARS),
    AfterValidator(limits.one_printable_line),
]
"""A name in the robot model (a body, joint or site) or of an actor."""
_Vec3 = tuple[float, float, float]


class MountConfig(Section):
    """Where a sensor sits: a site the model already has, or a point on a body (metres,
    in the body's frame; the sensor's axes are the robot base's)."""

    site: _Name | None = None
    """A site of the model (e.g. a URDF's ``base_scan`` link becomes a body: use body)."""
    body: _Name | None = None
    """The body the sensor is mounted on (default: the robot's base)."""
    pos: _Vec3 | None = None
    """m, in the body's frame."""

    @model_validator(mode="after")
    def _one_way(self) -> MountConfig:
        if self.site is not None and (self.body is not None or self.pos is not None):
            raise ValueError("give either site, or body and pos, not both")
        if self.site is None and self.pos is None:
            raise ValueError("give a site, or a pos (and optionally a body)")
        return self


class FramesConfig(Section):
    """The frame ids of the robot's links in /odom, /tf, /tf_static, /scan and /imu, as
    its URDF names them (REP 105); ``odom`` stays ``odom``. Unset: the model's names (the
    base body, the lidar's and the IMU's site or body), ``base_link``, ``laser`` and
    ``imu_link`` for otonav's own robot or a sensor otonav mounts on the base."""

    base: _Name | None = None
    """The base frame: /odom's child frame and the parent of the sensors' (a Nav2 robot
    often says ``base_footprint``)."""
    laser: _Name | None = None
    """The lidar's frame (/scan's ``frame_id``)."""
    imu: _Name | None = None
    """The IMU's frame (/imu's ``frame_id``)."""


class RobotConfig(Section):
    """The robot description (``otonav.hal._description``): a built-in robot or the
    user's MJCF/URDF, the names of its base and wheels, where its sensors sit. Wheel
    radius and separation, footprint and sensor offsets are derived from the model; a
    value given here overrides the derived one."""

    model: str = Field("otonav", min_length=1, max_length=limits.MAX_PATH_CHARS)
    """A built-in robot (``otonav``, ``burger``) or an MJCF/URDF file (a path relative
    to the config file it is written in)."""
    base: _Name | None = None
    """The robot's base body (base_link); it gets a free joint if it has none."""
    left_wheel: _Name | None = None
    """The left wheel's hinge joint (its actuator is found through it)."""
    right_wheel: _Name | None = None
    lidar: MountConfig | None = None
    """Where otonav's lidar casts from (default: the model's own, else on top)."""
    imu: MountConfig | None = None
    wheel_radius: float | None = Field(None, gt=0.0, le=5.0)
    """m: overrides the radius derived from the wheel's collision geom, in (0, 5]."""
    wheel_separation: float | None = Field(None, gt=0.0, le=20.0)
    """m: overrides the separation derived from the wheel joints, in (0, 20]."""
    footprint: tuple[tuple[float, float], ...] | None = Field(None, min_length=3)
    """(x, y) points in base_link, m: overrides the derived outline."""
    max_v: float | None = Field(None, gt=0.0, le=limits.MAX_BASE_V)
    """m/s, the robot's top speed: what the base and the navigator use (up or down from
    their defaults; a ``base.max_v`` / ``nav.max_v`` set away from its default lowers it,
    with a warning), and it scales scenario budgets."""
    max_omega: float | None = Field(None, gt=0.0, le=limits.MAX_BASE_OMEGA)
    """rad/s, the robot's top yaw rate: what the base and the navigator use (as
    ``max_v``)."""
    frames: FramesConfig = FramesConfig()
    """The frame ids otonav stamps its messages with (``--set robot.frames.base=...``)."""


class ActorConfig(Section):
    """One node of the launch: a class (``package.module:Class`` on ``sys.path``, in the
    current directory or the config file's, or ``path/to/file.py:Class`` relative to the
    config file) with its parameters and topic remaps. An entry named like a built-in
    actor (``nav``, ``safety``, ``base``) replaces it, or with no ``class``
    only remaps its topics (ADR 0071)."""

    name: _Name
    class_: str | None = Field(None, alias="class", min_length=3, max_length=limits.MAX_PATH_CHARS)
    """The node's class; none: the built-in actor of this name, remapped."""
    params: dict[str, Any] = Field(default_factory=dict)
    """Validated at start-up against the class's ``Params`` model; they win over
    ``params_file``'s."""
    params_file: str | None = Field(None, min_length=1, max_length=limits.MAX_PATH_CHARS)
    """A ROS 2 parameter file (``NAME: {ros__parameters: {...}}``, or ``/**:``),
    relative to the config file (ADR 0071)."""
    remap: dict[str, str] = Field(default_factory=dict)
    """Topic renames, from -> to (as ROS 2 remappings)."""

    model_config = ConfigDict(
        extra="forbid",
        frozen=True,
        strict=True,
        allow_inf_nan=False,
        populate_by_name=True,
        serialize_by_alias=True,
    )


_TOPIC_NAME = r"^(/[A-Za-z_][A-Za-z0-9_]*)+$"


class LockstepAnswer(Section):
    """One thing your ROS 2 nodes answer with in lockstep (ADR 0065): ``topic`` is
    published once every ``period`` s of sim time, after the node's /clock reaches it."""

    topic: Annotated[str, Field(pattern=_TOPIC_NAME)]
    """A topic a ROS 2 node publishes into the stack (one of ``inputs``)."""
    period: float = Field(gt=0.0, le=60.0)
    """s of sim time between two answers (the node's timer: 0.05 for 20 Hz), in (0, 60]."""


class Ros2Config(Section):
    """ROS 2 over DDS (``otonav run --ros2``, the extra ``otonav[ros2]``; ADR 0047)."""

    enabled: bool = False
    """Mirror every topic on DDS as a ROS 2 node would, and take ``inputs`` in."""
    domain_id: int | None = Field(None, ge=0, le=232)
    """DDS domain (null: ``ROS_DOMAIN_ID``, else 0)."""
    inputs: tuple[Annotated[str, Field(pattern=_TOPIC_NAME)], ...] = ("/goal",)
    """Topics ROS 2 nodes may publish into the stack (e.g. add ``/cmd_vel_nav``)."""
    lockstep: tuple[LockstepAnswer, ...] = ()
    """What your nodes answer with, for ``--lockstep`` (e.g. ``[{topic: /cmd_vel_nav,
    period: 0.05}]``): sim time holds at each due instant until the answer came."""
    lockstep_timeout: float = Field(5.0, gt=0.0, le=3600.0)
    """s of wall time a node may take to answer in lockstep before the run fails, in
    (0, 3600]."""
    twist_stamped: bool = False
    """Velocity commands (/cmd_vel, /cmd_vel_nav) are ``geometry_msgs/TwistStamped`` on
    DDS, in and out, as Jazzy's diff_drive_controller takes them by default; inside
    otonav (and in the recording) they stay ``Twist``."""
    wait: float | None = Field(None, gt=0.0, le=3600.0)
    """s of wall time, at most, that sim time holds at 0 until the ROS 2 nodes matched
    (``--ros2-wait``; null: do not wait, or 30 s in lockstep), in (0, 3600]."""


class FoxgloveConfig(Section):
    """The Foxglove live view (``otonav run --foxglove``, the extra ``otonav[foxglove]``;
    ADR 0031): every topic served over the Foxglove WebSocket protocol."""

    enabled: bool = False
    """Serve every topic (and the actors' parameters) to Foxglove clients."""
    host: Annotated[str, Field(min_length=1, max_length=253, pattern=r"^[A-Za-z0-9.:\-]+$")] = (
        "127.0.0.1"
    )
    """Interface to bind: loopback unless asked (``0.0.0.0`` serves every interface)."""
    port: int = Field(8765, ge=0, le=65535)
    """TCP port (Foxglove's convention, 8765); 0 picks a free one."""
    wait_for_subscriber: float | None = Field(None, gt=0.0, le=3600.0)
    """s of wall time, at most, that sim time holds at 0 until a client subscribes
    (``--foxglove-wait``; null: do not wait), in (0, 3600]."""


class StackConfig(Section):
    """Everything needed to bring the robot stack up."""

    world: WorldConfig = WorldConfig()
    rates: RatesConfig = RatesConfig()
    base: BaseConfig = BaseConfig()
    nav: NavConfig = NavConfig()
    guard: GuardConfig = GuardConfig()
    safety: SafetyConfig = SafetyConfig()
    hal: HalConfig = HalConfig()
    robot: RobotConfig = RobotConfig()
    ros2: Ros2Config = Ros2Config()
    foxglove: FoxgloveConfig = FoxgloveConfig()
    actors: tuple[ActorConfig, ...] = ()
    """Extra nodes, or replacements of built-in ones, in launch order."""

    @model_validator(mode="after")
    def _consistent(self) -> StackConfig:
        names = [entry.name for entry in self.actors]
        twice = sorted({name for name in names if names.count(name) > 1})
        if twice:
            raise ValueError(f"actors: each name once (given more than once: {twice})")
        if self.world.lidar_range_min >= self.world.lidar_range_max:
            raise ValueError(
                "world.lidar_range_min must be < world.lidar_range_max "
                f"(got {self.world.lidar_range_min} >= {self.world.lidar_range_max})"
            )
        if self.nav.dwa.dt > self.nav.dwa.horizon:
            raise ValueError(
                f"nav.dwa.dt must be <= nav.dwa.horizon (got {self.nav.dwa.dt} > "
                f"{self.nav.dwa.horizon})"
            )
        if self.nav.map.plan_resolution < self.nav.map.resolution:
            raise ValueError(
                "nav.map.plan_resolution must be >= nav.map.resolution "
                f"(got {self.nav.map.plan_resolution} < {self.nav.map.resolution})"
            )
        if self.safety.enabled and self.nav.clearance < self.safety.clearance:
            raise ValueError(
                f"nav.clearance ({self.nav.clearance} m) must be >= safety.clearance "
                f"({self.safety.clearance} m): a planner keeping less would drive into "
                "the safety layer"
            )
        self._consistent_can()
        tick_hz = 1.0 / self.world.timestep
        for key, hz in self.rates_hz().items():
            if hz > tick_hz * (1 + 1e-9):
                raise ValueError(
                    f"{key} = {hz:g} Hz is faster than the physics ticks: at most "
                    f"{tick_hz:g} Hz with world.timestep = {self.world.timestep:g} s "
                    "(lower the rate, or the timestep)"
                )
        return self

    def _consistent_can(self) -> None:
        """Cross-field checks of ``hal.can`` and ``hal.sim`` (here, at the top, so the
        one-line error quotes just the keys involved)."""
        can, sim = self.hal.can, self.hal.sim
        if can.left.node_id == can.right.node_id:
            raise ValueError(
                f"hal.can.left.node_id and hal.can.right.node_id must differ "
                f"(both {can.left.node_id})"
            )
        if sim.left_node_id == sim.right_node_id:
            raise ValueError(
                f"hal.sim.left_node_id and hal.sim.right_node_id must differ "
                f"(both {sim.left_node_id})"
            )
        drives = (sim.left_node_id, sim.right_node_id)
        for key, node in (
            ("axis_error", sim.faults.axis_error.node_id),
            ("heartbeat", sim.faults.heartbeat.node_id),
        ):
            if node is not None and node not in drives:
                raise ValueError(
                    f"hal.sim.faults.{key}.node_id = {node} is not an emulated drive "
                    f"(hal.sim.left_node_id {drives[0]}, hal.sim.right_node_id {drives[1]})"
                )
        timestep = self.world.timestep
        periods = {
            "hal.can.encoder_period": can.encoder_period,
            "hal.sim.encoder_period": sim.encoder_period,
            "hal.sim.heartbeat_period": sim.heartbeat_period,
        }
        for key, period in periods.items():
            if period < timestep * (1 - 1e-9):
                raise ValueError(
                    f"{key} = {period:g} s is shorter than a physics tick: at least "
                    f"world.timestep = {timestep:g} s (frames go out on ticks)"
                )
        if can.encoder_timeout <= can.encoder_period:
            raise ValueError(
                f"hal.can.encoder_timeout ({can.encoder_timeout:g} s) must be longer than "
                f"hal.can.encoder_period ({can.encoder_period:g} s): every estimate "
                "would be late"
            )
        if can.loss_window < can.encoder_period:
            raise ValueError(
                f"hal.can.loss_window ({can.loss_window:g} s) must be at least "
                f"hal.can.encoder_period ({can.encoder_period:g} s)"
            )

    def rates_hz(self) -> dict[str, float]:
        """Every periodic actor rate of the stack, by key path (Hz)."""
        rates = {f"rates.{key}": float(hz) for key, hz in self.rates.model_dump().items()}
        rates["base.rate_hz"] = self.base.rate_hz
        rates["nav.rate_hz"] = self.nav.rate_hz
        if self.safety.enabled:
            rates["safety.rate_hz"] = self.safety.rate_hz
        return rates
