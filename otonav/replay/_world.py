"""The robot a replay builds its actors for, without building its world.

The stack builder derives what the actors need from the hardware interface's
``geometry`` (wheel radius and separation for the base, the footprint radius and the
laser offset for the navigator and the safety layer); no replayed actor steps physics.
Compiling the MJCF for that was the largest part of bringing the actors up (3.4 ms warm,
7 ms in a fresh process, of a ~70 ms navigator replay). A recording made since ADR 0036
keeps the geometry the run's actors were built for (``otonav.world``'s ``robot``), so
:class:`RecordedRobot` answers ``geometry`` from it and builds the world itself only when
an actor asks for anything else: a node that needs the world still gets it.
"""

from __future__ import annotations

from collections.abc import Callable

from otonav.hal import (
    BoxObstacle,
    GroundTruth,
    HardwareHealth,
    ImuSample,
    RangeScan,
    RobotGeometry,
    RobotHardwareInterface,
    WheelSetpoint,
    WheelState,
)
from otonav.hal._types import Reach
from otonav.replay._recording import Recording
from otonav.stack import StackConfig
from otonav.stack._worldmeta import WORLD_METADATA, geometry_from_metadata, reach_from_metadata

__all__ = ("RecordedRobot", "recorded_geometry", "recorded_reach")


def recorded_geometry(recording: Recording, stack: StackConfig) -> RobotGeometry | None:
    """The robot geometry ``recording`` was made with, when it holds one and ``stack``
    (the replay's config, after ``--set``) has the recorded world, hardware and robot:
    changing ``world.*``, ``hal.*`` or ``robot.*`` asks for another robot, which is then
    built (None)."""
    recorded = recording.stack
    if (
        recorded is None
        or stack.world != recorded.world
        or stack.hal != recorded.hal
        or stack.robot != recorded.robot
    ):
        return None
    return geometry_from_metadata(recording.metadata.get(WORLD_METADATA, {}))


def recorded_reach(
    recording: Recording, geometry: RobotGeometry | None
) -> tuple[tuple[float, float], Reach] | None:
    """What the recorded robot was identified to reach, with the recorded geometry (a
    world built anew identifies its own)."""
    if geometry is None:
        return None
    return reach_from_metadata(recording.metadata.get(WORLD_METADATA, {}))


class RecordedRobot(RobotHardwareInterface):
    """A hardware interface whose ``geometry`` is the recorded one; every other call
    builds the world (``build()``, once) and goes to it."""

    def __init__(
        self,
        geometry: RobotGeometry,
        build: Callable[[], RobotHardwareInterface],
        reach: tuple[tuple[float, float], Reach] | None = None,
    ) -> None:
        self._geometry = geometry
        self._build = build
        self._reach = reach
        self._world: RobotHardwareInterface | None = None

    @property
    def built(self) -> bool:
        """Whether an actor needed more than the geometry (the world was built)."""
        return self._world is not None

    def world(self) -> RobotHardwareInterface:
        if self._world is None:
            self._world = self._build()
        return self._world

    @property
    def geometry(self) -> RobotGeometry:
        return self._geometry

    def reach(self, v: float, omega: float) -> Reach | None:
        # The base's deadband and the navigator's limits were built from it (ADR 0066):
        # none recorded (a CAN robot's, an older file's) was none in the run; the
        # recorded one when asked the same; else the world identifies it again.
        if self._reach is None:
            return None
        if self._reach[0] == (v, omega):
            return self._reach[1]
        return self.world().reach(v, omega)

    @property
    def tick(self) -> float:
        return self.world().tick

    @property
    def ticks(self) -> int:
        return self.world().ticks

    def advance(self, n: int) -> None:
        self.world().advance(n)

    def write(self, cmd: WheelSetpoint) -> None:
        self.world().write(cmd)

    def read_wheels(self) -> WheelState:
        return self.world().read_wheels()

    def read_imu(self) -> ImuSample:
        return self.world().read_imu()

    def read_scan(self) -> RangeScan:
        return self.world().read_scan()

    def ground_truth(self) -> GroundTruth:
        return self.world().ground_truth()

    def obstacles(self) -> tuple[BoxObstacle, ...]:
        return self.world().obstacles()

    def walls(self) -> tuple[BoxObstacle, ...]:
        return self.world().walls()

    def clearance_boxes(self) -> tuple[BoxObstacle, ...]:
        return self.world().clearance_boxes()

    def health(self) -> HardwareHealth:
        return self.world().health()

    def close(self) -> None:
        if self._world is not None:
            self._world.close()
