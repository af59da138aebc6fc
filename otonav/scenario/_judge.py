"""The judge: watches ground truth (which no robot actor may see) and scores the run."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Literal

from otonav.actors import _topics as topics
from otonav.hal import BoxObstacle, RobotHardwareInterface
from otonav.msgs import NavDiagnostics, NavState, Odometry
from otonav.runtime import Actor, Input, QoS, Reliability
from otonav.scenario._clearance import ClearanceTracker
from otonav.scenario._config import ScenarioConfig

_SCENARIO = ScenarioConfig()
#: s of sim time the judge keeps watching after the robot first enters the tolerance.
ARRIVAL_SETTLE_S = 2.0
#: m/s: the true speed below which the robot counts as stopped at the goal.
ARRIVAL_MAX_SPEED = 0.02
#: The most samples of the true path the judge keeps for the plot (:attr:`Judge.trajectory`).
TRAIL_POINTS = 8192


class Judge(Actor):
    """Samples the true pose at ``rate_hz``: distance to goal, clearance to every
    obstacle and wall (robot centre to box surface), path length, first time within
    tolerance of the goal. It also follows the navigator's /nav/state (every message
    since the last sample, so a short-lived state is not missed): the latest state, and
    the first sim time the navigator declared the goal ``unreachable``. It calls
    ``progress(judge, sim_time)`` after each sample (a UI's hook; it must not act on
    the robot).

    Arrival (issue 16): entering the tolerance is not arriving. ``settle_s`` after the
    first entry (``time_to_goal``) the judge checks, on ground truth, that the robot is
    still within the tolerance, its true speed is below ``max_speed``, and the navigator
    says ``reached``; ``reached`` is True only then. A robot that drives through the
    goal fails, and ``arrival_problem`` says why. With ``nav_must_say_reached=False``
    (``nav.planner: external``: a ROS 2 planner publishes no ``otonav_msgs/NavState``,
    issue 37) arrival is judged on ground truth alone: within the tolerance and stopped.
    """

    # depth 16: /nav/state comes at 20 Hz and the judge drains it at rate_hz (100 Hz).
    nav_state_in = Input(topics.NAV_STATE, NavState, QoS(Reliability.BEST_EFFORT, depth=16))
    odom_in = Input(topics.ODOM, Odometry, topics.SENSOR_QOS)
    """Where odometry puts the robot (its frame is the world's: it starts at the start
    pose), against the truth when the navigator says ``reached``: wheel slip."""
    # The planner's reason (why it gave up, what it avoids): the latest is enough.
    nav_diag_in = Input(
        topics.NAV_DIAGNOSTICS, NavDiagnostics, QoS(Reliability.BEST_EFFORT, depth=1)
    )

    def __init__(
        self,
        hal: RobotHardwareInterface,
        goal: tuple[float, float],
        tolerance: float,
        *,
        rate_hz: float = 100.0,
        progress: Callable[[Judge, float], None] | None = None,
        settle_s: float = ARRIVAL_SETTLE_S,
        max_speed: float = ARRIVAL_MAX_SPEED,
        nav_must_say_reached: bool = True,
        arrival: Literal["stop", "enter"] = _SCENARIO.arrival,
        name: str = "judge",
    ) -> None:
        super().__init__(name)
        self.arrival = arrival
        """``stop`` (the arrival check above) or ``enter`` (BARN's criterion: the first
        entry into the tolerance is arriving; issue 42)."""
        self.nav_must_say_reached = nav_must_say_reached
        self.settle_s = settle_s
        self.max_speed = max_speed
        self.arrival_checked_at: float | None = None
        """s of sim time of the arrival check (``settle_s`` after the first entry)."""
        self.arrival_problem: str | None = None
        """Why the arrival check failed (None: passed, or not checked yet)."""
        self.speed = 0.0
        """m/s, the true speed at the latest sample."""
        self.progress = progress
        self.nav_state = "starting"
        self.nav_reason = ""
        """The navigator's latest reason (/nav/diagnostics; empty for the stop planner)."""
        self.recoveries: list[str] = []
        """Each recovery rung the navigator ran, as it began: ``spin at 12.3 s (rung
        1/3, under 0.3 m of progress along the path in 3.5 s)`` (/nav/diagnostics'
        stage and reason; issue 24: the verdict says which rung ran and why)."""
        self._stage = ""
        self.slips: list[str] = []
        self._odom: Odometry | None = None
        """Each time the navigator said ``reached`` while the true pose was farther than
        the tolerance from the goal: its odometry and the truth had parted (wheel slip)."""
        self.hal = hal
        self.goal = goal
        self.tolerance = tolerance
        self.rate_hz = rate_hz
        self.boxes: tuple[BoxObstacle, ...] = hal.obstacles() + hal.walls()
        self.rounds = hal.round_obstacles()
        self.polygons = hal.polygon_obstacles()
        self._clearance = ClearanceTracker(self.boxes, self.rounds, self.polygons)
        self.min_clearance = math.inf
        self.min_clearance_at: tuple[float, float] = (math.nan, math.nan)
        self.path_length = 0.0
        self.distance = math.inf
        self.time_to_goal: float | None = None
        self.unreachable_at: float | None = None
        """s of sim time when /nav/state first said ``unreachable``; None if never."""
        self.hardware_fault: str | None = None
        """A permanent hardware fault (``HardwareHealth.permanent``), as the verdict's
        reason: the run ends on it (issue 27). None: none."""
        self.samples = 0
        self._trail: list[tuple[float, float, float]] = []
        self._stride = 1  # keep every stride-th sample (doubles as the trail fills)
        self._latest: tuple[float, float, float] | None = None
        self._last: tuple[float, float] | None = None

    @property
    def trajectory(self) -> list[tuple[float, float, float]]:
        """(t, x, y) of the true path, for the plot: every sample of a run up to
        :data:`TRAIL_POINTS` samples; past that every second kept one is dropped, and
        from then on one sample in two (then four, ...) is kept, so a long run holds at
        most that many (a 1,200 s run held 120,000: ~14 KB per sim second, issue 41).
        The latest sample always ends it."""
        trail, latest = self._trail, self._latest
        if latest is None or (trail and trail[-1] is latest):
            return list(trail)
        return [*trail, latest]

    @property
    def entered(self) -> bool:
        """The robot has been within the tolerance of the goal (at ``time_to_goal``)."""
        return self.time_to_goal is not None

    @property
    def reached(self) -> bool:
        """Arrived: within the tolerance, stopped, and (unless the planner is external)
        the navigator said ``reached``, ``settle_s`` after first entering the tolerance."""
        return self.arrival_checked_at is not None and self.arrival_problem is None

    @property
    def gave_up(self) -> bool:
        """The navigator declared the goal unreachable."""
        return self.unreachable_at is not None

    @property
    def finished(self) -> bool:
        """Nothing more will happen worth waiting for: the arrival checked, given up, or
        a permanent hardware fault."""
        return (
            self.arrival_checked_at is not None or self.gave_up or self.hardware_fault is not None
        )

    @property
    def clearance_problem(self) -> str | None:
        """Why the clearance was not measured (static geoms of a shape the judge cannot
        measure: a tilted cylinder, an ellipsoid); None: every static geom was measured. A
        clearance never measured is not a pass (issue 42)."""
        unjudged = self.hal.unjudged_geoms()
        if not unjudged:
            return None
        more = f" and {len(unjudged) - 5} more" if len(unjudged) > 5 else ""
        return (
            f"clearance not measured: the judge measures boxes, upright cylinders and "
            f"capsules, spheres and meshes, not {', '.join(unjudged[:5])}{more}"
        )

    def _entered(self, now: float) -> None:
        """The first entry into the tolerance: with ``arrival: enter`` that is arriving."""
        self.time_to_goal = now
        if self.arrival == "enter":
            self.arrival_checked_at = now

    def _check_arrival(self, now: float) -> None:
        problems = []
        if self.distance > self.tolerance:
            problems.append(f"{self.distance:.3f} m from the goal")
        if self.speed > self.max_speed:
            problems.append(f"moving at {self.speed:.2f} m/s")
        needs = f"<= {self.tolerance} m, < {self.max_speed} m/s"
        if self.nav_must_say_reached:
            needs += " and /nav/state 'reached'"
            if self.nav_state != "reached":
                problems.append(f"/nav/state '{self.nav_state}'")
        self.arrival_checked_at = now
        if problems:
            self.arrival_problem = (
                f"entered the goal tolerance at {self.time_to_goal:.2f} s but had not "
                f"arrived {self.settle_s:g} s later: {', '.join(problems)} (needs {needs})"
            )

    def _follow_nav_state(self, now: float) -> None:
        while (state := self.nav_state_in.try_recv()) is not None:
            if state.state == "reached" and self.nav_state != "reached":
                self._check_slip(now)
            self.nav_state = state.state
            if self.unreachable_at is None and state.state == "unreachable":
                self.unreachable_at = now
        diag = self.nav_diag_in.take_latest()
        if diag is not None:
            self.nav_reason = diag.reason
            if diag.stage and diag.stage != self._stage:
                why = diag.reason.removeprefix(f"{diag.stage}: ")
                self.recoveries.append(f"{diag.stage} at {now:.1f} s ({why})")
            self._stage = diag.stage

    def _check_slip(self, now: float) -> None:
        """The navigator says ``reached`` from its odometry: where odometry puts the robot
        must agree with the truth, to within the goal tolerance. (Not the truth's distance
        to the goal: a navigator told a wider tolerance stops early without any slip.)"""
        odom = self.odom_in.take_latest()
        if odom is not None:
            self._odom = odom
        if self._odom is None:
            return
        x, y, _, _ = self.hal.planar_truth()
        at = self._odom.pose.pose.position
        parted = math.hypot(at.x - x, at.y - y)
        if parted > self.tolerance:
            truth = math.hypot(self.goal[0] - x, self.goal[1] - y)
            self.slips.append(
                f"odometry says reached at {now:.1f} s; ground truth is {truth:.2f} m away "
                f"({parted:.2f} m from where odometry puts the robot): wheel slip"
            )

    def sample(self, now: float) -> None:
        x, y, vx, vy = self.hal.planar_truth()
        self.samples += 1
        self._latest = point = (now, x, y)
        if self.samples % self._stride == 0:
            trail = self._trail
            trail.append(point)
            if len(trail) > TRAIL_POINTS:
                del trail[1::2]  # the first stays; the latest is kept apart
                self._stride *= 2
        if self._last is not None:
            self.path_length += math.hypot(x - self._last[0], y - self._last[1])
        self._last = (x, y)
        self.distance = math.hypot(self.goal[0] - x, self.goal[1] - y)
        self.speed = math.hypot(vx, vy)
        if self.time_to_goal is None and self.distance <= self.tolerance:
            self._entered(now)
        if (
            self.time_to_goal is not None
            and self.arrival_checked_at is None
            and now >= self.time_to_goal + self.settle_s - 1e-9
        ):
            self._check_arrival(now)
        # Exact, at a cost that does not grow with the box count (scenario/clearance.py).
        clearance = self._clearance
        clearance.update(x, y)
        self.min_clearance = clearance.min_clearance
        self.min_clearance_at = clearance.min_clearance_at
        if self.hardware_fault is None:
            health = self.hal.health()
            if health.permanent:
                self.hardware_fault = (
                    f"hardware fault (permanent) at {health.since:.2f} s: "
                    f"{health.fault}: {health.message}"
                )

    async def on_start(self) -> None:
        self.sample(self.clock.now())

    async def run(self) -> None:
        rate = self.clock.rate(self.rate_hz)
        while True:
            await rate.sleep()
            now = self.clock.now()
            self._follow_nav_state(now)
            self.sample(now)
            if self.progress is not None:
                self.progress(self, now)
