"""The bridge: owns the hardware (simulated or real), publishes its sensors at their
rates, applies wheel commands. The only actor that touches the HAL."""

from __future__ import annotations

import contextlib
import logging
import math
from collections import deque
from collections.abc import Awaitable, Callable
from typing import Any

import anyio
import numpy as np

from otonav.actors import _topics as topics
from otonav.actors._odometry_error import OdometryError
from otonav.actors._topics import FRAMES, Frames
from otonav.control import OdometryEstimate, Pose2D, estimate_odometry
from otonav.hal import HardwareHealth, HealthLevel, ImuSample, RobotHardwareInterface, WheelSetpoint
from otonav.msgs import (
    Clock,
    DiagnosticArray,
    DiagnosticStatus,
    HardwareStatus,
    Header,
    Imu,
    JointState,
    KeyValue,
    LaserScan,
    Log,
    Odometry,
    Point,
    Pose,
    PoseWithCovariance,
    Quaternion,
    TFMessage,
    Time,
    Transform,
    TransformStamped,
    Twist,
    TwistWithCovariance,
    Vector3,
    WheelCommand,
)
from otonav.msgs._flat import FlatLayout, reader
from otonav.msgs._std import split_seconds
from otonav.params import RatesConfig
from otonav.runtime import Actor, Input, Output, Publisher

_RATES = RatesConfig()

log = logging.getLogger("otonav.hal")

_read_wheel_command = reader(WheelCommand, "left", "right")
"""left, right of a /wheel_cmd without building a flat one's header."""

_Now = Callable[[int, int, float], None]
_Waiting = Callable[[int, int, float], Awaitable[None]]

_LOG_LEVELS = {
    HealthLevel.OK: (Log.INFO, logging.INFO),
    HealthLevel.WARN: (Log.WARN, logging.WARNING),
    HealthLevel.ERROR: (Log.ERROR, logging.ERROR),
    HealthLevel.STALE: (Log.ERROR, logging.ERROR),
}


def _ignore(_message: object) -> None:
    pass


