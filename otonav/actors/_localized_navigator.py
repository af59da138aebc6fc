"""The avoiding navigator on the localized pose: it reads ``map -> odom`` from /tf (the
localizer's, :mod:`otonav.actors._localizer`) and works in the map frame, so its map,
its path, the goal and ``reached`` are all judged where the robot really is, not where
odometry drifted to."""

from __future__ import annotations

from otonav.actors import _topics as topics
from otonav.actors._avoiding_navigator import AvoidingNavigator
from otonav.msgs import TFMessage
from otonav.nav._scan_match import compose
from otonav.runtime import Input, QoS, Reliability

__all__ = ("LocalizedNavigator",)

TF_DEPTH = 64
"""/tf messages kept between two steps: the bridge's odom -> base_link at 100 Hz and
the localizer's map -> odom at 10 Hz, drained at the navigator's 20 Hz."""


class LocalizedNavigator(AvoidingNavigator):
    """:class:`AvoidingNavigator` in the map frame: every odometry pose it uses is
    composed with the latest ``map -> odom`` on /tf (identity until the first one).
    The goal on /goal is taken in the map frame (REP 105: the global frame)."""

    tf_in = Input(topics.TF, TFMessage, QoS(Reliability.BEST_EFFORT, depth=TF_DEPTH))
    frame_id = "map"
    correction: tuple[float, float, float] = (0.0, 0.0, 0.0)
    """The latest ``map -> odom`` (x m, y m, yaw rad)."""

    def _take_odometry(self) -> None:
        super()._take_odometry()
        for message in self.tf_in.drain():
            for t in message.transforms:
                if t.header.frame_id == "map" and t.child_frame_id == "odom":
                    tr = t.transform
                    self.correction = (tr.translation.x, tr.translation.y, tr.rotation.yaw())

    def _in_frame(self, pose: tuple[float, float, float]) -> tuple[float, float, float]:
        return compose(self.correction, pose)
