"""The judge: watches ground truth (which no robot actor may see) and scores the run."""

from __future__ import annotations

import math
from collections.abc import Callable

from otonav.actors import topics
from otonav.hal import BoxObstacle, RobotHardwareInterface
from otonav.msgs import NavDiagnostics, NavState
from otonav.runtime import Actor, Input, QoS, Reliability


class Judge(Actor):
    """Samples the true pose at ``rate_hz``: distance to goal, clearance to every
    obstacle and wall (robot centre to box surface), path length, first time within
    tolerance of the goal. It also follows the navigator's /nav/state (every message
    since the last sample, so a short-lived state is not missed): the latest state, and
    the first sim time the navigator declared the goal ``unreachable``. It calls
    ``progress(judge, sim_time)`` after each sample (a UI's hook; it must not act on
    the robot)."""

    # depth 16: /nav/state comes at 20 Hz and the judge drains it at rate_hz (100 Hz).
    nav_state_in = Input(topics.NAV_STATE, NavState, QoS(Reliability.BEST_EFFORT, depth=16))
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
        name: str = "judge",
    ) -> None:
        super().__init__(name)
        self.progress = progress
        self.nav_state = "starting"
        self.nav_reason = ""
        """The navigator's latest reason (/nav/diagnostics; empty for the stop planner)."""
        self.hal = hal
        self.goal = goal
        self.tolerance = tolerance
        self.rate_hz = rate_hz
        self.boxes: tuple[BoxObstacle, ...] = hal.obstacles() + hal.walls()
        self.min_clearance = math.inf
        self.min_clearance_at: tuple[float, float] = (math.nan, math.nan)
        self.path_length = 0.0
        self.distance = math.inf
        self.time_to_goal: float | None = None
        self.unreachable_at: float | None = None
        """s of sim time when /nav/state first said ``unreachable``; None if never."""
        self.samples = 0
        self.trajectory: list[tuple[float, float, float]] = []
        self._last: tuple[float, float] | None = None

    @property
    def reached(self) -> bool:
        return self.time_to_goal is not None

    @property
    def gave_up(self) -> bool:
        """The navigator declared the goal unreachable."""
        return self.unreachable_at is not None

    @property
    def finished(self) -> bool:
        """Nothing more will happen worth waiting for: reached, or given up."""
        return self.reached or self.gave_up

    def _follow_nav_state(self, now: float) -> None:
        while (state := self.nav_state_in.try_recv()) is not None:
            self.nav_state = state.state
            if self.unreachable_at is None and state.state == "unreachable":
                self.unreachable_at = now
        diag = self.nav_diag_in.take_latest()
        if diag is not None:
            self.nav_reason = diag.reason

    def sample(self, now: float) -> None:
        truth = self.hal.ground_truth()
        x, y = truth.x, truth.y
        self.samples += 1
        self.trajectory.append((now, x, y))
        if self._last is not None:
            self.path_length += math.hypot(x - self._last[0], y - self._last[1])
        self._last = (x, y)
        self.distance = math.hypot(self.goal[0] - x, self.goal[1] - y)
        if self.time_to_goal is None and self.distance <= self.tolerance:
            self.time_to_goal = now
        for box in self.boxes:
            d = box.distance_to(x, y)
            if d < self.min_clearance:
                self.min_clearance = d
                self.min_clearance_at = (x, y)

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
