"""The safety layer: /cmd_vel_nav -> (can the robot still stop?) -> /cmd_vel.

Nav2's collision monitor in spirit: its own actor on raw /scan and /odom, between the
planner and the base, trusting nothing the planner says."""

from __future__ import annotations

import math

from otonav.actors import _topics as topics
from otonav.actors._odom_history import OdomHistory
from otonav.actors._scan_cache import nearest_bound_of, nearest_of, points_of
from otonav.msgs import Header, LaserScan, Odometry, SafetyState, Time, Twist, Vector3
from otonav.nav._safety import safe_command, stopping_reach
from otonav.nav._scan import to_frame
from otonav.params import SafetyConfig, SafetyParams
from otonav.runtime import Actor, Input, Output

_DEFAULT = SafetyConfig()

_STOP = Twist.fast(
    linear=Vector3.fast(x=0.0, y=0.0, z=0.0), angular=Vector3.fast(x=0.0, y=0.0, z=0.0)
)
"""(0, 0): messages are immutable and shared, so one object serves every stop."""


class SafetyLayer(Actor):
    """At ``rate_hz``: take the newest planner command (zero once it is older than
    ``cmd_timeout`` s), move the last scan's returns into the current base_link with
    odometry, and publish on /cmd_vel the command limited by
    :func:`~otonav.nav._safety.safe_command`. With no scan or odometry for
    ``scan_timeout`` s of sim time it sends (0, 0) (``blind``); a zero command (or
    none) goes through as it is (``idle``). /safety/state says
    what it did whenever that changes, and at least once a second."""

    cmd_in = Input(topics.CMD_VEL_NAV, Twist, topics.COMMAND_QOS)
    odom = Input(topics.ODOM, Odometry, topics.SENSOR_QOS)
    scan = Input(topics.SCAN, LaserScan, topics.SENSOR_QOS)
    cmd_out = Output(topics.CMD_VEL, Twist, topics.COMMAND_QOS)
    state = Output(topics.SAFETY_STATE, SafetyState, topics.COMMAND_QOS)

    def __init__(
        self,
        params: SafetyParams,
        *,
        laser_offset_x: float,
        rate_hz: float = _DEFAULT.rate_hz,
        cmd_timeout: float = _DEFAULT.cmd_timeout,
        scan_timeout: float = _DEFAULT.scan_timeout,
        name: str = "safety",
    ) -> None:
        super().__init__(name)
        if not rate_hz > 0:
            raise ValueError(f"safety.rate_hz must be > 0 Hz, got {rate_hz}")
        self.params = params
        self.laser_offset_x = laser_offset_x
        self.rate_hz = rate_hz
        self.cmd_timeout = cmd_timeout
        self.scan_timeout = scan_timeout
        self._history = OdomHistory()
        self._scan: LaserScan | None = None
        self._points_pose: tuple[float, float, float] | None = None
        self._nearest = math.inf  # centre to the nearest return, at the scan's pose
        self._bound = math.inf  # a lower bound on it
        self.report_period = 1.0
        self._last_report: tuple[str, bool] | None = None
        self._reported_at = -math.inf
        self._scan_time = -math.inf

    async def run(self) -> None:
        rate = self.clock.rate(self.rate_hz)
        command: Twist | None = None
        received = -math.inf
        while True:
            await rate.sleep()
            now = self.clock.now()
            self._history.extend(self.odom.drain())
            latest = self.cmd_in.take_latest()
            if latest is not None:
                command, received = latest, now
            scan = self.scan.take_latest()
            if scan is not None:
                self._take_scan(scan, now)
            v_in = w_in = 0.0
            if command is not None and now - received <= self.cmd_timeout + 1e-9:
                v_in, w_in = command.linear.x, command.angular.z
            await self._send(now, v_in, w_in)

    def _take_scan(self, scan: LaserScan, now: float) -> None:
        pose = self._history.pose_at(scan.header.stamp.to_seconds())
        if pose is None:
            return
        # The points only when a return is within reach (_send); the fast-path test
        # needs the nearest distance, which costs a third of the points.
        self._scan, self._points_pose, self._scan_time = scan, pose, now
        self._nearest = math.nan  # computed when first needed (_nearest_return)
        self._bound = math.nan  # and its cheaper lower bound (_nearest_bound)

    def _nearest_bound(self) -> float:
        """A lower bound on :meth:`_nearest_return`, m (the exact one when known)."""
        if not math.isnan(self._nearest):
            return self._nearest
        if math.isnan(self._bound) and self._scan is not None:
            self._bound = nearest_bound_of(self._scan, self.laser_offset_x)
        return self._bound

    def _nearest_return(self) -> float:
        """Centre to the last scan's nearest return at the scan's pose, m."""
        if math.isnan(self._nearest) and self._scan is not None:
            self._nearest = nearest_of(self._scan, self.laser_offset_x)
        return self._nearest

    async def _send(self, now: float, v_in: float, w_in: float) -> None:
        stamp = self._history.latest_stamp  # the pose and twist only when moving
        clear_moved = 0.0  # the centre's travel since the scan, when a report wants it
        fresh_odom = stamp is not None and now - stamp <= self.scan_timeout
        if self._points_pose is None or now - self._scan_time > self.scan_timeout or not fresh_odom:
            v, w, scale, nearest, reason = 0.0, 0.0, 0.0, math.inf, "blind"
        elif v_in == 0.0 and w_in == 0.0:
            # A zero command (or none) goes through: braking is all there is, whatever
            # the scan says (safe_command would send the same (0, 0)); the scan is
            # only looked at if a report goes out. At rest this is every period.
            v, w, scale, nearest, reason = 0.0, 0.0, 1.0, math.nan, "idle"
        else:
            odom = self._history.latest
            assert odom is not None
            _, pose, v0, w0 = odom
            p, scan_pose = self.params, self._points_pose
            # The centre moved at most `moved` since the scan: a return that far plus
            # the longest stopping path out of the radius cannot matter (no transform).
            moved = math.hypot(pose[0] - scan_pose[0], pose[1] - scan_pose[1])
            fastest = max(abs(v_in), abs(v0))
            reach = stopping_reach(fastest, p)
            # A bound on the nearest return first (the shortest range less the laser
            # offset, ~1/6 of the exact distance's cost): when it clears, the exact
            # distance does too, and is only computed if a report goes out.
            if self._nearest_bound() - moved > p.radius + reach:
                v, w, scale, nearest, reason = v_in, w_in, 1.0, math.nan, "clear"
                clear_moved = moved
            elif (least := self._nearest_return()) - moved > p.radius + reach:
                v, w, scale, nearest, reason = v_in, w_in, 1.0, least - moved, "clear"
            else:
                assert self._scan is not None
                points = to_frame(points_of(self._scan, self.laser_offset_x).xy, scan_pose, pose)
                r = safe_command(v_in, w_in, v0, w0, points, p)
                v, w, scale, nearest, reason = r.v, r.omega, r.scale, r.nearest, r.reason
        await self.cmd_out.publish(
            _STOP
            if v == 0.0 and w == 0.0
            else Twist.fast(
                linear=Vector3.fast(x=v, y=0.0, z=0.0),
                angular=Vector3.fast(x=0.0, y=0.0, z=w),
            )
        )
        # /safety/state when what the layer does changes (the reason, or the command it
        # sends differing from the one it got), and once a second: one message per
        # period cost ~4 % of the stack's time for no news (Nav2's collision monitor
        # also reports actions, not every cycle).
        changed = (reason, v == v_in and w == w_in) != self._last_report
        if not changed and now - self._reported_at < self.report_period - 1e-9:
            return
        self._last_report = (reason, v == v_in and w == w_in)
        self._reported_at = now
        if math.isnan(nearest):
            nearest = self._nearest_return() - clear_moved
        await self.state.publish(
            SafetyState.fast(
                header=Header.fast(stamp=Time.from_seconds(now), frame_id="base_link"),
                reason=reason,
                scale=scale,
                nearest=nearest,
                v_in=v_in,
                omega_in=w_in,
                v_out=v,
                omega_out=w,
            )
        )
