"""The localizer's update (drifting odometry corrected against its own map), its /map
message, the odometry error model, and the localized navigator's frame."""

from __future__ import annotations

import math

import anyio
import numpy as np
import pytest
from numpy.typing import NDArray
from synthetic_scans import ROOM, box, scan

from otonav.actors import Bridge, topics
from otonav.actors._localized_navigator import LocalizedNavigator
from otonav.actors._localizer import Localizer, LocalizerParams
from otonav.actors._odometry_error import OdometryError
from otonav.hal import FakeHardware
from otonav.msgs import OccupancyGrid, Odometry, Time, WheelCommand
from otonav.nav._scan_match import compose, inverse
from otonav.params import NavigationParams
from otonav.record.cdr import decode, encode
from otonav.runtime import QoS, Reliability, System, virtual_loop_factory

pytestmark = pytest.mark.unit


def drifted(truth: tuple[float, float, float], k: int) -> tuple[float, float, float]:
    """What a drifting odometry says after ``k`` scans: 4 mm and 2 mrad more each."""
    return compose((0.004 * k, -0.002 * k, 0.002 * k), truth)


def test_the_localizer_corrects_drifting_odometry_against_its_own_map() -> None:
    localizer = Localizer(LocalizerParams(), laser_offset_x=0.0)
    worst = 0.0
    for k in range(40):  # 2 m along x at 5 cm per scan, turning a little
        truth = (-1.0 + 0.05 * k, 0.3, 0.01 * k)
        pose = localizer.update(drifted(truth, k), scan(ROOM, truth))
        worst = max(worst, math.hypot(pose[0] - truth[0], pose[1] - truth[1]))
        assert abs(math.remainder(pose[2] - truth[2], math.tau)) < 0.005
    odometry = drifted(truth, 39)
    assert math.hypot(odometry[0] - truth[0], odometry[1] - truth[1]) > 0.1  # it drifted
    assert worst < 0.01
    # map -> odom is what odometry got wrong: map -> odom * odom -> base_link = truth
    assert compose(localizer.correction, odometry) == pytest.approx(truth, abs=0.01)
    assert localizer.correction == pytest.approx(compose(pose, inverse(odometry)))
    assert localizer.rejected == 0
    assert localizer.matches == 39  # the first scan starts the map


def test_the_first_scan_is_taken_where_odometry_says_and_the_map_grows_on_motion() -> None:
    localizer = Localizer(
        LocalizerParams(update_distance=0.2, update_angle=0.5), laser_offset_x=0.1
    )

    def seen(pose: tuple[float, float, float]) -> NDArray[np.float64]:
        """The scan from the laser 0.1 m ahead, in base_link."""
        points: NDArray[np.float64] = scan(ROOM, compose(pose, (0.1, 0.0, 0.0))) + np.array(
            [0.1, 0.0]
        )
        return points

    start = (0.5, -0.5, 0.4)
    assert localizer.update(start, seen(start)) == start
    assert localizer.correction == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
    cells = localizer.grid.cells
    assert cells > 100
    # the same place again: matched where it is, nothing added
    assert localizer.update(start, seen(start)) == pytest.approx(start, abs=2e-3)
    assert localizer.grid.cells == cells
    # 0.1 m on (under update_distance): still nothing added
    localizer.update(compose(start, (0.1, 0.0, 0.0)), seen(compose(start, (0.1, 0.0, 0.0))))
    assert localizer.grid.cells == cells
    # 0.3 m on (past update_distance): a scan from a new place adds cells
    moved = compose(start, (0.3, 0.0, 0.0))
    assert localizer.update(moved, seen(moved)) == pytest.approx(moved, abs=5e-3)
    assert localizer.grid.cells > cells


def test_an_unmatched_scan_keeps_the_correction() -> None:
    localizer = Localizer(LocalizerParams(), laser_offset_x=0.0)
    localizer.update((0.0, 0.0, 0.0), scan(box(0, 0, 5, 5), (0.0, 0.0, 0.0)))
    localizer.correction = (0.1, 0.0, 0.0)
    elsewhere = [(-1.5, -3.0, -1.5, 3.0), (1.7, -3.0, 1.7, 3.0)]
    pose = localizer.update((0.0, 0.0, 0.0), scan(elsewhere, (0.0, 0.0, 0.0)))
    assert pose == (0.1, 0.0, 0.0)
    assert localizer.correction == pytest.approx((0.1, 0.0, 0.0))
    assert localizer.rejected == 1


