"""The bridge on FakeHardware: sensor rates, stamps, /tf, odometry, wheel commands.

Everything is asserted on sim time: the fake world is the loop's time source (1 tick =
2 ms), so the instant a message arrives is the instant it was published.
"""

from __future__ import annotations

import math
from collections.abc import AsyncIterator, Awaitable, Callable, Mapping
from contextlib import asynccontextmanager
from typing import Any

import anyio
import numpy as np
import pytest

from otonav.actors import Bridge, topics
from otonav.hal import FakeHardware, WheelSetpoint
from otonav.msgs import Clock, Imu, LaserScan, Odometry, TFMessage, Time, WheelCommand
from otonav.runtime import QoS, Reliability, Subscription, System, virtual_loop_factory

pytestmark = pytest.mark.unit

#: A passive observer: best-effort (never slows a publisher down), keeps everything.
OBSERVE = QoS(Reliability.BEST_EFFORT, depth=100_000)
SENSORS: dict[str, type[Any]] = {
    topics.CLOCK: Clock,
    topics.ODOM: Odometry,
    topics.IMU: Imu,
    topics.SCAN: LaserScan,
}
Log = dict[str, list[tuple[float, Any]]]


def _run(hal: FakeHardware, main: Callable[[], Awaitable[None]]) -> None:
    """Run ``main`` on a virtual-time loop whose time source is ``hal``."""
    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(hal, wall_ceiling=10)})


async def _drain(sub: Subscription[Any], into: list[tuple[float, Any]]) -> None:
    async for message in sub:
        into.append((anyio.current_time(), message))


@asynccontextmanager
async def _observing(system: System, kinds: Mapping[str, type[Any]]) -> AsyncIterator[Log]:
    """Record (sim time of arrival, message) on each topic while the body runs."""
    log: Log = {topic: [] for topic in kinds}
    subs = {topic: system.subscribe(topic, kind, OBSERVE) for topic, kind in kinds.items()}
    async with anyio.create_task_group() as tg:
        for topic, sub in subs.items():
            tg.start_soon(_drain, sub, log[topic])
        yield log
        tg.cancel_scope.cancel()


def _bridge(hal: FakeHardware, rates: Mapping[str, float]) -> Bridge:
    """A bridge with ``rates`` (Hz) overriding the defaults."""
    hz = {"clock_hz": 100.0, "odom_hz": 100.0, "imu_hz": 100.0, "scan_hz": 10.0, **rates}
    return Bridge(
        hal,
        clock_hz=hz["clock_hz"],
        odom_hz=hz["odom_hz"],
        imu_hz=hz["imu_hz"],
        scan_hz=hz["scan_hz"],
    )


def _stamp(message: Any) -> Time:
    stamp: Time = message.clock if isinstance(message, Clock) else message.header.stamp
    return stamp


def _ns(sim_time: float) -> int:
    return round(sim_time * 1e9)


# -- rates and stamps --------------------------------------------------------------------


@pytest.mark.parametrize(
    ("rates", "expected"),
    [
        pytest.param({}, (100, 100, 100, 10), id="defaults"),
        pytest.param(
            {"clock_hz": 250.0, "odom_hz": 50.0, "imu_hz": 125.0, "scan_hz": 20.0},
            (250, 50, 125, 20),
            id="custom",
        ),
        pytest.param(
            {"odom_hz": 30.0, "imu_hz": 200.0, "scan_hz": 15.0},
            (100, 30, 200, 15),
            id="off-tick",
        ),
    ],
)
def test_publishes_each_stream_at_its_rate(
    rates: dict[str, float], expected: tuple[int, int, int, int]
) -> None:
    hal = FakeHardware()

    async def main() -> None:
        async with System([_bridge(hal, rates)]) as system, _observing(system, SENSORS) as log:
            await anyio.sleep(1.5)
        for (topic, got), want in zip(log.items(), expected, strict=True):
            times = [t for t, _ in got]
            assert times[0] > 0.0, topic
            # Exactly `hz` messages in the sim second (0, 1]: no drift, no burst.
            assert sum(t <= 1.0 + 1e-9 for t in times) == want, topic
            # ... and never two at one instant.
            assert len(set(times)) == len(times), topic

    _run(hal, main)


