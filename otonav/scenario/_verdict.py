"""A scenario run's verdict: what the judge saw, judged against what the scenario
expects (:func:`judge_verdict`), and how it reads (a plot's title, JSON-safe figures)."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from otonav.hal import RobotHardwareInterface
from otonav.scenario._config import ScenarioConfig
from otonav.scenario._judge import Judge
from otonav.stack import StackConfig
from otonav.stack._robot import describe_robot, reached

_SCENARIO = ScenarioConfig()


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
    recording: str | None = None
    plot: str | None = None
    expect: str = _SCENARIO.expect
    """The scenario's expected outcome: ``reached`` or ``unreachable``."""
    unreachable_at_s: float | None = None
    """s of sim time when the navigator reported the goal unreachable; None if never."""
    nav_state: str = ""
    """The navigator's last /nav/state (e.g. reached, unreachable)."""
    nav_reason: str = ""
    """The navigator's last reason (/nav/diagnostics), e.g. why it gave up."""
    recoveries: list[str] = field(default_factory=list)
    """The recovery rungs the navigator ran, in order, each with when and why (e.g.
    ``spin at 12.3 s (rung 1/3, under 0.3 m of progress along the path in 3.5 s)``);
    the reason names them too."""
    sim_budget_s: float = 0.0
    """s of sim time the scenario allowed (scaled to the robot's speed: ``for_robot``)."""
    clearance_floor_m: float = 0.0
    """m: the scenario's ``min_clearance``, the floor ``min_clearance_m`` is judged on."""
    closest_xy: list[float] | None = None
    """[x, y] where the robot came closest to an obstacle (world frame, m; a list, as it
    reads back from JSON); None if nowhere."""
    robot: dict[str, Any] = field(default_factory=dict)
    """The robot as run: model, top speeds, the geometry values and where each came
    from (:func:`robot_summary`)."""

    def as_dict(self) -> dict[str, object]:
        return asdict(self)


def finite_figures(figures: dict[str, Any]) -> dict[str, Any]:
    """JSON has no Infinity or NaN: a figure that is not finite becomes null."""
    return {
        k: None if isinstance(v, float) and not math.isfinite(v) else v for k, v in figures.items()
    }


TITLE_REASON_WIDTH = 64
"""Characters per line of the verdict's reason in a plot's title (two lines at most)."""


def verdict_title(scenario: str, passed: bool, reason: str) -> str:
    """A plot's title that tells the verdict: the scenario, PASSED or FAILED, and why."""
    import textwrap

    why = textwrap.wrap(reason, TITLE_REASON_WIDTH, max_lines=2, placeholder=" …")
    return "\n".join([f"{scenario}: {'PASSED' if passed else 'FAILED'}", *why])


def robot_summary(stack: StackConfig, hal: RobotHardwareInterface) -> dict[str, Any]:
    """What the verdict says about the robot: which model, its top speeds, each
    geometry value and where it came from (derived from the model, or given)."""
    robot = describe_robot(stack.robot)
    g = hal.geometry
    return {
        "model": robot.label,
        "max_v": robot.max_v,
        "max_omega": robot.max_omega,
        "wheel_radius": g.wheel_radius,
        "wheel_separation": g.wheel_separation,
        "footprint_radius": g.footprint_radius,
        "laser_offset": [g.laser_offset_x, g.laser_offset_z],
        "reach": asdict(reach) if (reach := reached(stack, hal)) is not None else None,
        "sources": hal.geometry_sources(),
        "warnings": lidar_over_obstacles(hal),
    }


def lidar_over_obstacles(hal: RobotHardwareInterface) -> list[str]:
    """A lidar above the tallest obstacle sees none of them (issue 38): a warning."""
    g, top = hal.geometry, hal.tallest_obstacle()
    height = g.base_height + g.laser_offset_z
    if top is None or height < top:
        return []
    return [
        f"warning: the lidar is {height:.2f} m above the floor, over the tallest obstacle "
        f"({top:.2f} m): it sees none of them; mount it lower (robot.lidar)"
    ]


def judge_verdict(
    scenario: ScenarioConfig,
    judge: Judge,
    sim_time: float,
    wall: float,
    *,
    robot: dict[str, Any] | None = None,
) -> Verdict:
    """Pass when the scenario's expected outcome happened (``expect``: the goal reached,
    or the navigator's ``unreachable`` inside the budget) and the clearance held."""
    unmeasured = judge.clearance_problem
    clear = judge.min_clearance >= scenario.min_clearance and unmeasured is None
    gave_up = judge.unreachable_at is not None and judge.unreachable_at <= scenario.sim_budget
    reasons = []
    if scenario.expect == "reached":
        outcome = judge.reached
        if judge.arrival_problem is not None:
            reasons.append(judge.arrival_problem)
        elif not judge.reached:
            why = (
                f"the navigator reported the goal unreachable at {judge.unreachable_at:.1f} s"
                + (f" ({judge.nav_reason})" if judge.nav_reason else "")
                if judge.unreachable_at is not None
                else f"did not reach the goal within {scenario.sim_budget:g} s"
            )
            reasons.append(
                f"{why} (ended {judge.distance:.3f} m away; tolerance {scenario.goal_tolerance} m)"
            )
    else:
        outcome = gave_up and not judge.reached
        if judge.reached:
            reasons.append("reached a goal that was expected to be unreachable")
        elif not gave_up:
            reasons.append(
                f"the navigator did not report the goal unreachable within "
                f"{scenario.sim_budget:g} s (last state: {judge.nav_state})"
            )
    if judge.hardware_fault is not None and not judge.reached:
        outcome = False
        reasons[:] = [judge.hardware_fault]
    elif not outcome and (health := judge.hal.health()).faulted:
        # A fault that outlasted the run (e.g. encoder data late the whole time).
        reasons.append(
            f"hardware fault since {health.since:.2f} s: {health.fault}: {health.message}"
        )
    if unmeasured is not None:
        reasons.append(unmeasured)
    elif not clear:
        reasons.append(
            f"came {judge.min_clearance:.3f} m from an obstacle "
            f"(minimum {scenario.min_clearance} m)"
        )
    if not reasons:
        reasons.append(
            "reached the goal with clearance"
            if scenario.expect == "reached"
            else f"reported unreachable at {judge.unreachable_at:.1f} s, as expected, "
            "with clearance"
        )
    reasons.extend(judge.slips)
    reasons.extend((robot or {}).get("warnings", ()))
    if judge.recoveries:
        reasons.append(f"recoveries: {'; '.join(judge.recoveries)}")
    return Verdict(
        scenario=scenario.name,
        passed=outcome and clear,
        reached=judge.reached,
        reason="; ".join(reasons),
        time_to_goal_s=judge.time_to_goal,
        min_clearance_m=judge.min_clearance,
        final_distance_m=judge.distance,
        path_length_m=judge.path_length,
        sim_time_s=sim_time,
        wall_time_s=wall,
        rtf=sim_time / wall if wall > 0 else math.inf,
        expect=scenario.expect,
        unreachable_at_s=judge.unreachable_at,
        nav_state=judge.nav_state,
        nav_reason=judge.nav_reason,
        recoveries=list(judge.recoveries),
        sim_budget_s=scenario.sim_budget,
        clearance_floor_m=scenario.min_clearance,
        closest_xy=list(judge.min_clearance_at) if judge.min_clearance_at else None,
        robot=robot or {},
    )