def _diag6(*variances: float) -> tuple[float, ...]:
    """A row-major 6x6 covariance with ``variances`` on the diagonal."""
    return tuple(variances[i // 6] if i % 7 == 0 else 0.0 for i in range(36))


def _f32(*values: float) -> list[float]:
    """``values`` rounded to float32 (as Python floats)."""
    rounded: list[float] = np.array(values, dtype=np.float32).tolist()
    return rounded


# (x, y, z, roll, pitch, yaw): planar robot; z, roll and pitch are not estimated.
_POSE_COV = _diag6(1e-3, 1e-3, 1e6, 1e6, 1e6, 1e-3)
_TWIST_COV = _diag6(1e-3, 1e6, 1e6, 1e6, 1e6, 1e-3)


def _header(frame_id: str) -> Header:
    return Header.fast(stamp=Time.fast(sec=0, nanosec=0), frame_id=frame_id)


def _vector(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Vector3:
    return Vector3.fast(x=x, y=y, z=z)


_IDENTITY = Quaternion.fast(x=0.0, y=0.0, z=0.0, w=1.0)
_STAMP = ("header.stamp.sec", "header.stamp.nanosec")

# The four 100 Hz streams as fixed layouts (otonav.msgs._flat, ADR 0033): what varies
# per message, in the order the bridge gives it; everything else is the template's.
# The values are the ones the eager construction used (the quaternion of a yaw is
# (0, 0, sin(yaw/2), cos(yaw/2)), as Quaternion.from_yaw builds it).
CLOCK = FlatLayout(Clock.fast(clock=Time.fast(sec=0, nanosec=0)), ("clock.sec", "clock.nanosec"))
"""/clock: sec, nanosec."""


def sensor_layouts(
    frames: Frames,
) -> tuple[FlatLayout[Odometry], FlatLayout[TFMessage], FlatLayout[Imu]]:
    """The fixed layouts of /odom, /tf and /imu with ``frames``' names (what varies per
    message, in the order the bridge gives it; everything else is the template's)."""
    odom = FlatLayout(
        Odometry.fast(
            header=_header("odom"),
            child_frame_id=frames.base,
            pose=PoseWithCovariance.fast(
                pose=Pose.fast(position=Point.fast(x=0.0, y=0.0, z=0.0), orientation=_IDENTITY),
                covariance=_POSE_COV,
            ),
            twist=TwistWithCovariance.fast(
                twist=Twist.fast(linear=_vector(), angular=_vector()), covariance=_TWIST_COV
            ),
        ),
        (
            *_STAMP,
            "pose.pose.position.x",
            "pose.pose.position.y",
            "pose.pose.orientation.z",
            "pose.pose.orientation.w",
            "twist.twist.linear.x",
            "twist.twist.angular.z",
        ),
    )
    # /odom: sec, nanosec, x, y, qz, qw, v, omega.
    tf = FlatLayout(
        TFMessage.fast(
            transforms=(
                TransformStamped.fast(
                    header=_header("odom"),
                    child_frame_id=frames.base,
                    transform=Transform.fast(translation=_vector(), rotation=_IDENTITY),
                ),
            )
        ),
        (
            "transforms.0.header.stamp.sec",
            "transforms.0.header.stamp.nanosec",
            "transforms.0.transform.translation.x",
            "transforms.0.transform.translation.y",
            "transforms.0.transform.rotation.z",
            "transforms.0.transform.rotation.w",
        ),
    )
    # /tf odom -> base_link: sec, nanosec, x, y, qz, qw.
    imu = FlatLayout(
        Imu.fast(
            header=_header(frames.imu),
            orientation=_IDENTITY,
            orientation_covariance=(0.0,) * 9,
            angular_velocity=_vector(),
            angular_velocity_covariance=(0.0,) * 9,
            linear_acceleration=_vector(),
            linear_acceleration_covariance=(0.0,) * 9,
        ),
        (
            *_STAMP,
            "orientation.x",
            "orientation.y",
            "orientation.z",
            "orientation.w",
            *(f"{v}.{a}" for v in ("angular_velocity", "linear_acceleration") for a in "xyz"),
        ),
    )
    # /imu: sec, nanosec, orientation x y z w, angular velocity x y z, acceleration x y z.
    return odom, tf, imu


ODOM, TF, IMU = sensor_layouts(FRAMES)
"""otonav's own robot's: /odom (sec, nanosec, x, y, qz, qw, v, omega), /tf odom ->
base_link (sec, nanosec, x, y, qz, qw), /imu (sec, nanosec, orientation x y z w, angular
velocity x y z, acceleration x y z)."""


class Bridge(Actor):
    """Publishes /clock, /odom (+ /tf odom->base_link), /imu and /scan at their rates;
    /tf_static base_link->laser once; writes /wheel_cmd to the hardware.

    Odometry: wheel encoders for distance, the gyro for heading (it does not scrub
    in turns; measured when the model was tuned: ~2 cm and 0.2 deg over a circle against
    7 cm and 8 deg from the wheels alone).

    Hardware health (:meth:`RobotHardwareInterface.health`, whatever the HAL): checked at
    every publishing instant; a change is published on /hardware/status (latched, for
    the base and the navigator) and /diagnostics, and logged on /rosout. /diagnostics
    also repeats at ``diagnostics_hz``.

    A stream no one subscribes to at its instant is not built (/clock, /odom, /tf, /imu,
    /joint_states; as a ROS 2 driver checks ``get_subscription_count``); the hardware is
    read the same either way, so a recorder changes nothing the robot does.
    """

    clock_out = Output(topics.CLOCK, Clock, topics.CLOCK_QOS)
    odom = Output(topics.ODOM, Odometry, topics.ODOM_QOS)
    imu = Output(topics.IMU, Imu, topics.SENSOR_QOS)
    scan = Output(topics.SCAN, LaserScan, topics.SENSOR_QOS)
    joint_states = Output(topics.JOINT_STATES, JointState, topics.SENSOR_QOS)
    tf = Output(topics.TF, TFMessage, topics.TF_QOS)
    tf_static = Output(topics.TF_STATIC, TFMessage, topics.LATCHED)
    wheel_cmd = Input(topics.WHEEL_CMD, WheelCommand, topics.COMMAND_QOS)
    hardware_status = Output(topics.HARDWARE_STATUS, HardwareStatus, topics.HARDWARE_QOS)
    diagnostics = Output(topics.DIAGNOSTICS, DiagnosticArray, topics.DIAGNOSTICS_QOS)
    rosout = Output(topics.ROSOUT, Log, topics.ROSOUT_QOS)

    def __init__(
        self,
        hal: RobotHardwareInterface,
        *,
        clock_hz: float = _RATES.clock_hz,
        odom_hz: float = _RATES.odom_hz,
        imu_hz: float = _RATES.imu_hz,
        scan_hz: float = _RATES.scan_hz,
        diagnostics_hz: float = 1.0,
        joint_states_hz: float = 10.0,
        initial_pose: tuple[float, float, float] = (0.0, 0.0, 0.0),
        odometry_error: OdometryError | None = None,
        frames: Frames = FRAMES,
        name: str = "bridge",
    ) -> None:
        super().__init__(name)
        self.frames = frames
        layouts = (ODOM, TF, IMU) if frames == FRAMES else sensor_layouts(frames)
        self._odom_layout, self._tf_layout, self._imu_layout = layouts
        for field, hz in (
            ("clock_hz", clock_hz),
            ("odom_hz", odom_hz),
            ("imu_hz", imu_hz),
            ("scan_hz", scan_hz),
            ("diagnostics_hz", diagnostics_hz),
            ("joint_states_hz", joint_states_hz),
        ):
            if not hz > 0:
                raise ValueError(f"bridge.{field} must be > 0 Hz, got {hz}")
        self.hal = hal
        self._periods = {
            "clock": 1.0 / clock_hz,
            "odom": 1.0 / odom_hz,
            "imu": 1.0 / imu_hz,
            "scan": 1.0 / scan_hz,
            "diagnostics": 1.0 / diagnostics_hz,
            "joint_states": 1.0 / joint_states_hz,
        }
        self._health: HardwareHealth | None = None
        self._odometry = OdometryEstimate(Pose2D(*initial_pose), 0.0, 0.0, 0.0, 0.0)
        self._imu_sample: ImuSample | None = None
        self._imu_time = -1.0
        self._pending: deque[tuple[Publisher[Any], Any]] = deque()
        self._odometry_error = odometry_error

    async def on_start(self) -> None:
        """/tf_static: base_link -> laser and base_link -> imu_link (latched), so a
        viewer can place the scan and the IMU."""
        geometry = self.hal.geometry
        frames = self.frames
        header = Header.fast(stamp=Time.from_seconds(self.clock.now()), frame_id=frames.base)

        def fixed(child: str, x: float, y: float, z: float) -> TransformStamped:
            return TransformStamped.fast(
                header=header,
                child_frame_id=child,
                transform=Transform.fast(
                    translation=Vector3.fast(x=x, y=y, z=z), rotation=Quaternion()
                ),
            )

        self.wheel_cmd.deliver_to(self._apply_command)
        await self._check_health(self.clock.now())
        await self.tf_static.publish(
            TFMessage.fast(
                transforms=(
                    fixed(frames.laser, geometry.laser_offset_x, 0.0, geometry.laser_offset_z),
                    fixed(frames.imu, *geometry.imu_offset),
                )
            )
        )

    async def run(self) -> None:
        await self._publish_loop()

    async def on_stop(self) -> None:
        """Zero the wheels as the bridge stops (after every actor that commands them):
        on any crash or stop, the hardware must not keep the last setpoint (issue 27
        item 8). The base's own zero on /wheel_cmd is what the recording shows."""
        self.hal.write(WheelSetpoint(0.0, 0.0))
        self.wheel_cmd.deliver_to(_ignore)  # stopped: the hardware is no longer ours

    def _apply_command(self, cmd: WheelCommand) -> None:
        """A /wheel_cmd goes to the hardware in its publisher's call (ADR 0084): at the
        instant it is published, before the world steps on, with no wake-up of its own."""
        self.hal.write(WheelSetpoint(*_read_wheel_command(cmd)))

    async def _publish_loop(self) -> None:
        """One timer for all streams: wake at the earliest due instant, publish every
        stream due then, in a fixed order (clock, odom, imu, scan): deterministic, and
        one wake per instant instead of one per stream."""
        start = self.clock.now()
        # (period, publish now, or publish waiting): the 100 Hz streams publish without a
        # coroutine each (_send), the scan and diagnostics as coroutines.
        publishers: tuple[tuple[float, _Now | None, _Waiting | None], ...] = (
            (self._periods["clock"], self._publish_clock, None),
            (self._periods["odom"], self._publish_odom, None),
            (self._periods["imu"], self._publish_imu, None),
            (self._periods["scan"], None, self._publish_scan),
            (self._periods["diagnostics"], None, self._publish_diagnostics),
            (self._periods["joint_states"], self._publish_joints, None),
        )
        counts = [1] * len(publishers)
        due = [start + period for period, _, _ in publishers]
        wheels = self.hal.read_wheels()  # odometry counts motion from the start
        self._odometry = self._odometry._replace(
            left=wheels.left_position, right=wheels.right_position, time=start
        )
        clock, hal, pending = self.clock, self.hal, self._pending
        streams = tuple(enumerate(publishers))
        while True:
            instant = min(due)
            await clock.sleep_until(instant)
            # A period that is not a whole number of ticks wakes at the next tick: stamp
            # (and integrate) with the instant the data is actually read at.
            now = clock.now()
            if hal.health() is not self._health:
                await self._check_health(now)
            sec, nanosec = split_seconds(now)  # Time.from_seconds(now)'s, no Time object
            last = instant + 1e-12
            for i, (period, publish, publish_waiting) in streams:
                if due[i] <= last:
                    counts[i] += 1
                    due[i] = start + counts[i] * period  # no drift: k periods from start
                    if publish is not None:
                        publish(sec, nanosec, now)
                    elif publish_waiting is not None:
                        if pending:
                            await self._publish_pending()  # in order
                        await publish_waiting(sec, nanosec, now)
            if pending:  # a coroutine only when a message waits (almost never)
                await self._publish_pending()

    async def _publish_pending(self) -> None:
        """What found a full reliable mailbox (:meth:`_send`), in order, waiting."""
        pending = self._pending
        while pending:
            publisher, message = pending.popleft()
            await publisher.publish(message)

    def _send(self, publisher: Publisher[Any], message: Any) -> None:
        """Publish without a coroutine (:meth:`Publisher.publish_nowait`); once a mailbox
        is full, this and every later message of the instant wait in order (in the loop)."""
        if not self._pending:
            try:
                publisher.publish_nowait(message)
            except anyio.WouldBlock:
                pass
            else:
                return
        self._pending.append((publisher, message))

    def _publish_clock(self, sec: int, nanosec: int, _now: float) -> None:
        if self.clock_out.get_subscription_count():
            self._send(self.clock_out, CLOCK(sec, nanosec))

    def _publish_odom(self, sec: int, nanosec: int, now: float) -> None:
        hal = self.hal
        wheels = hal.read_wheels()
        gyro_z = self._imu_at(now).angular_velocity[2]
        error = self._odometry_error
        odometry = self._odometry = estimate_odometry(
            self._odometry,
            wheels.left_position,
            wheels.right_position,
            gyro_z,
            now,
            hal.geometry.wheel_radius,
            error=None if error is None else error.apply,
        )
        pose, v = odometry.pose, odometry.v
        if error is not None:  # /odom's twist is what the mis-calibrated odometry believes
            gyro_z = odometry.yaw_rate
        qz, qw = math.sin(pose.yaw / 2), math.cos(pose.yaw / 2)  # Quaternion.from_yaw's
        if self.odom.get_subscription_count():
            odom = self._odom_layout(sec, nanosec, pose.x, pose.y, qz, qw, v, gyro_z)
            self._send(self.odom, odom)
        if self.tf.get_subscription_count():
            self._send(self.tf, self._tf_layout(sec, nanosec, pose.x, pose.y, qz, qw))

    def _publish_joints(self, sec: int, nanosec: int, _now: float) -> None:
        """/joint_states: the wheel joints by the model's names, each in its own sign
        (the HAL reads positive-forward), after every other stream of the instant."""
        left, right, left_v, right_v = self.hal.wheel_values()
        if not self.joint_states.get_subscription_count():
            return
        sl, sr = self.hal.geometry.wheel_signs
        self._send(
            self.joint_states,
            JointState.fast(
                header=Header.fast(stamp=Time.fast(sec=sec, nanosec=nanosec), frame_id=""),
                name=self.hal.geometry.wheel_joints,
                position=(sl * left, sr * right),
                velocity=(sl * left_v, sr * right_v),
                effort=(),
            ),
        )

    def _imu_at(self, now: float) -> ImuSample:
        """One IMU read per instant, shared by odometry and /imu (it was read twice)."""
        if self._imu_time != now or self._imu_sample is None:
            self._imu_sample = self.hal.read_imu()
            self._imu_time = now
        return self._imu_sample

    def _publish_imu(self, sec: int, nanosec: int, now: float) -> None:
        sample = self._imu_at(now)
        if not self.imu.get_subscription_count():
            return
        w, x, y, z = sample.orientation
        self._send(
            self.imu,
            self._imu_layout(
                sec, nanosec, x, y, z, w, *sample.angular_velocity, *sample.linear_acceleration
            ),
        )

    async def _publish_scan(self, sec: int, nanosec: int, _now: float) -> None:
        stamp = Time.fast(sec=sec, nanosec=nanosec)
        scan = self.hal.read_scan()
        # float32 like the ROS 2 message and the recording, so every subscriber (the
        # live view, a replay from the file) sees the values the file holds; the ranges
        # are float32 already (their float64 copies are exact).
        a_min, a_max, a_inc, period, r_min, r_max = _f32(
            scan.angle_min,
            scan.angle_max,
            scan.angle_increment,
            self._periods["scan"],
            scan.range_min,
            scan.range_max,
        )
        await self.scan.publish(
            LaserScan.fast(
                header=Header.fast(stamp=stamp, frame_id=self.frames.laser),
                angle_min=a_min,
                angle_max=a_max,
                angle_increment=a_inc,
                time_increment=0.0,
                scan_time=period,
                range_min=r_min,
                range_max=r_max,
                ranges=tuple(scan.ranges.tolist()),
                intensities=(),
            )
        )

    # -- hardware health -----------------------------------------------------------------

    async def _check_health(self, now: float) -> None:
        """Publish and log the HAL's health if it changed (the first one always, but
        logged only when it is not a plain OK)."""
        health = self.hal.health()
        first = self._health is None
        if health is self._health:
            return
        self._health = health
        stamp = Time.from_seconds(now)
        await self.hardware_status.publish(
            HardwareStatus.fast(
                header=Header.fast(stamp=stamp, frame_id=""),
                level=int(health.level),
                ready=health.ready,
                fault=health.fault,
                message=health.message,
            )
        )
        await self._publish_diagnostics(stamp.sec, stamp.nanosec, now)
        if first and health.level == HealthLevel.OK and health.ready:
            return
        # Starting and recovered are news, not warnings; recovering is a warning.
        level = health.level if health.faulted or health.fault else HealthLevel.OK
        ros_level, py_level = _LOG_LEVELS[level]
        log.log(py_level, "[%.3f] hardware: %s", now, health.message)
        with contextlib.suppress(anyio.WouldBlock):
            self.rosout.publish_nowait(
                Log.fast(
                    stamp=stamp,
                    level=ros_level,
                    name=self.name,
                    msg=f"hardware {health.fault or 'status'}: {health.message}",
                    file="",
                    function="",
                    line=0,
                )
            )

    async def _publish_diagnostics(self, sec: int, nanosec: int, _now: float) -> None:
        stamp = Time.fast(sec=sec, nanosec=nanosec)
        health = self._health if self._health is not None else self.hal.health()
        values = (
            ("ready", "true" if health.ready else "false"),
            ("fault", health.fault),
            ("since", f"{health.since:.3f}"),
            *health.values,
        )
        await self.diagnostics.publish(
            DiagnosticArray.fast(
                header=Header.fast(stamp=stamp, frame_id=""),
                status=(
                    DiagnosticStatus.fast(
                        level=int(min(health.level, HealthLevel.STALE)),
                        name=f"{self.name}: hardware",
                        message=health.message,
                        hardware_id=type(self.hal).__name__,
                        values=tuple(KeyValue.fast(key=k, value=v) for k, v in values),
                    ),
                ),
            )
        )
