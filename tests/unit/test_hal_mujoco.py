"""MujocoInterface: scenes compile, time is ticks, the robot drives flat, the lidar is honest."""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

from otonav.hal import BoxObstacle, RangeScan, RobotHardwareInterface, WheelSetpoint
from otonav.hal._description import RobotDescription
from otonav.hal.mujoco import MujocoInterface, SceneError, compile_scene, scene_names

pytestmark = pytest.mark.unit

ASSETS = Path(str(resources.files("otonav.hal").joinpath("assets")))
START = (0.0, 0.0)
GOAL = (4.0, 1.5)
SPEED = 6.0  # rad/s = 0.3 m/s on 0.05 m wheels
SCAN_EVERY = 50  # ticks: 10 Hz at dt 0.002


def beam(scan: RangeScan, angle: float) -> int:
    """The beam of a full-circle ``scan`` nearest ``angle`` (rad, laser frame)."""
    return round((angle - scan.angle_min) / scan.angle_increment) % scan.ranges.size


def drive_and_brake(
    hw: MujocoInterface, *, drive_s: float = 1.0, brake_s: float = 1.0
) -> tuple[list[float], list[int], list[float]]:
    """Step-start at SPEED, then step-stop; scan at 10 Hz.

    Returns the |pitch| (rad) at every scan, the floor hits of every scan, and the
    nearest floor hit (m) of every scan in the forward sector |angle| < 0.26 rad.
    """
    pitches: list[float] = []
    floor_hits: list[int] = []
    forward_floor: list[float] = []
    for seconds, speed in ((drive_s, SPEED), (brake_s, 0.0)):
        hw.write(WheelSetpoint(speed, speed))
        for _ in range(round(seconds / (SCAN_EVERY * hw.tick))):
            hw.advance(SCAN_EVERY)
            scan = hw.read_scan()
            pitches.append(abs(hw.ground_truth().pitch))
            floor_hits.append(int(hw.scan_floor_mask().sum()))
            on_floor = hw.scan_floor_mask() & (np.abs(scan.angles) < 0.26)
            forward_floor.append(float(scan.ranges[on_floor].min(initial=np.inf)))
    return pitches, floor_hits, forward_floor


@pytest.mark.parametrize("path", sorted(ASSETS.glob("*.xml")), ids=lambda p: p.name)
def test_every_asset_compiles(path: Path) -> None:
    compile_scene(path)


def test_builtin_scene_names() -> None:
    assert {"empty", "obstacles"} <= set(scene_names())
    for name in scene_names():
        compile_scene(name)


def test_bad_mjcf_error_names_the_file(tmp_path: Path) -> None:
    unparsable = tmp_path / "unparsable.xml"
    unparsable.write_text("<mujoco><worldbody><geom type='bogus'/></worldbody></mujoco>")
    with pytest.raises(SceneError, match=r"unparsable\.xml does not parse"):
        compile_scene(unparsable)
    uncompilable = tmp_path / "uncompilable.xml"
    uncompilable.write_text("<mujoco><worldbody><geom type='box'/></worldbody></mujoco>")
    with pytest.raises(SceneError, match=r"uncompilable\.xml does not compile"):
        compile_scene(uncompilable)
    with pytest.raises(SceneError, match="neither a built-in scene"):
        compile_scene(tmp_path / "missing.xml")


def test_a_scene_without_a_robot_gets_the_configured_one(tmp_path: Path) -> None:
    bare = tmp_path / "bare.xml"
    bare.write_text(
        "<mujoco><worldbody><geom name='floor' type='plane' size='1 1 .1'/></worldbody></mujoco>"
    )
    compile_scene(bare)
    world = MujocoInterface(bare)
    # the robot's own physics options fill what the scene leaves at MuJoCo's defaults
    assert world.tick == 0.002
    assert world.geometry.wheel_radius == 0.05
    assert abs(world.ground_truth().pitch) < 0.02  # rests on wheels and caster


