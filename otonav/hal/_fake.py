"""A kinematic, in-memory robot for fast, deterministic actor tests.

:class:`FakeHardware` has no physics: the wheels follow their setpoints instantly (or
through a first-order lag), the pose integrates the unicycle model exactly, and the lidar
is an analytic 2-D ray cast against boxes (vectorised slab method). The defaults match
the geometry of the MuJoCo robot in ``otonav/hal/assets/robot.xml``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from otonav.hal._interface import RobotHardwareInterface
from otonav.hal._types import (
    BoxObstacle,
    GroundTruth,
    ImuSample,
    LidarSpec,
    RangeScan,
    RobotGeometry,
    WheelSetpoint,
    WheelState,
)

__all__ = ["GRAVITY", "FakeHardware", "arena_walls", "cast_rays_2d"]

GRAVITY = 9.81
"""m/s^2, reported by the fake accelerometer on +z."""

_TINY = 1e-12
_LIDAR = LidarSpec()  # the default lidar


def arena_walls(half_size: float, thickness: float = 0.1) -> tuple[BoxObstacle, ...]:
    """Four walls whose inner faces are at x, y = +-``half_size`` (m)."""
    h, t = half_size, thickness / 2.0
    span = half_size + thickness
    return (
        BoxObstacle(h + t, 0.0, t, span),
        BoxObstacle(-h - t, 0.0, t, span),
        BoxObstacle(0.0, h + t, span, t),
        BoxObstacle(0.0, -h - t, span, t),
    )


def cast_rays_2d(
    origin_x: float,
    origin_y: float,
    angles: NDArray[np.float64],
    boxes: Sequence[BoxObstacle],
) -> NDArray[np.float64]:
    """Distance (m) along each world-frame ray angle to the nearest box; inf on a miss.

    A ray starting inside a box reports 0. Vectorised over rays x boxes (slab method).
    """
    if not boxes:
        return np.full(angles.shape, np.inf)
    cx = np.array([b.x for b in boxes])
    cy = np.array([b.y for b in boxes])
    hx = np.array([b.half_x for b in boxes])
    hy = np.array([b.half_y for b in boxes])
    yaw = np.array([b.yaw for b in boxes])
    c, s = np.cos(yaw), np.sin(yaw)
    # Ray origin and directions in each box's frame: shapes (m,) and (n, m).
    rx, ry = origin_x - cx, origin_y - cy
    ox = c * rx + s * ry
    oy = -s * rx + c * ry
    dx, dy = np.cos(angles)[:, None], np.sin(angles)[:, None]
    ux = c * dx + s * dy
    uy = -s * dx + c * dy
    ux = np.where(np.abs(ux) < _TINY, _TINY, ux)
    uy = np.where(np.abs(uy) < _TINY, _TINY, uy)
    t1x, t2x = (-hx - ox) / ux, (hx - ox) / ux
    t1y, t2y = (-hy - oy) / uy, (hy - oy) / uy
    t_near = np.maximum(np.minimum(t1x, t2x), np.minimum(t1y, t2y))
    t_far = np.minimum(np.maximum(t1x, t2x), np.maximum(t1y, t2y))
    hit = (t_far >= t_near) & (t_far >= 0.0)
    dist = np.where(hit, np.maximum(t_near, 0.0), np.inf)
    return np.asarray(dist.min(axis=1), dtype=np.float64)


class FakeHardware(RobotHardwareInterface):
    """Kinematic unicycle robot with an analytic lidar. Deterministic, no physics.

    ``wheel_time_constant`` (s): 0 means the wheels reach their setpoint instantly;
    otherwise they follow it through a first-order lag (exactly discretised).
    ``start`` is (x m, y m, yaw rad). ``arena_half_size`` (m) adds four walls whose
    inner faces are at +-half size.
    """

    def __init__(
        self,
        *,
        tick: float = 0.002,
        wheel_radius: float = 0.05,
        wheel_separation: float = 0.22,
        laser_offset_x: float = 0.06,
        laser_offset_z: float = 0.09,
        obstacles: Sequence[BoxObstacle] = (),
        arena_half_size: float | None = None,
        start: tuple[float, float, float] = (0.0, 0.0, 0.0),
        wheel_time_constant: float = 0.0,
        lidar_beams: int = _LIDAR.beams,
        lidar_range_min: float = _LIDAR.range_min,
        lidar_range_max: float = _LIDAR.range_max,
    ) -> None:
        if not tick > 0.0:
            raise ValueError(f"tick must be positive, got {tick}")
        self._lidar = LidarSpec(lidar_beams, lidar_range_min, lidar_range_max)
        if wheel_time_constant < 0.0:
            raise ValueError(f"wheel_time_constant must be >= 0, got {wheel_time_constant}")
        self._tick = tick
        self._geometry = RobotGeometry(
            wheel_radius=wheel_radius,
            wheel_separation=wheel_separation,
            laser_offset_x=laser_offset_x,
            laser_offset_z=laser_offset_z,
            base_height=wheel_radius,
        )
        self._obstacles = tuple(obstacles)
        self._walls = () if arena_half_size is None else arena_walls(arena_half_size)
        self._boxes = self._obstacles + self._walls
        self._tau = wheel_time_constant
        self._beam_angles = self._lidar.angles()

        self._x, self._y, self._yaw = start
        self._cmd = WheelSetpoint(0.0, 0.0)
        self._wl = self._wr = 0.0  # wheel angular velocities, rad/s
        self._ql = self._qr = 0.0  # wheel angles, rad
        self._accel = 0.0  # forward acceleration over the last tick, m/s^2

    # -- time ---------------------------------------------------------------------------

    @property
    def tick(self) -> float:
        return self._tick

    def advance(self, n: int) -> None:
        if not self._steps(n):
            return
        if self._tau == 0.0:
            wl, wr = self._cmd.left, self._cmd.right
            v_before = self._rates(self._wl, self._wr)[0]
            self._wl, self._wr = wl, wr
            self._integrate(wl, wr, n * self._tick)
            self._accel = (self._rates(wl, wr)[0] - v_before) / self._tick if n == 1 else 0.0
        else:
            decay = math.exp(-self._tick / self._tau)
            gain = self._tau * (1.0 - decay)  # integral of the decaying error over a tick
            for _ in range(n):
                cl, cr = self._cmd.left, self._cmd.right
                wl0, wr0 = self._wl, self._wr
                wl1 = cl + (wl0 - cl) * decay
                wr1 = cr + (wr0 - cr) * decay
                # Mean wheel speeds over the tick (exact for the first-order response).
                ml = cl + (wl0 - cl) * gain / self._tick
                mr = cr + (wr0 - cr) * gain / self._tick
                self._wl, self._wr = wl1, wr1
                self._integrate(ml, mr, self._tick)
                dv = self._rates(wl1, wr1)[0] - self._rates(wl0, wr0)[0]
                self._accel = dv / self._tick
        self._ticks += n

    def _rates(self, wl: float, wr: float) -> tuple[float, float]:
        """Body speed (m/s) and turn rate (rad/s) at wheel speeds ``wl``, ``wr``."""
        r = self._geometry.wheel_radius
        return r * (wl + wr) / 2.0, r * (wr - wl) / self._geometry.wheel_separation

    def _integrate(self, wl: float, wr: float, dt: float) -> None:
        """Advance pose and wheel angles by ``dt`` at constant wheel speeds (exact arc)."""
        v, w = self._rates(wl, wr)
        yaw0 = self._yaw
        dyaw = w * dt
        if abs(dyaw) < 1e-9:
            mid = yaw0 + dyaw / 2.0
            self._x += v * dt * math.cos(mid)
            self._y += v * dt * math.sin(mid)
        else:
            self._x += v / w * (math.sin(yaw0 + dyaw) - math.sin(yaw0))
            self._y -= v / w * (math.cos(yaw0 + dyaw) - math.cos(yaw0))
        self._yaw = math.remainder(yaw0 + dyaw, 2.0 * math.pi)
        self._ql += wl * dt
        self._qr += wr * dt

    # -- I/O ----------------------------------------------------------------------------

    def write(self, cmd: WheelSetpoint) -> None:
        self._check_open()
        if not (math.isfinite(cmd.left) and math.isfinite(cmd.right)):
            raise ValueError(f"wheel command must be finite, got {cmd}")
        self._cmd = cmd

    def read_wheels(self) -> WheelState:
        return WheelState(self._ql, self._qr, self._wl, self._wr)

    def read_imu(self) -> ImuSample:
        v, w = self._rates(self._wl, self._wr)
        half = self._yaw / 2.0
        return ImuSample(
            orientation=(math.cos(half), 0.0, 0.0, math.sin(half)),
            angular_velocity=(0.0, 0.0, w),
            linear_acceleration=(self._accel, v * w, GRAVITY),
        )

    def read_scan(self) -> RangeScan:
        ox = self._x + self._geometry.laser_offset_x * math.cos(self._yaw)
        oy = self._y + self._geometry.laser_offset_x * math.sin(self._yaw)
        world_angles = np.asarray(self._beam_angles + self._yaw, dtype=np.float64)
        return self._lidar.scan(cast_rays_2d(ox, oy, world_angles, self._boxes))

    def ground_truth(self) -> GroundTruth:
        v, _ = self._rates(self._wl, self._wr)
        return GroundTruth(
            x=self._x,
            y=self._y,
            yaw=self._yaw,
            pitch=0.0,
            roll=0.0,
            vx_world=v * math.cos(self._yaw),
            vy_world=v * math.sin(self._yaw),
        )

    @property
    def geometry(self) -> RobotGeometry:
        return self._geometry

    def obstacles(self) -> tuple[BoxObstacle, ...]:
        return self._obstacles

    def walls(self) -> tuple[BoxObstacle, ...]:
        return self._walls
