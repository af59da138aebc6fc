"""The hardware abstraction: what the rest of otonav may know about a robot.

A :class:`RobotHardwareInterface` is both the robot's I/O (wheel commands in; encoders,
IMU, lidar out) and, in simulation, the *time source*: the virtual-time loop calls
:meth:`RobotHardwareInterface.advance` and nothing else steps the world. Time is an
integer count of physics ticks; ``sim_time`` is derived from it, never accumulated.
"""

from __future__ import annotations

import abc
from types import TracebackType
from typing import Self

from otonav.hal._health import HardwareHealth
from otonav.hal._types import (
    BoxObstacle,
    GroundTruth,
    ImuSample,
    PolygonObstacle,
    RangeScan,
    Reach,
    RobotGeometry,
    RoundObstacle,
    WheelSetpoint,
    WheelState,
)

__all__ = ["RobotHardwareInterface"]

_OK = HardwareHealth()


class RobotHardwareInterface(abc.ABC):
    """A differential-drive robot with wheel encoders, an IMU and a planar lidar.

    Usable as a context manager (``close()`` on exit).
    """

    _closed = False
    _ticks = 0

    @property
    @abc.abstractmethod
    def tick(self) -> float:
        """Physics step, seconds. Constant for the life of the interface."""

    @property
    def ticks(self) -> int:
        """Number of physics steps taken since construction: the truth of time."""
        return self._ticks

    @property
    def sim_time(self) -> float:
        """Simulated time, seconds: ``ticks * tick`` (computed, so it never drifts)."""
        return self.ticks * self.tick

    @abc.abstractmethod
    def advance(self, n: int) -> None:
        """Step the world ``n`` ticks (``n >= 0``) holding the current wheel command."""

    def _steps(self, n: int) -> bool:
        """Check an :meth:`advance` by ``n``: open, ``n >= 0``; False: nothing to do."""
        self._check_open()
        if n < 0:
            raise ValueError(f"cannot advance by a negative number of ticks ({n})")
        return n > 0

    @abc.abstractmethod
    def write(self, cmd: WheelSetpoint) -> None:
        """Set the wheel angular velocity setpoints (rad/s); takes effect on next advance."""

    @abc.abstractmethod
    def read_wheels(self) -> WheelState:
        """Wheel encoders now: angles (rad) and angular velocities (rad/s)."""

    @abc.abstractmethod
    def read_imu(self) -> ImuSample:
        """IMU now: orientation (w, x, y, z), gyro (rad/s), accelerometer (m/s^2, with g)."""

    @abc.abstractmethod
    def read_scan(self) -> RangeScan:
        """One lidar sweep taken now, in the laser frame; ranges in metres, misses +inf."""

    @abc.abstractmethod
    def ground_truth(self) -> GroundTruth:
        """True chassis pose and world velocity (for judging only, never for control)."""

    def wheel_values(self) -> tuple[float, float, float, float]:
        """:meth:`read_wheels` as a plain tuple ``(left_position, right_position,
        left_velocity, right_velocity)`` (what a drive emulator reads from a simulated
        world at every 10 ms instant). This default reads :meth:`read_wheels`; a
        simulator may answer it more cheaply."""
        w = self.read_wheels()
        return w.left_position, w.right_position, w.left_velocity, w.right_velocity

    def planar_truth(self) -> tuple[float, float, float, float]:
        """True ``(x, y, vx_world, vy_world)``: the part of :meth:`ground_truth` a
        judge samples at every tick, without the attitude (for judging only). This
        default reads :meth:`ground_truth`; a simulator may answer it more cheaply."""
        truth = self.ground_truth()
        return truth.x, truth.y, truth.vx_world, truth.vy_world

    @property
    @abc.abstractmethod
    def geometry(self) -> RobotGeometry:
        """Wheel radius and separation (m) and laser mounting offset (m)."""

    def geometry_sources(self) -> dict[str, str]:
        """Where each value of :attr:`geometry` (and each robot part) came from: derived
        from the model, or given in the robot description. Empty when not known."""
        return {}

    def tallest_obstacle(self) -> float | None:
        """m: the top of the tallest obstacle above the floor; None if none or unknown."""
        return None

    def identified(self) -> tuple[tuple[float, float], Reach] | None:
        """The last :meth:`reach` measured: the (v, omega) asked and the result."""
        return None

    def reach(self, v: float, omega: float) -> Reach | None:
        """What the robot really reaches when asked for ``v`` m/s and ``omega`` rad/s
        (:class:`Reach`); None when this interface cannot tell (the stack then trusts
        the asked figures)."""
        return None

    @abc.abstractmethod
    def obstacles(self) -> tuple[BoxObstacle, ...]:
        """The world's obstacle boxes (m), for ground-truth clearance. Excludes walls."""

    def walls(self) -> tuple[BoxObstacle, ...]:
        """The world's boundary walls as boxes (m). Empty if the world has none."""
        return ()

    def round_obstacles(self) -> tuple[RoundObstacle, ...]:
        """The world's upright cylinders, capsules and spheres as disks (m), for
        ground-truth clearance. Empty if the world has none."""
        return ()

    def polygon_obstacles(self) -> tuple[PolygonObstacle, ...]:
        """The world's meshes as the convex hull of their vertices on the floor (m), for
        ground-truth clearance. Empty if the world has none."""
        return ()

    def unjudged_geoms(self) -> tuple[str, ...]:
        """The static geoms the robot could hit whose clearance cannot be measured (a
        tilted cylinder, an ellipsoid), ``name (type)`` each: a judged run fails on them."""
        return ()

    def clearance_boxes(self) -> tuple[BoxObstacle, ...]:
        """Everything the robot must keep clear of: obstacles and walls."""
        return self.obstacles() + self.walls()

    def health(self) -> HardwareHealth:
        """The hardware's health now. A simulated world is always OK (the default);
        real hardware reports starting, faults and recoveries. Cheap: the same object
        is returned until something changes."""
        return _OK

    def close(self) -> None:
        """Release resources. Idempotent; the interface must not be used afterwards."""
        self._closed = True

    def _check_open(self) -> None:
        if self._closed:
            raise RuntimeError(f"{type(self).__name__} is closed")

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
