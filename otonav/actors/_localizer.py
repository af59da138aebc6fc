"""The localizer: /odom + /scan -> /tf (map -> odom) + /map. Scan-to-map matching in
the manner of Hector SLAM and Karto's scan matcher (mapping and localization at once,
no loop closure): each scan is matched to the map built so far, near where odometry
predicts it (:mod:`otonav.nav._scan_match`), and added to the map at the matched pose
(:mod:`otonav.nav._scan_map`). What odometry got wrong since the start is the
``map -> odom`` transform (REP 105): ``map -> base_link = (map -> odom) * (odom ->
base_link)``."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from otonav.actors import _topics as topics
from otonav.actors._odom_history import OdomHistory
from otonav.actors._scan_cache import points_of
from otonav.msgs import (
    Header,
    LaserScan,
    MapMetaData,
    OccupancyGrid,
    Odometry,
    Point,
    Pose,
    Quaternion,
    TFMessage,
    Time,
    Transform,
    TransformStamped,
    Vector3,
)
from otonav.nav._geometry import wrap_angle
from otonav.nav._scan_map import ScanMap
from otonav.nav._scan_match import compose, inverse, match_scan, transform
from otonav.params import LocalizerParams
from otonav.runtime import Actor, Input, Output

__all__ = ("Localizer", "LocalizerParams")

MAP_FRAME = "map"
ODOM_FRAME = "odom"


class Localizer(Actor):
    """On every scan: the odometry pose at its stamp, predicted into the map frame by
    the current ``map -> odom``, matched to the map; a trusted match becomes the new
    ``map -> odom`` (published on /tf, stamped with the scan); the scan is added to the
    map at the matched pose when the robot moved ``update_distance`` or turned
    ``update_angle`` since the last one. /map (latched) every ``map_period`` s when it
    changed. The map frame is the world frame at the start: odometry starts at the
    start pose, and ``map -> odom`` starts as the identity."""

    odom = Input(topics.ODOM, Odometry, topics.SENSOR_QOS)
    scan = Input(topics.SCAN, LaserScan, topics.SENSOR_QOS)
    tf = Output(topics.TF, TFMessage, topics.TF_QOS)
    map_out = Output(topics.MAP, OccupancyGrid, topics.LATCHED)

    def __init__(
        self,
        params: LocalizerParams,
        *,
        laser_offset_x: float,
        start: tuple[float, float] = (0.0, 0.0),
        name: str = "localizer",
    ) -> None:
        super().__init__(name)
        self.params = params
        self.laser_offset_x = laser_offset_x
        self.grid = ScanMap(
            start[0],
            start[1],
            half_size=params.half_size,
            resolution=params.resolution,
            max_distance=params.match.max_distance,
        )
        self.correction: tuple[float, float, float] = (0.0, 0.0, 0.0)
        """``map -> odom`` (x m, y m, yaw rad)."""
        self.matches = 0
        self.rejected = 0
        self._history = OdomHistory()
        self._inserted: tuple[float, float, float] | None = None
        self._map_changed = False
        self._map_time = -math.inf

    async def run(self) -> None:
        async for scan in self.scan:
            self._history.extend(self.odom.drain())
            stamp = scan.header.stamp.to_seconds()
            odom_pose = self._history.pose_at(stamp)
            if odom_pose is None:
                continue
            self.update(odom_pose, self._points(scan))
            await self._publish_tf(scan.header.stamp)
            now = self.clock.now()
            if self._map_changed and now - self._map_time >= self.params.map_period:
                self._map_time = now
                self._map_changed = False
                await self.map_out.publish(self.occupancy_grid(Time.from_seconds(now)))

    def _points(self, scan: LaserScan) -> NDArray[np.float64]:
        """The scan's valid returns in base_link (a blocked beam says nothing of where)."""
        seen = points_of(scan, self.laser_offset_x)
        xy = seen.xy
        if seen.blocked:
            far = np.hypot(xy[:, 0] - self.laser_offset_x, xy[:, 1]) >= scan.range_min
            xy = xy[far]
        return xy

    def update(
        self, odom_pose: tuple[float, float, float], points: NDArray[np.float64]
    ) -> tuple[float, float, float]:
        """One scan (its points in base_link, taken at ``odom_pose`` in odom): match,
        correct ``map -> odom``, grow the map; returns the pose in the map frame."""
        predicted = compose(self.correction, odom_pose)
        pose = predicted
        if self.grid.cells > 0:
            result = match_scan(self.grid, points, predicted, self.params.match)
            if result.ok:
                pose = result.pose
                self.matches += 1
            else:
                self.rejected += 1
        self.correction = compose(pose, inverse(odom_pose))
        if self._due(pose):
            self._inserted = pose
            sensor = compose(pose, (self.laser_offset_x, 0.0, 0.0))
            x, y = transform(pose, points)
            self.grid.insert(sensor[0], sensor[1], x, y)
            self._map_changed = True
        return pose

    def _due(self, pose: tuple[float, float, float]) -> bool:
        last = self._inserted
        if last is None:
            return True
        return (
            math.hypot(pose[0] - last[0], pose[1] - last[1]) >= self.params.update_distance
            or abs(wrap_angle(pose[2] - last[2])) >= self.params.update_angle
        )

    async def _publish_tf(self, stamp: Time) -> None:
        x, y, yaw = self.correction
        await self.tf.publish(
            TFMessage.fast(
                transforms=(
                    TransformStamped.fast(
                        header=Header.fast(stamp=stamp, frame_id=MAP_FRAME),
                        child_frame_id=ODOM_FRAME,
                        transform=Transform.fast(
                            translation=Vector3.fast(x=x, y=y, z=0.0),
                            rotation=Quaternion.from_yaw(yaw),
                        ),
                    ),
                )
            )
        )

    def occupancy_grid(self, stamp: Time) -> OccupancyGrid:
        """The known part of the map as a ``nav_msgs/OccupancyGrid`` in the map frame."""
        grid = self.grid
        row0, col0, height, width, cells = grid.occupancy()
        res = grid.resolution
        origin = Pose.fast(
            position=Point.fast(x=grid.origin_x + col0 * res, y=grid.origin_y + row0 * res, z=0.0),
            orientation=Quaternion.fast(x=0.0, y=0.0, z=0.0, w=1.0),
        )
        return OccupancyGrid.fast(
            header=Header.fast(stamp=stamp, frame_id=MAP_FRAME),
            info=MapMetaData.fast(
                map_load_time=stamp,
                resolution=float(np.float32(res)),
                width=width,
                height=height,
                origin=origin,
            ),
            data=tuple(cells.tolist()),
        )