def test_advance_counts_ticks() -> None:
    hw = MujocoInterface("empty", timestep=0.005)
    assert hw.tick == 0.005
    assert hw.ticks == 0
    hw.advance(7)
    hw.advance(0)
    hw.advance(13)
    assert hw.ticks == 20
    assert hw.sim_time == 20 * 0.005
    with pytest.raises(ValueError, match="negative"):
        hw.advance(-1)
    hw.close()
    with pytest.raises(RuntimeError, match="closed"):
        hw.advance(1)


def test_geometry_matches_the_robot_model() -> None:
    geo = MujocoInterface("empty").geometry
    assert geo.wheel_radius == pytest.approx(0.05)
    assert geo.wheel_separation == pytest.approx(0.22)
    assert geo.laser_offset_x == pytest.approx(0.06)
    assert geo.laser_offset_z == pytest.approx(0.09)
    assert geo.base_height == pytest.approx(0.05)


def test_at_rest_imu_reads_gravity_and_lidar_never_sees_the_robot() -> None:
    hw = MujocoInterface("empty")
    imu = hw.read_imu()
    assert imu.linear_acceleration == pytest.approx((0.0, 0.0, 9.81), abs=0.01)
    assert imu.angular_velocity == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
    assert imu.orientation == pytest.approx((1.0, 0.0, 0.0, 0.0), abs=1e-3)
    scan = hw.read_scan()
    # Inner wall faces at +-5 m; the laser sits 0.06 m ahead of the origin.
    assert np.all(np.isfinite(scan.ranges))
    assert float(scan.ranges.min()) > 4.9
    assert {hw.geom_name(int(g)) for g in hw.scan_hit_geoms()} <= {
        "wall_east",
        "wall_west",
        "wall_north",
        "wall_south",
    }


def test_straight_drive_moves_v_times_t_and_stays_flat() -> None:
    hw = MujocoInterface("empty")
    hw.write(WheelSetpoint(SPEED, SPEED))
    max_pitch = 0.0
    for _ in range(100):  # 2 s
        hw.advance(10)
        max_pitch = max(max_pitch, abs(hw.ground_truth().pitch))
    gt = hw.ground_truth()
    assert hw.sim_time == pytest.approx(2.0)
    assert gt.x == pytest.approx(0.6, abs=0.02)
    assert abs(gt.y) < 0.005
    assert abs(gt.yaw) < math.radians(0.5)
    assert gt.vx_world == pytest.approx(0.3, abs=0.01)
    wheels = hw.read_wheels()
    assert wheels.left_velocity == pytest.approx(SPEED, abs=0.05)
    assert wheels.left_position * hw.geometry.wheel_radius == pytest.approx(gt.x, abs=0.01)
    assert math.degrees(max_pitch) < 2.0


def test_planar_truth_is_ground_truth_without_the_attitude() -> None:
    """The judge's cheap per-tick read gives exactly ground_truth's x, y, vx, vy (and
    the interface's default, which reads ground_truth, agrees) while the robot arcs."""
    hw = MujocoInterface("empty")
    hw.write(WheelSetpoint(SPEED, 0.5 * SPEED))
    for _ in range(60):
        hw.advance(10)
        gt = hw.ground_truth()
        expected = (gt.x, gt.y, gt.vx_world, gt.vy_world)
        assert hw.planar_truth() == expected
        assert RobotHardwareInterface.planar_truth(hw) == expected
    assert abs(gt.y) > 0.01  # every component was exercised
    assert abs(gt.vy_world) > 0.01


def test_wheel_values_are_read_wheels_as_a_tuple() -> None:
    """The drive emulator's per-instant read gives exactly read_wheels' four values, in
    its field order (and the interface's default, which reads read_wheels, agrees),
    with the wheels turning at different speeds."""
    hw = MujocoInterface("empty")
    hw.write(WheelSetpoint(SPEED, -0.5 * SPEED))
    for _ in range(30):
        hw.advance(10)
        w = hw.read_wheels()
        expected = (w.left_position, w.right_position, w.left_velocity, w.right_velocity)
        assert hw.wheel_values() == expected
        assert RobotHardwareInterface.wheel_values(hw) == expected
        assert all(type(v) is float for v in hw.wheel_values())
    assert w.left_velocity > 0.1 > -0.1 > w.right_velocity  # all four differ