@pytest.mark.parametrize(
    "rates",
    [
        pytest.param({}, id="defaults"),
        pytest.param({"clock_hz": 250.0, "odom_hz": 50.0, "imu_hz": 125.0}, id="custom"),
        # Periods that are not a whole number of 2 ms ticks: the world is sampled at the
        # tick after the nominal instant, so that tick is what the stamp must say.
        pytest.param({"odom_hz": 30.0, "imu_hz": 200.0, "scan_hz": 15.0}, id="off-tick"),
    ],
)
def test_stamps_equal_the_sim_instant_of_publication(rates: dict[str, float]) -> None:
    hal = FakeHardware()

    async def main() -> None:
        async with System([_bridge(hal, rates)]) as system, _observing(system, SENSORS) as log:
            await anyio.sleep(1.0)
        for topic, got in log.items():
            assert got, topic
            wrong = [
                (t, _stamp(m).to_seconds()) for t, m in got if _stamp(m).to_nanoseconds() != _ns(t)
            ]
            assert not wrong, f"{topic}: (published at, stamped) {wrong[:3]}"

    _run(hal, main)


def test_scan_and_imu_carry_the_hardware_readings() -> None:
    hal = FakeHardware(lidar_beams=90, lidar_range_max=5.0)

    async def main() -> None:
        async with System([Bridge(hal)]) as system, _observing(system, SENSORS) as log:
            await anyio.sleep(0.25)
        _, scan = log[topics.SCAN][-1]
        assert scan.header.frame_id == "laser"
        assert len(scan.ranges) == 90
        assert scan.range_max == 5.0
        assert scan.scan_time == pytest.approx(0.1)
        _, imu = log[topics.IMU][-1]
        assert imu.header.frame_id == "imu_link"
        assert imu.linear_acceleration.z == pytest.approx(9.81)

    _run(hal, main)


def test_scan_fields_are_float32_like_the_wire_and_the_recording() -> None:
    # ROS 2's LaserScan and the recording hold float32: a subscriber in the run (the live
    # view, the navigator) must see the values a replay of the file will see. 2*pi/360
    # and 0.1 are not float32 values, so an unrounded float64 fails here.
    hal = FakeHardware(lidar_beams=360, lidar_range_max=5.0)

    async def main() -> None:
        async with System([Bridge(hal)]) as system, _observing(system, SENSORS) as log:
            await anyio.sleep(0.25)
        _, scan = log[topics.SCAN][-1]
        raw = hal.read_scan()
        assert raw.angle_increment != float(np.float32(raw.angle_increment))  # the premise
        for field in ("angle_min", "angle_max", "angle_increment", "scan_time", "range_min"):
            value = getattr(scan, field)
            assert value == float(np.float32(value)), field
        assert scan.angle_increment == float(np.float32(raw.angle_increment))
        assert scan.scan_time == float(np.float32(0.1))
        assert all(r == float(np.float32(r)) for r in scan.ranges)

    _run(hal, main)


# -- /tf_static and /tf ------------------------------------------------------------------


def test_tf_static_laser_and_imu_frames_are_latched_for_a_late_subscriber() -> None:
    hal = FakeHardware(laser_offset_x=0.12, laser_offset_z=0.2)

    async def main() -> None:
        async with System([Bridge(hal)]) as system:
            await anyio.sleep(0.5)
            late = system.subscribe(topics.TF_STATIC, TFMessage, topics.LATCHED)
            message = late.try_recv()
            assert message is not None, "a transient-local subscriber joining late got nothing"
            assert late.try_recv() is None  # published once
            laser, imu = message.transforms
            for transform in (laser, imu):
                assert transform.header.frame_id == "base_link"
                assert transform.header.stamp.to_nanoseconds() == 0  # started at 0 s
                q = transform.transform.rotation
                assert (q.x, q.y, q.z, q.w) == (0.0, 0.0, 0.0, 1.0)
            assert laser.child_frame_id == "laser"
            t = laser.transform.translation
            assert (t.x, t.y, t.z) == (0.12, 0.0, 0.2)
            assert imu.child_frame_id == "imu_link"  # /imu's frame, placed for viewers
            t = imu.transform.translation
            assert (t.x, t.y, t.z) == hal.geometry.imu_offset

    _run(hal, main)


def test_tf_odom_to_base_link_matches_odom() -> None:
    hal = FakeHardware()
    kinds = {topics.ODOM: Odometry, topics.TF: TFMessage}

    async def main() -> None:
        async with System([Bridge(hal)]) as system, _observing(system, kinds) as log:
            wheels = system.publisher(topics.WHEEL_CMD, WheelCommand, topics.COMMAND_QOS)
            await anyio.sleep(0.05)
            await wheels.publish(WheelCommand(left=3.0, right=6.0))  # an arc
            await anyio.sleep(1.005)  # end between two publications: both logs complete
        odoms, tfs = log[topics.ODOM], log[topics.TF]
        assert len(odoms) == len(tfs) == 105
        for (t_odom, odom), (t_tf, tf) in zip(odoms, tfs, strict=True):
            assert t_tf == t_odom
            (transform,) = tf.transforms
            assert transform.header == odom.header
            assert odom.header.frame_id == "odom"
            assert transform.child_frame_id == odom.child_frame_id == "base_link"
            p, q = odom.pose.pose.position, odom.pose.pose.orientation
            tr, rot = transform.transform.translation, transform.transform.rotation
            assert (tr.x, tr.y, tr.z) == (p.x, p.y, p.z)
            assert rot == q
        assert odoms[-1][1].pose.pose.position.y > 0.01  # it did move on the arc

    _run(hal, main)


