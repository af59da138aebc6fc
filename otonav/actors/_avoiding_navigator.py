"""The avoiding navigator: /odom + /scan + /goal -> /cmd_vel_nav (+ /nav/state,
/nav/diagnostics), through :class:`otonav.nav.Navigation` (map, A*, DWA, recovery)."""

from __future__ import annotations

import math

import numpy as np

from otonav.actors import _topics as topics
from otonav.actors._navigator import NAME, RATE_HZ, SCAN_TIMEOUT, GoalNavigator
from otonav.actors._odom_history import OdomHistory
from otonav.actors._scan_cache import odom_xy_of, points_of, rays_of
from otonav.msgs import LaserScan, NavDiagnostics, Time
from otonav.nav._navigate import Navigation, NavOutput
from otonav.nav._scan import to_frame
from otonav.params import NavigationParams
from otonav.runtime import Output

_AT_REST = frozenset({"idle", "waiting", "reached", "unreachable", "fault"})


class AvoidingNavigator(GoalNavigator):
    """At ``rate_hz``: record each new scan in the map (at the odometry pose of its
    stamp), then step :class:`~otonav.nav._navigate.Navigation`. Only /odom and /scan
    are used, never ground truth. With no scan yet, or none for ``scan_timeout`` s of
    sim time, it does not drive (state ``waiting``).

    Publishes its command on /cmd_vel (remapped to /cmd_vel_nav behind the safety
    layer) and /nav/state every step, /nav/diagnostics every step while moving (at
    rest: when the state or reason change). While /hardware/status reports a fault it
    commands zero and its state is ``fault``."""

    diagnostics = Output(topics.NAV_DIAGNOSTICS, NavDiagnostics, topics.COMMAND_QOS)

    def __init__(
        self,
        params: NavigationParams,
        *,
        laser_offset_x: float,
        start: tuple[float, float] = (0.0, 0.0),
        rate_hz: float = RATE_HZ,
        goal: tuple[float, float] | None = None,
        scan_timeout: float = SCAN_TIMEOUT,
        name: str = NAME,
        remap: dict[str, str] | None = None,
    ) -> None:
        super().__init__(rate_hz=rate_hz, scan_timeout=scan_timeout, name=name, remap=remap)
        self.laser_offset_x = laser_offset_x
        self.nav = Navigation(params, start)
        if goal is not None:
            self.nav.set_goal(goal)
        self._history = OdomHistory()
        self._scan: LaserScan | None = None
        self._points_pose: tuple[float, float, float] | None = None
        self._last_diag: tuple[str, str] | None = None

    live_parameters = frozenset(
        {"dwa.max_v", "dwa.max_omega", "dwa.max_accel", "dwa.max_alpha", "dwa.w_heading",
         "dwa.w_progress", "dwa.w_clearance", "dwa.w_speed", "dwa.latency", "tolerance"}
    )  # fmt: skip
    """What :class:`Navigation` reads every step: settable while it runs. (The map's size
    and resolution, the clearance radius and the progress checker are built once.)"""

    @property
    def params(self) -> NavigationParams:
        """What the navigation runs with; a new value takes effect at its next step (the
        live parameters: Foxglove's panel, ROS 2 parameter services)."""
        return self.nav.params

    @params.setter
    def params(self, value: NavigationParams) -> None:
        self.nav.params = value

    def _take_odometry(self) -> None:
        self._history.extend(self.odom.drain())

    def _take_goal(self, goal: tuple[float, float]) -> None:
        self.nav.set_goal(goal)

    def _in_frame(self, pose: tuple[float, float, float]) -> tuple[float, float, float]:
        """An odometry pose in :attr:`frame_id` (here: itself)."""
        return pose

    def _take_scan(self, scan: LaserScan) -> bool:
        pose = self._history.pose_at(scan.header.stamp.to_seconds())
        if pose is None:
            return False
        pose = self._in_frame(pose)
        moved = self._points_pose is None or (
            abs(pose[0] - self._points_pose[0]) + abs(pose[1] - self._points_pose[1]) > 1e-3
            or abs(pose[2] - self._points_pose[2]) > 1e-3
        )
        self._scan, self._points_pose = scan, pose
        # A static world seen from the same pose marks the same cells: skip the update
        # (and the points: at rest a scan costs nothing here).
        if moved:
            offset = self.laser_offset_x
            self.nav.observe(odom_xy_of(scan, offset, pose), lambda: rays_of(scan, offset, pose))
        return True

    async def _step(self) -> None:
        now = self.clock.now()
        latest = self._history.latest
        if latest is None:
            await self._publish(NavOutput(0.0, 0.0, "idle", "no odometry", math.inf, 0.0))
            return
        _, odom_pose, v0, omega0 = latest
        pose = self._in_frame(odom_pose)
        if self._hardware_fault:
            await self._publish(NavOutput(0.0, 0.0, "fault", "hardware fault", math.inf, 0.0))
            return
        if self._blind(now):
            out = self.nav.step(now, pose, v0, omega0, np.empty((0, 2)))
            if out.state not in ("idle", "reached", "unreachable"):
                out = NavOutput(0.0, 0.0, "waiting", "no fresh scan", out.distance, 0.0)
            await self._publish(out)
            return
        scan, scan_pose, offset = self._scan, self._points_pose, self.laser_offset_x
        assert scan is not None
        assert scan_pose is not None
        await self._publish(
            self.nav.step(
                now,
                pose,
                v0,
                omega0,
                lambda: to_frame(points_of(scan, offset).xy, scan_pose, pose),
            )
        )

    async def _publish(self, out: NavOutput) -> None:
        dwa = out.dwa
        closest = dwa.clearance if dwa is not None else math.inf
        header = await self._publish_command(
            Time.from_seconds(self.clock.now()),
            out.v,
            out.omega,
            out.state,
            out.distance,
            out.heading_error,
            closest,
        )
        # Diagnostics every step while it moves (driving, avoiding, recovering, blocked);
        # at rest (idle, waiting, reached, unreachable) when the state or reason change.
        key = (out.state, out.reason)
        if out.state in _AT_REST and key == self._last_diag:
            return
        self._last_diag = key
        if not self.diagnostics.get_subscription_count():  # none without a recorder
            return
        await self.diagnostics.publish(
            NavDiagnostics.fast(
                header=header,
                planner="dwa",
                state=out.state,
                reason=out.reason,
                stage=out.stage,
                v=out.v,
                omega=out.omega,
                admissible=dwa.admissible if dwa is not None else 0,
                samples=dwa.samples if dwa is not None else 0,
                best_score=dwa.best_score if dwa is not None else 0.0,
                clearance=closest,
                path_length=out.path_length,
                replans=out.replans,
            )
        )