def test_shipped_model_stays_flat_and_never_scans_the_floor() -> None:
    hw = MujocoInterface("obstacles")
    pitches, floor_hits, _ = drive_and_brake(hw)
    assert math.degrees(max(pitches)) < 2.0
    assert sum(floor_hits) == 0
    assert abs(hw.ground_truth().vx_world) < 0.01  # it did stop


def test_bug_variant_scans_the_floor(sabotaged_robot: RobotDescription) -> None:
    """The seeds' bug: no caster, no torque limit, kv 10.

    Without the caster the centre of mass (ahead of the axle) puts the nose on the
    floor already at rest (about 8 deg, floor read at about 0.9 m ahead); the abrupt
    stop pitches it much further and the floor comes within half a metre.
    """
    hw = MujocoInterface("obstacles", robot=sabotaged_robot)
    hw.read_scan()
    assert int(hw.scan_floor_mask().sum()) > 0
    pitches, floor_hits, forward_floor = drive_and_brake(hw)
    assert math.degrees(max(pitches)) > 10.0
    assert sum(floor_hits) > 0
    assert min(forward_floor) < 0.5


def test_lidar_sees_an_extra_obstacle_at_the_expected_range() -> None:
    box = BoxObstacle(1.5, 0.0, 0.1, 0.1)
    hw = MujocoInterface("empty", extra_obstacles=[box])
    assert box in hw.obstacles()
    scan = hw.read_scan()
    ahead = beam(scan, 0.0)
    assert scan.ranges[ahead] == pytest.approx(1.5 - 0.1 - 0.06, abs=0.005)
    assert hw.geom_name(int(hw.scan_hit_geoms()[ahead])) == "obstacle_extra_0"
    behind = beam(scan, math.pi)
    assert scan.ranges[behind] == pytest.approx(5.0 + 0.06, abs=0.005)


def test_lidar_range_limits_give_inf() -> None:
    hw = MujocoInterface("empty", lidar_beams=90, lidar_range_max=3.0)
    scan = hw.read_scan()
    assert scan.ranges.size == 90
    assert np.all(np.isposinf(scan.ranges))  # walls are 5 m away
    # Anything closer than range_min (0.12 m) would be inside the robot, so raise it.
    near = MujocoInterface(
        "empty", lidar_range_min=0.5, extra_obstacles=[BoxObstacle(0.5, 0.0, 0.1, 0.3)]
    )
    scan = near.read_scan()
    # REP 117: too close to measure is -inf (it was +inf, which reads as "free").
    assert np.isneginf(scan.ranges[beam(scan, 0.0)])  # 0.34 m < range_min 0.5
    assert scan.ranges[beam(scan, math.pi)] == pytest.approx(5.06, abs=0.005)


def test_a_beam_that_meets_nothing_reads_plus_inf(tmp_path: Path) -> None:
    """REP 117 through MuJoCo's -1 for a miss: +inf (free), never -inf (too close)."""
    scene = tmp_path / "open.xml"
    scene.write_text(
        '<mujoco><worldbody><geom name="floor" type="plane" size="20 20 0.1"/></worldbody></mujoco>'
    )
    hw = MujocoInterface(scene, lidar_beams=36)
    scan = hw.read_scan()
    assert (hw.scan_hit_geoms() == -1).all()
    assert np.isposinf(scan.ranges).all()


def _mirrored(ranges: np.ndarray) -> np.ndarray:
    """The scan a lidar with the wrong handedness would give: the beam at angle a reads
    what is at -a (beam i at -pi + i*2pi/n swaps with beam n - i)."""
    n = ranges.size
    return ranges[(n - np.arange(n)) % n]


def _left_box_is_on_the_left(ranges: np.ndarray, left: int, right: int, expected: float) -> bool:
    return bool(abs(ranges[left] - expected) < 0.01 and np.isposinf(ranges[right]))


