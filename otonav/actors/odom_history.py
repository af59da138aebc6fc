"""Recent odometry by stamp: where the robot was when a scan was taken."""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable

from otonav.msgs import Odometry

Pose = tuple[float, float, float]


def _stamp(odom: Odometry) -> float:
    t = odom.header.stamp
    return t.sec + t.nanosec * 1e-9


def _pose(odom: Odometry) -> Pose:
    p = odom.pose.pose
    return (p.position.x, p.position.y, p.orientation.yaw())


class OdomHistory:
    """The last ``size`` odometry messages; decoded only when asked (odometry comes at
    100 Hz, a pose is wanted at 10-20 Hz)."""

    def __init__(self, size: int = 32) -> None:
        self._items: deque[Odometry] = deque(maxlen=size)

    def add(self, odom: Odometry) -> None:
        self._items.append(odom)

    def extend(self, odoms: Iterable[Odometry]) -> None:
        """Add messages, oldest first (``Subscription.drain``)."""
        self._items.extend(odoms)

    @property
    def latest(self) -> tuple[float, Pose, float, float] | None:
        """(stamp s, pose (x, y, yaw), v m/s, omega rad/s) of the newest message."""
        if not self._items:
            return None
        odom = self._items[-1]
        twist = odom.twist.twist
        return _stamp(odom), _pose(odom), twist.linear.x, twist.angular.z

    def pose_at(self, stamp: float) -> Pose | None:
        """The pose with the stamp nearest ``stamp`` (None with no odometry yet)."""
        if not self._items:
            return None
        # Newest first: stamps only grow, so the gap shrinks until the nearest one.
        best, gap = self._items[-1], abs(_stamp(self._items[-1]) - stamp)
        for odom in reversed(self._items):
            this = abs(_stamp(odom) - stamp)
            if this > gap:
                break
            best, gap = odom, this
        return _pose(best)
