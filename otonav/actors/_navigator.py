"""The navigators' shared skeleton, and the stop-only one: go-to-goal with an obstacle
guard. /odom + /scan + /goal -> /cmd_vel (+ /nav/state)."""

from __future__ import annotations

import logging
import math

import numpy as np
from numpy.typing import NDArray

from otonav.actors import _topics as topics
from otonav.control import Pose2D
from otonav.msgs import (
    HardwareStatus,
    Header,
    LaserScan,
    NavState,
    Odometry,
    PoseStamped,
    Time,
    Twist,
    Vector3,
)
from otonav.nav import GoToGoalParams, GuardParams, go_to_goal, goal_problem, guard_blocked
from otonav.params import NavConfig
from otonav.runtime import Actor, Input, Output

_log = logging.getLogger(__name__)

RATE_HZ = NavConfig().rate_hz
"""A navigator's default rate (``nav.rate_hz``'s), Hz."""
SCAN_TIMEOUT = 0.5
"""s of sim time without /scan before a navigator stops driving forward (blind)."""
NAME = "nav"
"""The navigator's node name: the stack's ``nav`` actor."""

STOP = Twist.fast(
    linear=Vector3.fast(x=0.0, y=0.0, z=0.0), angular=Vector3.fast(x=0.0, y=0.0, z=0.0)
)
"""(0, 0): messages are immutable and shared, so one object serves every stop."""


class GoalNavigator(Actor):
    """What every navigator does around its decision: the ports, and at ``rate_hz`` the
    inputs in a fixed order (odometry, goal, hardware status, scan) then one
    :meth:`_step`, which publishes /cmd_vel and /nav/state (:meth:`_publish_command`).
    Subclasses say what each input means to them (the ``_take_*`` hooks)."""

    frame_id = "odom"
    """The frame the navigator works in (poses, goal; the header of /nav/state)."""

    odom = Input(topics.ODOM, Odometry, topics.SENSOR_QOS)
    scan = Input(topics.SCAN, LaserScan, topics.SENSOR_QOS)
    goal_in = Input(topics.GOAL, PoseStamped, topics.LATCHED)
    hardware = Input(topics.HARDWARE_STATUS, HardwareStatus, topics.HARDWARE_QOS)
    cmd_vel = Output(topics.CMD_VEL, Twist, topics.COMMAND_QOS)
    state = Output(topics.NAV_STATE, NavState, topics.COMMAND_QOS)

    def __init__(
        self, *, rate_hz: float, scan_timeout: float, name: str, remap: dict[str, str] | None
    ) -> None:
        super().__init__(name, remap=remap)
        if not rate_hz > 0:
            raise ValueError(f"nav.rate_hz must be > 0 Hz, got {rate_hz}")
        self.rate_hz = rate_hz
        self.scan_timeout = scan_timeout
        self._hardware_fault = False
        self._scan_time = -math.inf
        self.refused_goals = 0
        """Goals on /goal it would not drive to (:func:`~otonav.nav.goal_problem`); the
        door refuses them first (``otonav.stack._door``): this is defence in depth."""

    async def run(self) -> None:
        rate = self.clock.rate(self.rate_hz)
        while True:
            await rate.sleep()
            self._take_odometry()
            goal_msg = self.goal_in.take_latest()
            if goal_msg is not None:
                self._check_goal(goal_msg.pose.position.x, goal_msg.pose.position.y)
            status = self.hardware.take_latest()
            if status is not None:
                self._hardware_fault = status.faulted
            scan = self.scan.take_latest()
            if scan is not None and self._take_scan(scan):
                self._scan_time = self.clock.now()
            await self._step()

    def _check_goal(self, x: float, y: float) -> None:
        """Take the goal at (x, y), or refuse it and keep the one it had."""
        problem = goal_problem(x, y)
        if problem is None:
            self._take_goal((x, y))
            return
        self.refused_goals += 1
        if self.refused_goals == 1:  # once: later ones are counted (refused_goals)
            _log.warning("%s: refused a goal on %s: %s", self.name, topics.GOAL, problem)

    def _take_odometry(self) -> None:
        raise NotImplementedError

    def _take_goal(self, goal: tuple[float, float]) -> None:
        raise NotImplementedError

    def _take_scan(self, scan: LaserScan) -> bool:
        """Take ``scan``; False when it could not be used (it does not count as fresh)."""
        raise NotImplementedError

    def _blind(self, now: float) -> bool:
        """No scan taken yet, or none for ``scan_timeout`` s: the way ahead is unknown."""
        return now - self._scan_time > self.scan_timeout

    async def _step(self) -> None:
        raise NotImplementedError

    async def _publish_command(
        self,
        stamp: Time,
        v: float,
        omega: float,
        state: str,
        distance: float,
        heading_error: float,
        closest: float,
    ) -> Header:
        """/cmd_vel and /nav/state; the header it stamped them with."""
        header = Header.fast(stamp=stamp, frame_id=self.frame_id)
        await self.cmd_vel.publish(
            STOP
            if v == 0.0 and omega == 0.0
            else Twist.fast(
                linear=Vector3.fast(x=v, y=0.0, z=0.0),
                angular=Vector3.fast(x=0.0, y=0.0, z=omega),
            )
        )
        if self.state.get_subscription_count():  # none in a run without a recorder
            await self.state.publish(
                NavState.fast(
                    header=header,
                    state=state,
                    distance_to_goal=distance,
                    heading_error=heading_error,
                    closest_ahead=closest,
                )
            )
        return header


