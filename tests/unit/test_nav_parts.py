"""The three parts of :class:`otonav.nav.Navigation` on their own (issue 36): the global
planner's replan timing, the recovery ladder's rungs, and a new goal as new state (a
fresh plan, controller and ladder: nothing of the last goal's carries over)."""

from __future__ import annotations

import numpy as np
import pytest

from otonav.nav import Navigation, NavigationParams
from otonav.nav._controller import Controller
from otonav.nav._planner import GlobalPlanner, Plan
from otonav.nav._recovery import ProgressChecker, Recovery, Stage

pytestmark = pytest.mark.unit

NONE = np.empty((0, 2))
DT = 0.125
"""s per step: a binary fraction, so k steps are exactly k x DT (replan_period 0.5: 4)."""


def test_the_planner_searches_at_once_then_only_for_a_blocked_path_each_period() -> None:
    p = NavigationParams()
    assert p.replan_period == 4 * DT
    planner, plan, pose = GlobalPlanner(p, (0.0, 0.0)), Plan((3.0, 0.0)), (0.0, 0.0, 0.0)
    assert planner.update(plan, 0.0, pose, p) is not None  # the open field: one step
    assert plan.path is not None
    replans = []
    for k in range(1, 9):  # the path stays clear: checked each period, never searched
        planner.update(plan, k * DT, pose, p)
        replans.append(planner.replans)
    assert replans == [1] * 8
    wall = np.stack((np.full(41, 1.5), np.linspace(-1.0, 1.0, 41)), axis=1)
    planner.observe(wall)  # across the path, just after a check
    for k in range(9, 13):
        planner.update(plan, k * DT, pose, p)
        replans.append(planner.replans)
    assert replans[8:] == [1, 1, 1, 2]  # at the next check, not before
    while plan.search is not None:
        planner.update(plan, 13 * DT, pose, p)
    assert plan.path is not None
    assert np.abs(plan.path[:, 1]).max() > 1.0  # round the wall


@pytest.mark.parametrize(
    ("returns", "v0", "state"),
    [
        ("open", 0.2, "driving"),  # the fast path's clear arc
        ("wall", 0.0, "avoiding"),  # a wall 0.5 m ahead: the sampled arcs pass near it
        ("ring", 0.4, "blocked"),  # returns 0.45 m all round at 0.4 m/s: no arc can stop
    ],
)
def test_the_controller_names_its_command_by_the_arcs_it_had(
    returns: str, v0: float, state: str
) -> None:
    p = NavigationParams()
    planner = GlobalPlanner(p, (0.0, 0.0))
    a = np.linspace(0.0, 2.0 * np.pi, 200)
    planner.observe(
        {
            "open": np.array([[3.0, 3.0]]),
            "wall": np.stack((np.full(81, 0.5), np.linspace(-0.8, 0.8, 81)), axis=1),
            "ring": np.stack((0.45 * np.cos(a), 0.45 * np.sin(a)), axis=1),
        }[returns]
    )
    pose, target = (0.0, 0.0, 0.0), (3.5, 0.0)
    *_, got, _, dwa = Controller().command(pose, v0, 0.0, target, 3.5, 0.0, planner, p)
    assert got == state
    assert dwa is not None
    assert (dwa.admissible == 0) == (state == "blocked")


def test_the_ladder_climbs_spin_backup_follow_then_starts_over_and_resets_on_progress() -> None:
    p = NavigationParams()
    rec = Recovery(ProgressChecker(p.progress_distance, p.progress_window))
    names = [rec.next_rung("stuck")[0] for _ in range(4)]
    assert names == ["spin", "backup", "follow", "spin"]
    assert rec.next_rung("stuck")[1] == "rung 2/3 (round 2), stuck"
    clearance_map = GlobalPlanner(p, (0.0, 0.0)).map
    rec.begin(Stage("follow", "why", 0.0, (0.0, 0.0, 0.0), 3.0, 1), NONE, 0.0, clearance_map, p)
    assert rec.best == 3.0  # where the ladder began
    rec.stage = None
    assert rec.stuck(0.1, 3.0, 0.0, 2.8, False, p) is None  # 0.2 m closer: not enough
    assert rec.next_rung("stuck")[0] == "follow"
    assert rec.next_rung("stuck") == ("spin", "rung 1/3 (round 3), stuck")
    assert rec.stuck(0.2, 3.0, 0.0, 3.0 - p.progress_distance, False, p) is None
    assert rec.next_rung("stuck")[0] == "spin"  # real progress: from the first rung


def test_a_stage_ends_and_progress_is_judged_afresh() -> None:
    p = NavigationParams()
    rec = Recovery(ProgressChecker(p.progress_distance, p.progress_window))
    assert rec.stuck(0.0, 3.0, 0.0, 3.0, False, p) is None
    assert rec.stuck(p.progress_window, 3.0, 0.0, 3.0, False, p) is not None  # no progress
    clearance_map = GlobalPlanner(p, (0.0, 0.0)).map
    rec.begin(Stage("backup", "stuck", 4.0, (0.0, 0.0, 0.0), 3.0, 1), NONE, 0.0, clearance_map, p)
    command = rec.command(4.1, (-0.01, 0.0, 0.0), 3.0, NONE, p)
    assert command == (-p.backup_speed, 0.0, "recovering", "backup: stuck")
    assert rec.command(5.0, (-p.backup_distance, 0.0, 0.0), 3.0, NONE, p) is None  # backed up
    assert rec.stage is None
    assert rec.stuck(5.0, 3.0, 0.0, 3.0, False, p) is None  # the window starts again


def test_a_new_goal_is_a_new_plan_controller_and_ladder() -> None:
    """Reached at the first goal (latched up to twice the tolerance) is not reached at
    a second one as near; a goal set during a recovery stage drops the stage."""
    nav = Navigation(NavigationParams(tolerance=0.08), (0.0, 0.0))
    nav.set_goal((1.0, 0.0))
    assert nav.step(0.0, (0.95, 0.0, 0.0), 0.0, 0.0, NONE).state == "reached"
    first = nav.plan
    nav.set_goal((1.0, 0.0))  # the same goal: nothing changes
    assert nav.plan is first
    nav.set_goal((0.95, 0.12))  # 12 cm away: within twice the tolerance, not within it
    assert nav.plan is not first
    assert nav.step(0.1, (0.95, 0.0, 0.0), 0.0, 0.0, NONE).state != "reached"
    box = np.concatenate(
        [np.stack((np.full(41, x), np.linspace(2.2, 3.8, 41)), axis=1) for x in (2.2, 3.8)]
        + [np.stack((np.linspace(2.2, 3.8, 41), np.full(41, y)), axis=1) for y in (2.2, 3.8)]
    )
    nav.observe(box)
    nav.set_goal((3.0, 3.0))  # walled in: the look-around spin starts
    assert nav.step(0.2, (0.0, 0.0, 0.0), 0.0, 0.0, NONE).stage == "spin"
    nav.set_goal((-1.0, 0.0))
    out = nav.step(0.3, (0.0, 0.0, 0.0), 0.0, 0.0, NONE)
    assert (out.state, out.stage) != ("recovering", "spin")
    assert nav.recovery.rung == 0
    assert not nav.recovery.looked_around
