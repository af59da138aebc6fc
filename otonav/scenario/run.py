"""Run a scenario on a virtual-time loop driven by the physics world, and judge it."""

from __future__ import annotations

import asyncio
import contextlib
import math
import time
from dataclasses import asdict, dataclass

from otonav.actors import topics
from otonav.hal import RobotHardwareInterface
from otonav.msgs import Header, Point, Pose, PoseStamped, Time
from otonav.runtime import LATCHED_QOS, SimTimeoutError, System, until, virtual_loop_factory
from otonav.scenario.config import ScenarioConfig
from otonav.scenario.judge import Judge
from otonav.stack import StackConfig, build_actors, build_world


@dataclass(frozen=True, slots=True)
class Verdict:
    """The outcome of a scenario run (sim figures are from ground truth)."""

    scenario: str
    passed: bool
    reached: bool
    reason: str
    time_to_goal_s: float | None
    min_clearance_m: float
    final_distance_m: float
    path_length_m: float
    sim_time_s: float
    wall_time_s: float
    rtf: float

    def as_dict(self) -> dict[str, object]:
        return asdict(self)


async def run_stack_scenario(
    scenario: ScenarioConfig, stack: StackConfig, hal: RobotHardwareInterface
) -> tuple[Judge, System]:
    """Bring the stack up on ``hal``, publish the goal, wait (in sim time) until the
    robot reaches it or the budget runs out. Returns the judge and the stopped system."""
    judge = Judge(hal, (scenario.goal.x, scenario.goal.y), scenario.goal_tolerance)
    system = System([*build_actors(stack, hal), judge])
    async with system:
        goal = system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS, name="scenario")
        await goal.publish(
            PoseStamped(
                header=Header(stamp=Time.from_seconds(system.clock.now()), frame_id="odom"),
                pose=Pose(position=Point(x=scenario.goal.x, y=scenario.goal.y)),
            )
        )
        with contextlib.suppress(SimTimeoutError):
            await until(
                lambda: judge.reached,
                within=scenario.sim_budget,
                observe=lambda: f"{judge.distance:.3f} m from the goal",
                what=f"reaching the goal within {scenario.goal_tolerance} m",
            )
    return judge, system


def run_scenario(
    scenario: ScenarioConfig = ScenarioConfig(),
    stack: StackConfig = StackConfig(),
    *,
    wall_ceiling: float | None = 300.0,
) -> Verdict:
    """Run ``scenario`` headless in virtual time and judge it."""
    stack = stack.model_copy(
        update={"world": stack.world.model_copy(update={"scene": scenario.scene})}
    )
    hal = build_world(stack, extra_obstacles=[b.to_obstacle() for b in scenario.obstacles])
    wall_start = time.perf_counter()
    try:
        with asyncio.Runner(
            loop_factory=virtual_loop_factory(hal, wall_ceiling=wall_ceiling)
        ) as runner:
            judge, _system = runner.run(run_stack_scenario(scenario, stack, hal))
            sim_time = runner.get_loop().time()
    finally:
        hal.close()
    wall = time.perf_counter() - wall_start
    return judge_verdict(scenario, judge, sim_time, wall)


def judge_verdict(scenario: ScenarioConfig, judge: Judge, sim_time: float, wall: float) -> Verdict:
    clear = judge.min_clearance >= scenario.min_clearance
    reasons = []
    if not judge.reached:
        reasons.append(
            f"did not reach the goal within {scenario.sim_budget:g} s "
            f"(ended {judge.distance:.3f} m away; tolerance {scenario.goal_tolerance} m)"
        )
    if not clear:
        reasons.append(
            f"came {judge.min_clearance:.3f} m from an obstacle "
            f"(minimum {scenario.min_clearance} m)"
        )
    return Verdict(
        scenario=scenario.name,
        passed=judge.reached and clear,
        reached=judge.reached,
        reason="; ".join(reasons) or "reached the goal with clearance",
        time_to_goal_s=judge.time_to_goal,
        min_clearance_m=judge.min_clearance,
        final_distance_m=judge.distance,
        path_length_m=judge.path_length,
        sim_time_s=sim_time,
        wall_time_s=wall,
        rtf=sim_time / wall if wall > 0 else math.inf,
    )