class Navigator(GoalNavigator):
    """At ``rate_hz``: drive toward the goal (turn, then drive; P-control) and stop when
    a valid return inside the guard's front sector is closer than its stop distance.

    The goal comes from ``/goal`` (latched) or ``goal=(x, y)``; the newest wins. With no
    scan yet, or none for ``scan_timeout`` s of sim time, it will not drive forward
    (the guard fails safe): its state is then ``waiting``.
    Publishes /cmd_vel and /nav/state (idle | driving | blocked | reached | fault).
    While /hardware/status reports a fault it commands zero and its state is ``fault``.
    """

    def __init__(
        self,
        params: GoToGoalParams = GoToGoalParams(),
        guard: GuardParams = GuardParams(),
        *,
        rate_hz: float = RATE_HZ,
        goal: tuple[float, float] | None = None,
        scan_timeout: float = SCAN_TIMEOUT,
        name: str = NAME,
        remap: dict[str, str] | None = None,
    ) -> None:
        super().__init__(rate_hz=rate_hz, scan_timeout=scan_timeout, name=name, remap=remap)
        self.params = params
        self.guard = guard
        self.goal = goal
        self._odom: Odometry | None = None
        self._scan: LaserScan | None = None
        self._ranges: NDArray[np.float32] = np.empty(0, np.float32)

    def _take_odometry(self) -> None:
        self._odom = self.odom.take_latest() or self._odom

    def _take_goal(self, goal: tuple[float, float]) -> None:
        self.goal = goal

    def _take_scan(self, scan: LaserScan) -> bool:
        self._scan = scan
        self._ranges = np.asarray(scan.ranges, dtype=np.float32)
        return True

    async def _step(self) -> None:
        odom = self._odom
        stamp = Time.from_seconds(self.clock.now())
        if self._hardware_fault:
            await self._publish_command(stamp, 0.0, 0.0, "fault", math.inf, 0.0, math.inf)
            return
        if odom is None or self.goal is None:
            await self._publish_command(stamp, 0.0, 0.0, "idle", math.inf, 0.0, math.inf)
            return
        p = odom.pose.pose
        pose = Pose2D(p.position.x, p.position.y, p.orientation.yaw())
        command = go_to_goal(pose, self.goal[0], self.goal[1], self.params)
        closest = math.inf
        blocked = False
        blind = self._blind(self.clock.now())  # fail safe
        if self._scan is not None:
            blocked, closest = guard_blocked(
                self._ranges,
                self._scan.angle_min,
                self._scan.angle_increment,
                self.guard,
                range_min=self._scan.range_min,
                range_max=self._scan.range_max,
            )
        if command.reached:
            state, v, omega = "reached", 0.0, 0.0
        elif blocked and command.v > 0:
            state, v, omega = "blocked", 0.0, 0.0
        elif blind and command.v > 0:
            state, v, omega = "waiting", 0.0, 0.0
        else:
            state, v, omega = "driving", command.v, command.omega
        await self._publish_command(
            stamp, v, omega, state, command.distance, command.heading_error, closest
        )
