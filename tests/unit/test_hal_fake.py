"""FakeHardware: exact unicycle kinematics and an analytic lidar."""

from __future__ import annotations

import math

import numpy as np
import pytest

from otonav.hal import BoxObstacle, FakeHardware, RangeScan, WheelSetpoint
from otonav.hal._fake import cast_rays_2d

pytestmark = pytest.mark.unit

R = 0.05  # wheel radius, m
B = 0.22  # wheel separation, m


def beam(scan: RangeScan, angle: float) -> int:
    """The beam of a full-circle ``scan`` nearest ``angle`` (rad, laser frame)."""
    return round((angle - scan.angle_min) / scan.angle_increment) % scan.ranges.size


def test_straight_drive_moves_v_times_t() -> None:
    hw = FakeHardware(wheel_radius=R, wheel_separation=B)
    hw.write(WheelSetpoint(6.0, 6.0))  # 0.3 m/s
    hw.advance(1000)
    gt = hw.ground_truth()
    assert hw.ticks == 1000
    assert hw.sim_time == pytest.approx(2.0)
    assert gt.x == pytest.approx(0.6, abs=1e-12)
    assert gt.y == pytest.approx(0.0, abs=1e-12)
    assert gt.yaw == pytest.approx(0.0, abs=1e-12)
    assert gt.vx_world == pytest.approx(0.3)
    wheels = hw.read_wheels()
    assert wheels.left_position == pytest.approx(12.0)
    assert wheels.right_velocity == pytest.approx(6.0)


def test_pure_rotation_turns_in_place() -> None:
    hw = FakeHardware(wheel_radius=R, wheel_separation=B)
    hw.write(WheelSetpoint(-2.0, 2.0))
    hw.advance(500)  # 1 s
    gt = hw.ground_truth()
    expected = R * 4.0 / B  # rad/s
    assert gt.yaw == pytest.approx(expected, abs=1e-12)
    assert (gt.x, gt.y) == pytest.approx((0.0, 0.0), abs=1e-12)
    imu = hw.read_imu()
    assert imu.angular_velocity[2] == pytest.approx(expected)
    assert imu.linear_acceleration[2] == pytest.approx(9.81)
    w, _, _, z = imu.orientation
    assert 2.0 * math.atan2(z, w) == pytest.approx(expected)


def test_arc_is_exact_and_independent_of_chunking() -> None:
    one, many = FakeHardware(), FakeHardware()
    for hw in (one, many):
        hw.write(WheelSetpoint(4.0, 6.0))
    one.advance(1000)
    for _ in range(100):
        many.advance(10)
    v, w = R * 5.0, R * 2.0 / B
    radius, angle = v / w, w * 2.0
    a, b = one.ground_truth(), many.ground_truth()
    assert a.x == pytest.approx(radius * math.sin(angle), abs=1e-9)
    assert a.y == pytest.approx(radius * (1.0 - math.cos(angle)), abs=1e-9)
    assert (b.x, b.y, b.yaw) == pytest.approx((a.x, a.y, a.yaw), abs=1e-9)


def test_first_order_wheel_lag() -> None:
    hw = FakeHardware(wheel_time_constant=0.1)
    hw.write(WheelSetpoint(6.0, 6.0))
    hw.advance(50)  # 0.1 s = one time constant
    assert hw.read_wheels().left_velocity == pytest.approx(6.0 * (1.0 - math.exp(-1.0)))
    # Distance = integral of v: v_cmd * (t - tau * (1 - e^-t/tau)).
    expected = 0.3 * (0.1 - 0.1 * (1.0 - math.exp(-1.0)))
    assert hw.ground_truth().x == pytest.approx(expected, rel=1e-9)
    assert hw.read_imu().linear_acceleration[0] > 0.0