@pytest.mark.parametrize("yaw", [0.0, 1.0])
def test_lidar_handedness_a_box_at_plus_y_is_hit_by_the_plus_half_pi_beam(yaw: float) -> None:
    """REP 103: x forward, y left, angles CCW. A box on the robot's left (+y in its
    frame) must be seen by the +pi/2 beam, not the -pi/2 one; a mirrored scan fails."""
    # 1.5 m to the robot's left, whatever its heading; the laser is 0.06 m ahead of
    # base_link, so the +pi/2 beam starts 0.06 m forward and runs parallel to the box.
    left_x, left_y = -math.sin(yaw) * 1.5, math.cos(yaw) * 1.5
    box = BoxObstacle(left_x, left_y, 0.2, 0.2, yaw)
    hw = MujocoInterface("empty", extra_obstacles=[box], lidar_range_max=3.0, start=(0, 0, yaw))
    scan = hw.read_scan()
    left, right = beam(scan, math.pi / 2), beam(scan, -math.pi / 2)
    assert scan.angles[left] == pytest.approx(math.pi / 2)
    assert hw.geom_name(int(hw.scan_hit_geoms()[left])) == "obstacle_extra_0"
    expected = 1.5 - 0.2  # the box's near face, along the beam
    assert _left_box_is_on_the_left(scan.ranges, left, right, expected)
    # The check has teeth: the same scan mirrored is caught.
    assert not _left_box_is_on_the_left(_mirrored(scan.ranges), left, right, expected)


def test_reading_sensors_does_not_perturb_physics() -> None:
    quiet, chatty = MujocoInterface("obstacles"), MujocoInterface("obstacles")
    for hw in (quiet, chatty):
        hw.write(WheelSetpoint(4.0, 6.0))
    for _ in range(40):
        quiet.advance(10)
        chatty.advance(10)
        chatty.read_scan()
        chatty.read_imu()
    assert quiet.ground_truth() == chatty.ground_truth()
    assert quiet.read_wheels() == chatty.read_wheels()


def test_obstacle_scene_layout() -> None:
    hw = MujocoInterface("obstacles")
    obstacles, walls = hw.obstacles(), hw.walls()
    assert len(obstacles) >= 3
    assert len(walls) == 4
    gt = hw.ground_truth()
    assert (gt.x, gt.y) == pytest.approx(START, abs=1e-3)
    assert gt.yaw == pytest.approx(0.0, abs=1e-3)
    samples = np.linspace(0.0, 1.0, 401)
    path = [
        (START[0] + t * (GOAL[0] - START[0]), START[1] + t * (GOAL[1] - START[1])) for t in samples
    ]
    clearance = [min(box.distance_to(x, y) for x, y in path) for box in obstacles]
    assert min(clearance) >= 0.45, clearance
    assert min(clearance) <= 1.5
    assert min(w.distance_to(*GOAL) for w in walls) >= 0.9


def test_geometry_places_the_imu_site_in_base_link() -> None:
    from otonav.hal.mujoco import MujocoInterface

    hal = MujocoInterface("empty", lidar_beams=8)
    try:
        # robot.xml: <site name="imu" pos="0 0 0.02"/> on the chassis (= base_link).
        assert hal.geometry.imu_offset == pytest.approx((0.0, 0.0, 0.02))
    finally:
        hal.close()


def test_a_lidar_field_of_view_below_a_full_circle() -> None:
    """``world.lidar_fov`` (issue 42; BARN's Jackal: 270 degrees): the beams span
    -fov/2 .. +fov/2, both ends a beam, and nothing behind the robot is seen. A full
    circle keeps its floats: from -pi, one increment short of +pi."""
    full = MujocoInterface("obstacles", lidar_beams=360)
    narrow = MujocoInterface("obstacles", lidar_beams=271, lidar_fov=math.radians(270))
    try:
        s = full.read_scan()
        assert (s.angle_min, s.angle_increment) == (-math.pi, 2.0 * math.pi / 360)
        n = narrow.read_scan()
        assert n.angle_min == pytest.approx(-math.radians(135))
        assert n.angle_max == pytest.approx(math.radians(135))
        assert n.angle_increment == pytest.approx(math.radians(1.0))
        assert len(n.ranges) == 271
        # The beam straight ahead reads the same in both (the same ray).
        assert n.ranges[135] == pytest.approx(s.ranges[180], abs=1e-9)
    finally:
        full.close()
        narrow.close()
    with pytest.raises(ValueError, match="lidar_fov"):
        MujocoInterface("obstacles", lidar_fov=7.0)