# -- odometry vs the fake's true pose ----------------------------------------------------


Segments = list[tuple[float, float, float]]  # (left rad/s, right rad/s, duration s)


def _odometry_errors(hal: FakeHardware, segments: Segments, *, start: float) -> list[Any]:
    """Drive ``segments`` through /wheel_cmd from sim time ``start``; for every /odom
    return (sim time, position error m, yaw error rad, odom v, true v)."""
    errors: list[Any] = []

    async def main() -> None:
        async with System([Bridge(hal)]) as system:
            odom = system.subscribe(topics.ODOM, Odometry, OBSERVE)
            wheels = system.publisher(topics.WHEEL_CMD, WheelCommand, topics.COMMAND_QOS)

            async def compare() -> None:
                async for message in odom:
                    truth = hal.ground_truth()  # the world at the instant of publication
                    p = message.pose.pose
                    errors.append(
                        (
                            anyio.current_time(),
                            math.hypot(p.position.x - truth.x, p.position.y - truth.y),
                            abs(math.remainder(p.orientation.yaw() - truth.yaw, math.tau)),
                            message.twist.twist.linear.x,
                            math.hypot(truth.vx_world, truth.vy_world),
                        )
                    )

            async with anyio.create_task_group() as tg:
                tg.start_soon(compare)
                await anyio.sleep(start)
                for left, right, duration in segments:
                    await wheels.publish(WheelCommand(left=left, right=right))
                    await anyio.sleep(duration)
                tg.cancel_scope.cancel()

    _run(hal, main)
    return errors


def test_odometry_tracks_the_true_pose_driving_straight() -> None:
    hal = FakeHardware()
    errors = _odometry_errors(hal, [(6.0, 6.0, 2.0)], start=0.05)
    assert hal.ground_truth().x == pytest.approx(0.6, abs=1e-9)  # 0.3 m/s for 2 s
    # The fake is exact kinematics and commands change on odom instants: odometry is
    # exact up to rounding.
    assert max(e[1] for e in errors) < 1e-9
    assert max(e[2] for e in errors) < 1e-9
    assert errors[-1][3] == pytest.approx(0.3, abs=1e-9)


def test_odometry_tracks_the_true_pose_turning() -> None:
    hal = FakeHardware()
    segments = [(4.0, 6.0, 1.0), (-3.0, 3.0, 0.5), (6.0, 2.0, 0.5), (6.0, 6.0, 0.5)]
    errors = _odometry_errors(hal, segments, start=0.05)
    truth = hal.ground_truth()
    assert abs(truth.yaw) > 0.5  # it really turned
    assert truth.y > 0.1
    assert max(e[1] for e in errors) < 1e-9
    assert max(e[2] for e in errors) < 1e-9


def test_odometry_error_is_bounded_with_wheel_lag() -> None:
    # Wheels that lag their setpoint (tau = 50 ms): the gyro is sampled, not integrated,
    # so heading picks up a small error in each transient; distance stays exact.
    hal = FakeHardware(wheel_time_constant=0.05)
    segments = [(4.0, 6.0, 1.0), (-3.0, 3.0, 0.5), (6.0, 2.0, 0.5), (6.0, 6.0, 0.5)]
    errors = _odometry_errors(hal, segments, start=0.05)
    assert max(e[1] for e in errors) < 2e-3  # m
    assert max(e[2] for e in errors) < math.radians(0.5)


def test_odometry_counts_motion_from_the_bridge_start() -> None:
    # A wheel command at the first instant (or a robot already rolling when the bridge
    # starts): the odom frame starts where the robot was when the bridge started, so
    # odometry must count the motion of the first odom period too, and the first /odom
    # must report the speed the robot has.
    hal = FakeHardware()
    errors = _odometry_errors(hal, [(6.0, 6.0, 1.0)], start=0.0)
    first_t, _, _, first_v, true_v = errors[0]
    assert first_t == pytest.approx(0.01)
    assert first_v == pytest.approx(true_v, abs=1e-9), "first /odom reports v = 0 while moving"
    assert max(e[1] for e in errors) < 1e-9, "motion before the first /odom was lost"


# -- wheel commands ----------------------------------------------------------------------