def test_scan_sees_box_at_the_analytic_range_and_beam() -> None:
    hw = FakeHardware(obstacles=[BoxObstacle(2.0, 0.0, 0.1, 0.1)])
    scan = hw.read_scan()
    assert scan.ranges.dtype == np.float32
    assert scan.ranges.size == 360
    assert scan.angle_min == pytest.approx(-math.pi)
    assert scan.angle_max == pytest.approx(math.pi - scan.angle_increment)
    ahead = beam(scan, 0.0)
    assert ahead == 180
    assert scan.angles[ahead] == pytest.approx(0.0, abs=1e-12)
    assert scan.ranges[ahead] == pytest.approx(2.0 - 0.1 - 0.06, abs=1e-6)
    # The box subtends atan(0.1 / 1.84) = 3.1 deg each side: 7 beams, the rest miss.
    finite = np.flatnonzero(np.isfinite(scan.ranges))
    assert finite.tolist() == list(range(177, 184))
    assert np.all(np.isposinf(np.delete(scan.ranges, finite)))


def test_scan_rotates_with_the_robot() -> None:
    hw = FakeHardware(start=(1.0, 1.0, math.pi / 2), obstacles=[BoxObstacle(1.0, 3.0, 0.2, 0.1)])
    scan = hw.read_scan()
    assert scan.ranges[beam(scan, 0.0)] == pytest.approx(2.0 - 0.1 - 0.06, abs=1e-6)
    assert np.isposinf(scan.ranges[beam(scan, math.pi / 2)])


def test_scan_range_limits_are_inf() -> None:
    near = FakeHardware(obstacles=[BoxObstacle(0.2, 0.0, 0.1, 0.5)])
    assert np.isneginf(near.read_scan().ranges[180])  # 0.04 m < range_min: REP 117 -inf
    far = FakeHardware(obstacles=[BoxObstacle(2.0, 0.0, 0.1, 0.1)], lidar_range_max=1.0)
    assert np.all(np.isposinf(far.read_scan().ranges))


def test_arena_walls_are_scanned_and_listed() -> None:
    hw = FakeHardware(arena_half_size=5.0, lidar_beams=4)
    scan = hw.read_scan()  # beams at -pi, -pi/2, 0, pi/2
    assert scan.ranges.tolist() == pytest.approx([5.06, 5.0, 4.94, 5.0], abs=1e-5)
    assert len(hw.walls()) == 4
    assert hw.obstacles() == ()
    assert min(w.distance_to(0.0, 0.0) for w in hw.clearance_boxes()) == pytest.approx(5.0)


def test_rotated_box_ray_cast() -> None:
    diamond = BoxObstacle(2.0, 0.0, 0.5, 0.5, yaw=math.pi / 4)
    dist = cast_rays_2d(0.0, 0.0, np.array([0.0, math.pi / 2]), [diamond])
    assert dist[0] == pytest.approx(2.0 - 0.5 * math.sqrt(2.0))
    assert np.isposinf(dist[1])
    inside = cast_rays_2d(2.0, 0.0, np.array([0.0]), [diamond])
    assert inside[0] == 0.0


def test_box_distance() -> None:
    box = BoxObstacle(1.0, 1.0, 0.5, 0.25)
    assert box.distance_to(1.2, 1.1) == 0.0
    assert box.distance_to(2.0, 1.0) == pytest.approx(0.5)
    assert box.distance_to(2.5, 2.25) == pytest.approx(math.hypot(1.0, 1.0))
    turned = BoxObstacle(0.0, 0.0, 1.0, 0.1, yaw=math.pi / 2)
    assert turned.distance_to(0.0, 1.5) == pytest.approx(0.5)
    assert turned.distance_to(1.0, 0.0) == pytest.approx(0.9)
    with pytest.raises(ValueError, match="positive"):
        BoxObstacle(0.0, 0.0, 0.0, 1.0)


def test_deterministic_and_guarded() -> None:
    def run() -> tuple[float, ...]:
        hw = FakeHardware(wheel_time_constant=0.05, obstacles=[BoxObstacle(1.0, 0.5, 0.2, 0.2)])
        hw.write(WheelSetpoint(3.0, 5.0))
        hw.advance(321)
        return (*hw.read_scan().ranges.tolist(), hw.ground_truth().x, hw.ground_truth().yaw)

    assert run() == run()
    with FakeHardware() as hw:
        with pytest.raises(ValueError, match="negative"):
            hw.advance(-1)
        with pytest.raises(ValueError, match="finite"):
            hw.write(WheelSetpoint(math.nan, 0.0))
    with pytest.raises(RuntimeError, match="closed"):
        hw.advance(1)
