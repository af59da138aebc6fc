"""Localization over a long run: pose error on ground truth, false ``reached``, and the
localizer's cost per scan.

    python benchmarks/localization_bench.py [--distance 100] [--gyro-bias 0.005]
        [--scale 0.01] [--gyro-noise 0.01] [--seed 0]

The robot drives a route of waypoints, lap after lap, through the built-in
``cluttered`` world (twelve boxes in the 10 x 10 m arena) until it has driven
``--distance`` m (on ground truth), then finishes at the next waypoint. Three runs:
odometry as simulated (no injected error, no localization), injected odometry error
without localization, and the same error with localization on (``nav.localization``).
For each: metres driven, sim time, the pose error at the end and its median and
maximum along the way (position, m; yaw, deg; the navigator's pose against ground
truth, sampled at every scan), the waypoints the navigator called ``reached`` and how
many of those were false (the robot's true centre farther than the scenarios'
0.15 m tolerance from the waypoint), whether the navigator gave up (``unreachable``:
the run then ends), the RTF, and with localization the CPU time of
one localizer update (match + map update) per scan: median, p99, max. Last, the wall
time of the built-in ``cluttered`` scenario with localization on over off (``--reps``
runs each, interleaved).
"""

from __future__ import annotations

import argparse
import asyncio
import math
import statistics
import time
from dataclasses import dataclass, field
from typing import Any

from otonav.actors import topics
from otonav.actors._localizer import Localizer
from otonav.hal import RobotHardwareInterface
from otonav.msgs import Header, NavState, Point, Pose, PoseStamped, Time
from otonav.nav._geometry import wrap_angle
from otonav.runtime import (
    LATCHED_QOS,
    Actor,
    Input,
    Output,
    QoS,
    Reliability,
    until,
    virtual_loop_factory,
)
from otonav.scenario import run_scenario
from otonav.scenario._assembly import scenario_world
from otonav.scenario._builtin import CLUTTERED
from otonav.stack import StackConfig, build_actors
from otonav.stack._session import StackSession

ROUTE = ((4.2, 0.3), (3.5, 3.5), (-3.5, 3.5), (-3.5, -3.5), (3.5, -3.5), (-4.0, 0.0))
"""Waypoints of one lap (m, world = map frame), from the start (-4, 0) of ``cluttered``."""
JUDGE_TOLERANCE = 0.15
"""m: the scenarios' goal tolerance on ground truth."""


@dataclass
class Figures:
    driven: float = 0.0
    errors: list[float] = field(default_factory=list)
    yaw_errors: list[float] = field(default_factory=list)
    reached: int = 0
    false_reached: list[float] = field(default_factory=list)
    costs: list[float] = field(default_factory=list)
    done: bool = False
    gave_up: str = ""


class Route(Actor):
    """Publishes the route's waypoints on /goal one after another: the next once
    /nav/state says ``reached`` (after it said something else for this one); checks
    each ``reached`` on ground truth; stops after ``distance`` m driven."""

    state_in = Input(topics.NAV_STATE, NavState, QoS(Reliability.BEST_EFFORT, depth=16))
    goal_out = Output(topics.GOAL, PoseStamped, LATCHED_QOS)

    def __init__(self, hal: RobotHardwareInterface, figures: Figures, distance: float) -> None:
        super().__init__("route")
        self.hal, self.figures, self.distance = hal, figures, distance
        self._last: tuple[float, float] | None = None

    async def run(self) -> None:
        i = 0
        await self._publish(ROUTE[0])
        left = False
        rate = self.clock.rate(100.0)
        while True:
            await rate.sleep()
            x, y, _, _ = self.hal.planar_truth()
            if self._last is not None:
                self.figures.driven += math.hypot(x - self._last[0], y - self._last[1])
            self._last = (x, y)
            for state in self.state_in.drain():
                if state.state == "unreachable":  # lost: its map smeared by the drift
                    self.figures.gave_up = f"unreachable at {self.clock.now():.0f} s"
                    self.figures.done = True
                    return
                if state.state != "reached":
                    left = True
                    continue
                if not left:
                    continue
                gx, gy = ROUTE[i % len(ROUTE)]
                self.figures.reached += 1
                miss = math.hypot(gx - x, gy - y)
                if miss > JUDGE_TOLERANCE:
                    self.figures.false_reached.append(miss)
                if self.figures.driven >= self.distance:
                    self.figures.done = True
                    return
                i += 1
                left = False
                await self._publish(ROUTE[i % len(ROUTE)])
                break

    async def _publish(self, goal: tuple[float, float]) -> None:
        await self.goal_out.publish(
            PoseStamped(
                header=Header(stamp=Time.from_seconds(self.clock.now()), frame_id="map"),
                pose=Pose(position=Point(x=goal[0], y=goal[1])),
            )
        )


def _probe(nav: Any, hal: RobotHardwareInterface, figures: Figures) -> None:
    """After each navigator step: its pose (odom, or map with localization) against
    ground truth."""
    step = nav._step

    async def probed() -> None:
        await step()
        latest = nav._history.latest
        if latest is None:
            return
        pose = nav._in_frame(latest[1])
        truth = hal.ground_truth()
        figures.errors.append(math.hypot(pose[0] - truth.x, pose[1] - truth.y))
        figures.yaw_errors.append(abs(math.degrees(wrap_angle(pose[2] - truth.yaw))))

    nav._step = probed


