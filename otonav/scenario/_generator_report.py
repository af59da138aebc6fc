"""Scoring runs of generated worlds: one record per run, one row per family (what the
navigation benchmark prints, and what a sweep can reuse).

Definitions (issue 10's targets, BARN's metric):

- success: the goal reached within tolerance inside the budget, with the clearance kept
  (the scenario's verdict passed), counted over the *reachable* worlds;
- clearance violation: a run whose robot centre came closer than ``min_clearance`` to a
  box or wall, over *all* runs (walled-in included);
- BARN metric: mean over the reachable worlds of ``success * optimal / clip(actual,
  2 optimal, 8 optimal)`` (:func:`~otonav.scenario._generator.barn_metric`); 0.5 at
  best, so the median of ``actual / optimal`` over the successes is given too (it can
  dip under 1: the optimal path keeps footprint + clearance from every box, the judge
  only the clearance, and the run ends at the goal tolerance);
- walled-in reported: the navigator said ``unreachable`` inside the budget;
- timeout: the budget ran out with neither the goal reached nor ``unreachable`` said.
"""

from __future__ import annotations

import statistics
from collections.abc import Sequence
from dataclasses import dataclass

from otonav.scenario._generator import GeneratedWorld, barn_metric

__all__ = ("FamilyRow", "RunResult", "summarise")


@dataclass(frozen=True, slots=True)
class RunResult:
    """The figures of one run of one generated world (sim time, ground truth)."""

    family: str
    seed: int
    expect: str
    reachable: bool
    optimal_time_s: float | None
    budget_s: float
    passed: bool
    reached: bool
    time_to_goal_s: float | None
    min_clearance_m: float
    required_clearance_m: float
    unreachable_at_s: float | None
    sim_time_s: float
    final_distance_m: float
    wall_time_s: float
    reason: str

    @classmethod
    def of(
        cls,
        family: str,
        world: GeneratedWorld,
        *,
        passed: bool,
        reached: bool,
        time_to_goal_s: float | None,
        min_clearance_m: float,
        unreachable_at_s: float | None,
        sim_time_s: float,
        final_distance_m: float,
        wall_time_s: float,
        reason: str,
    ) -> RunResult:
        s = world.scenario
        return cls(
            family=family,
            seed=world.seed,
            expect=s.expect,
            reachable=world.reachable,
            optimal_time_s=world.optimal_time_s,
            budget_s=s.sim_budget,
            passed=passed,
            reached=reached,
            time_to_goal_s=time_to_goal_s,
            min_clearance_m=min_clearance_m,
            required_clearance_m=s.min_clearance,
            unreachable_at_s=unreachable_at_s,
            sim_time_s=sim_time_s,
            final_distance_m=final_distance_m,
            wall_time_s=wall_time_s,
            reason=reason,
        )

    @property
    def clearance_violated(self) -> bool:
        return self.min_clearance_m < self.required_clearance_m

    @property
    def gave_up(self) -> bool:
        return self.unreachable_at_s is not None and self.unreachable_at_s <= self.budget_s

    @property
    def timed_out(self) -> bool:
        return not self.reached and not self.gave_up

    @property
    def failure(self) -> str | None:
        """Why this run failed, in a word or two (None when it passed)."""
        if self.passed:
            return None
        if self.clearance_violated:
            return "clearance"
        if self.expect == "unreachable":
            return "reached walled-in goal" if self.reached else "walled-in timeout"
        if self.gave_up:
            return "gave up (false unreachable)"
        return "timeout"

    @property
    def barn(self) -> float:
        if self.optimal_time_s is None or self.time_to_goal_s is None:
            return 0.0
        return barn_metric(self.passed, self.time_to_goal_s, self.optimal_time_s)


@dataclass(frozen=True, slots=True)
class FamilyRow:
    """One density's figures. Percentages are of the reachable (``success_pct``) or of
    the walled-in worlds (``walled_reported_pct``); None when there were none."""

    family: str
    worlds: int
    reachable: int
    successes: int
    success_pct: float | None
    barn_metric: float | None
    time_ratio_median: float | None
    """Median over the successes of time to goal / optimal time."""
    timeouts: int
    gave_up: int
    clearance_violations: int
    runs: int
    walled: int
    walled_reported: int
    walled_reported_pct: float | None
    walled_timeouts: int
    wall_time_s: float


def _pct(part: int, whole: int) -> float | None:
    return 100.0 * part / whole if whole else None


def summarise(family: str, results: Sequence[RunResult]) -> FamilyRow:
    """The row of one family: its reachable worlds, its walled-in worlds, all runs."""
    reach = [r for r in results if r.expect == "reached" and r.reachable]
    walled = [r for r in results if r.expect == "unreachable"]
    successes = sum(r.passed for r in reach)
    reported = sum(r.gave_up and not r.reached for r in walled)
    ratios = [
        r.time_to_goal_s / r.optimal_time_s
        for r in reach
        if r.passed and r.time_to_goal_s is not None and r.optimal_time_s
    ]
    return FamilyRow(
        family=family,
        worlds=sum(r.expect == "reached" for r in results),
        reachable=len(reach),
        successes=successes,
        success_pct=_pct(successes, len(reach)),
        barn_metric=sum(r.barn for r in reach) / len(reach) if reach else None,
        time_ratio_median=statistics.median(ratios) if ratios else None,
        timeouts=sum(r.timed_out for r in reach),
        gave_up=sum(r.gave_up and not r.reached for r in reach),
        clearance_violations=sum(r.clearance_violated for r in results),
        runs=len(results),
        walled=len(walled),
        walled_reported=reported,
        walled_reported_pct=_pct(reported, len(walled)),
        walled_timeouts=sum(r.timed_out for r in walled),
        wall_time_s=sum(r.wall_time_s for r in results),
    )