def test_the_map_message_is_an_occupancy_grid_in_the_map_frame() -> None:
    localizer = Localizer(LocalizerParams(resolution=0.1, half_size=6.0), laser_offset_x=0.0)
    localizer.update((0.0, 0.0, 0.0), scan(ROOM, (0.0, 0.0, 0.0)))
    grid = localizer.occupancy_grid(Time.from_seconds(1.5))
    assert grid.header.frame_id == "map"
    assert grid.info.resolution == pytest.approx(0.1)
    assert len(grid.data) == grid.info.width * grid.info.height
    # the room's walls (inner faces at +-5 m) bound what is known
    assert grid.info.origin.position.x == pytest.approx(-5.0, abs=0.11)
    assert grid.info.width * 0.1 == pytest.approx(10.0, abs=0.25)
    cells = np.array(grid.data).reshape(grid.info.height, grid.info.width)
    assert set(np.unique(cells).tolist()) <= {-1, *range(101)}
    assert (cells > 50).sum() > 100  # walls and boxes
    assert (cells == -1).sum() > 0  # behind the boxes
    # the robot's own cell is free
    row = int((0.0 - grid.info.origin.position.y) / 0.1)
    col = int((0.0 - grid.info.origin.position.x) / 0.1)
    assert 0 <= cells[row, col] < 50
    # it encodes as ROS 2 CDR and decodes to the same message
    assert decode(OccupancyGrid, encode(grid)) == grid


# -- the odometry error model ------------------------------------------------------------


def test_the_odometry_error_scales_distance_and_biases_the_yaw_rate() -> None:
    error = OdometryError(scale=0.02, gyro_bias=0.01)
    assert error.apply(0.5, 0.2) == pytest.approx((0.51, 0.21))


def test_the_gyro_noise_is_seeded() -> None:
    a = [OdometryError(gyro_noise=0.1, seed=3).apply(0.0, 0.0)[1] for _ in range(1)]
    run = OdometryError(gyro_noise=0.1, seed=3)
    same = [run.apply(0.0, 0.0)[1] for _ in range(50)]
    again = OdometryError(gyro_noise=0.1, seed=3)
    assert [again.apply(0.0, 0.0)[1] for _ in range(50)] == same
    other = OdometryError(gyro_noise=0.1, seed=4)
    assert [other.apply(0.0, 0.0)[1] for _ in range(50)] != same
    assert a[0] == same[0]
    assert 0.05 < float(np.std(same)) < 0.15


def test_the_bridge_applies_the_odometry_error() -> None:
    hal = FakeHardware()
    got: list[Odometry] = []

    async def main() -> None:
        bridge = Bridge(hal, odometry_error=OdometryError(scale=0.1, gyro_bias=0.2))
        async with System([bridge]) as system:
            odom = system.subscribe(
                topics.ODOM, Odometry, QoS(Reliability.BEST_EFFORT, depth=100_000)
            )
            wheels = system.publisher(topics.WHEEL_CMD, WheelCommand, topics.COMMAND_QOS)
            await wheels.publish(WheelCommand(left=6.0, right=6.0))
            await anyio.sleep(1.0)
            got.extend(odom.drain())

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(hal, wall_ceiling=10)})
    truth = hal.ground_truth()
    assert abs(truth.yaw) < 1e-9  # it drove straight
    last = got[-1]
    # the yaw drifted by the bias over the second; the distance is 10 % long
    assert last.pose.pose.orientation.yaw() == pytest.approx(0.2, abs=0.01)
    assert last.twist.twist.linear.x == pytest.approx(1.1 * 0.3, rel=1e-6)  # 0.3 m/s true
    driven = math.hypot(last.pose.pose.position.x, last.pose.pose.position.y)
    assert driven > 1.08 * 0.29


# -- the localized navigator -------------------------------------------------------------


def test_the_localized_navigator_works_in_the_map_frame() -> None:
    nav = LocalizedNavigator(NavigationParams(), laser_offset_x=0.0)
    assert nav.frame_id == "map"
    assert nav._in_frame((1.0, 0.0, 0.0)) == (1.0, 0.0, 0.0)  # no correction yet
    nav.correction = (0.5, -0.2, math.pi / 2)
    assert nav._in_frame((1.0, 0.0, 0.0)) == pytest.approx((0.5, 0.8, math.pi / 2))


def test_the_stack_config_defaults_are_the_localizers() -> None:
    from otonav.stack import StackConfig
    from otonav.stack._build import localizer_params

    assert localizer_params(StackConfig()) == LocalizerParams()