def _timed(localizer: Localizer, figures: Figures) -> None:
    update = localizer.update

    def timed(odom_pose: Any, points: Any) -> Any:
        start = time.perf_counter()
        try:
            return update(odom_pose, points)
        finally:
            figures.costs.append(time.perf_counter() - start)

    localizer.update = timed  # type: ignore[method-assign]


def run(stack: StackConfig, distance: float, budget: float) -> tuple[Figures, float, float]:
    scenario, stack, hal = scenario_world(CLUTTERED, stack, source="bench")
    figures = Figures()
    actors = build_actors(stack, hal, initial_pose=scenario.start.as_tuple())
    for actor in actors:
        if isinstance(actor, Localizer):
            _timed(actor, figures)
        if actor.name == "nav":
            _probe(actor, hal, figures)
    session = StackSession(hal, [*actors, Route(hal, figures, distance)])

    async def main() -> None:
        async with session.running():
            try:
                await until(lambda: figures.done, within=budget, what="the route")
            except Exception as exc:  # a run that does not finish still has figures
                print(f"  (ended early: {exc})")

    wall = time.perf_counter()
    with asyncio.Runner(loop_factory=virtual_loop_factory(wall_ceiling=3600.0)) as runner:
        runner.run(main())
        sim = runner.get_loop().time()
    return figures, sim, time.perf_counter() - wall


def cost_ratio(reps: int) -> None:
    """Wall time of the built-in ``cluttered`` scenario with localization on / off,
    interleaved in this process (the first run of each a discarded warm-up)."""
    off = StackConfig()
    on = StackConfig.model_validate({"nav": {"localization": {"enabled": True}}})
    walls: dict[str, list[float]] = {"off": [], "on": []}
    for rep in range(reps + 1):
        for label, stack in (("off", off), ("on", on)):
            verdict = run_scenario(CLUTTERED, stack, record=False, plot=False)
            if not verdict.passed:
                print(f"  cluttered with localization {label} failed: {verdict.reason}")
            if rep > 0:
                walls[label].append(verdict.wall_time_s)
    on_s, off_s = statistics.median(walls["on"]), statistics.median(walls["off"])
    print(
        f"'cluttered' wall median, localization on {on_s:.3f} s / off {off_s:.3f} s "
        f"= {on_s / off_s:.2f} ({reps} runs each, interleaved)"
    )


def _ms(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return 1e3 * ordered[min(len(ordered) - 1, math.ceil(q * len(ordered)) - 1)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--distance", type=float, default=100.0, help="m to drive")
    parser.add_argument("--gyro-bias", type=float, default=0.005, help="rad/s")
    parser.add_argument("--scale", type=float, default=0.01, help="distance scale error")
    parser.add_argument("--gyro-noise", type=float, default=0.01, help="rad/s per sample")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--reps", type=int, default=3, help="runs of the cost ratio")
    args = parser.parse_args()
    budget = args.distance / 0.1 + 60.0
    error = {
        "scale": args.scale,
        "gyro_bias": args.gyro_bias,
        "gyro_noise": args.gyro_noise,
        "seed": args.seed,
    }
    runs: tuple[tuple[str, dict[str, Any], bool], ...] = (
        ("odometry as simulated", {}, False),
        ("odometry error, no localization", error, False),
        ("odometry error, localization", error, True),
    )
    print(
        f"route: laps of {len(ROUTE)} waypoints in 'cluttered', >= {args.distance:g} m; "
        f"odometry error: {error}"
    )
    for label, odometry_error, localized in runs:
        stack = StackConfig.model_validate(
            {
                "world": {"odometry_error": odometry_error},
                "nav": {"localization": {"enabled": localized}},
            }
        )
        figures, sim, wall = run(stack, args.distance, budget)
        errors = figures.errors or [math.nan]
        yaws = figures.yaw_errors or [math.nan]
        print(
            f"{label:<34} driven {figures.driven:6.1f} m in {sim:6.1f} s sim  "
            f"pose error end {errors[-1]:.3f} m / {yaws[-1]:.2f} deg, "
            f"median {statistics.median(errors):.3f} m, max {max(errors):.3f} m  "
            f"reached {figures.reached}, false {len(figures.false_reached)}"
            + (f" (up to {max(figures.false_reached):.2f} m off)" if figures.false_reached else "")
            + (f"  gave up: {figures.gave_up}" if figures.gave_up else "")
            + f"  RTF {sim / wall:.1f}"
        )
        if figures.costs:
            print(
                f"{'':<34} localizer per scan ({len(figures.costs)} scans): median "
                f"{_ms(figures.costs, 0.5):.2f} ms, p99 {_ms(figures.costs, 0.99):.2f} ms, "
                f"max {1e3 * max(figures.costs):.2f} ms"
            )
    cost_ratio(args.reps)


if __name__ == "__main__":
    main()