def test_wheel_commands_on_wheel_cmd_reach_the_hardware() -> None:
    hal = FakeHardware()

    async def main() -> None:
        async with System([Bridge(hal)]) as system:
            wheels = system.publisher(topics.WHEEL_CMD, WheelCommand, topics.COMMAND_QOS)
            await wheels.publish(WheelCommand(left=2.0, right=-1.0))
            await anyio.sleep(0.1)
            state = hal.read_wheels()
            assert (state.left_velocity, state.right_velocity) == (2.0, -1.0)
            # Applied at the instant it was published (t = 0), held for 0.1 s.
            assert state.left_position == pytest.approx(0.2, abs=1e-12)
            assert state.right_position == pytest.approx(-0.1, abs=1e-12)
            wheels.publish_nowait(WheelCommand(left=3.0, right=3.0))
            # In the publisher's call, with no task of the bridge's in between (ADR 0084).
            assert hal._cmd == WheelSetpoint(3.0, 3.0)
            await anyio.sleep(0.1)
            state = hal.read_wheels()
            assert (state.left_velocity, state.right_velocity) == (3.0, 3.0)
            assert state.left_position == pytest.approx(0.5, abs=1e-12)
            assert state.right_position == pytest.approx(0.2, abs=1e-12)

    _run(hal, main)


def test_rates_must_be_positive() -> None:
    with pytest.raises(ValueError, match="scan_hz"):
        Bridge(FakeHardware(), scan_hz=0.0)


def test_a_full_reliable_subscriber_holds_the_streams_back_in_order() -> None:
    """The 100 Hz streams publish without a coroutine each; a reliable mailbox that is
    full (a /tf reader of depth 1 that takes one every 50 ms) makes that message and
    every later one of the instant wait: nothing lost, the publish order kept (/imu
    after /tf, although /imu's mailboxes had room)."""
    from otonav.msgs import TFMessage
    from otonav.runtime._funnel import Funnel

    hal = FakeHardware()
    wanted = {topics.CLOCK, topics.ODOM, topics.TF, topics.IMU}

    async def main() -> tuple[list[tuple[str, float, Any]], int]:
        got: list[tuple[str, float, Any]] = []
        async with System([_bridge(hal, {})]) as system:
            funnel = Funnel(system.bus, "tap", anyio.current_time, wanted=wanted.__contains__)
            slow = system.subscribe(topics.TF, TFMessage, QoS(Reliability.RELIABLE, depth=1))
            for _ in range(6):
                await anyio.sleep(0.05)
                slow.try_recv()
                got += funnel.take_all()
            waited = sum(1 for t, _, _ in got if t == topics.TF)
        return got, waited

    got, tfs = anyio.run(
        main, backend_options={"loop_factory": virtual_loop_factory(hal, wall_ceiling=10)}
    )
    assert 5 <= tfs <= 8  # the bridge was held back by the /tf reader (else ~30)
    names = [topic for topic, _, _ in got]
    for i in range(0, len(names) - len(names) % 4, 4):
        assert names[i : i + 4] == [topics.CLOCK, topics.ODOM, topics.TF, topics.IMU], i
    times = [t for _, t, _ in got]
    assert times == sorted(times)


def test_a_stream_with_no_subscriber_is_not_built_and_a_late_one_gets_the_next() -> None:
    """As a ROS 2 driver checks ``get_subscription_count``: no mailbox, no message; a
    subscriber that joins gets the stream from the next instant, and odometry integrated
    all along (the hardware is read either way)."""
    hal = FakeHardware()
    kinds = {topics.CLOCK: Clock, topics.IMU: Imu, topics.ODOM: Odometry, topics.TF: TFMessage}

    async def main() -> None:
        async with System([Bridge(hal)]) as system:
            wheels = system.publisher(topics.WHEEL_CMD, WheelCommand, topics.COMMAND_QOS)
            await wheels.publish(WheelCommand(left=5.0, right=5.0))
            await anyio.sleep(0.505)
            published = {t: system.bus.topics[t].publishers[0].published for t in kinds}
            assert published == dict.fromkeys(kinds, 0)
            async with _observing(system, kinds) as log:
                await anyio.sleep(0.1)
        for topic in kinds:
            first_at, first = log[topic][0]
            stamped = first.transforms[0] if topic == topics.TF else first
            assert first_at == pytest.approx(0.51)
            assert _stamp(stamped).to_nanoseconds() == _ns(0.51)
            assert len(log[topic]) == 10
        odom = log[topics.ODOM][-1][1]
        # The last /odom is at 0.6 s, the truth read at 0.605 s (the fake is exact).
        assert odom.pose.pose.position.x == pytest.approx(hal.ground_truth().x, abs=2e-3)
        assert odom.pose.pose.position.x > 0.1

    _run(hal, main)
