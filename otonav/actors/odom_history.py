"""Recent odometry by stamp: where the robot was when a scan was taken."""

from __future__ import annotations

from collections import deque

from otonav.msgs import Odometry

Pose = tuple[float, float, float]


class OdomHistory:
    """The last ``size`` odometry messages as (stamp s, pose (x, y, yaw), v, omega)."""

    def __init__(self, size: int = 32) -> None:
        self._items: deque[tuple[float, Pose, float, float]] = deque(maxlen=size)

    def add(self, odom: Odometry) -> None:
        p = odom.pose.pose
        t = odom.twist.twist
        self._items.append(
            (
                odom.header.stamp.to_seconds(),
                (p.position.x, p.position.y, p.orientation.yaw()),
                t.linear.x,
                t.angular.z,
            )
        )

    @property
    def latest(self) -> tuple[float, Pose, float, float] | None:
        return self._items[-1] if self._items else None

    def pose_at(self, stamp: float) -> Pose | None:
        """The pose with the stamp nearest ``stamp`` (None with no odometry yet)."""
        if not self._items:
            return None
        return min(self._items, key=lambda item: abs(item[0] - stamp))[1]
