"""The judge: watches ground truth (which no robot actor may see) and scores the run."""

from __future__ import annotations

import math

from otonav.hal import BoxObstacle, RobotHardwareInterface
from otonav.runtime import Actor


class Judge(Actor):
    """Samples the true pose at ``rate_hz``: distance to goal, clearance to every
    obstacle and wall (robot centre to box surface), path length, first time within
    tolerance of the goal."""

    def __init__(
        self,
        hal: RobotHardwareInterface,
        goal: tuple[float, float],
        tolerance: float,
        *,
        rate_hz: float = 100.0,
        name: str = "judge",
    ) -> None:
        super().__init__(name)
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
        self.samples = 0
        self.trajectory: list[tuple[float, float, float]] = []
        self._last: tuple[float, float] | None = None

    @property
    def reached(self) -> bool:
        return self.time_to_goal is not None

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
            self.sample(self.clock.now())
