"""Indoors (issue 24): gaps down to the robot's limit are planned and driven through,
progress is judged on what the robot does, the recovery ladder is short, and a search
that cannot finish in one tick continues on the next. Sim time only, plain numbers."""

from __future__ import annotations

import math

import numpy as np
import pytest
from grid_search import cell_of

from otonav.nav import Navigation, NavigationParams
from otonav.nav._dwa import DwaParams
from otonav.nav._planner import Plan

pytestmark = pytest.mark.unit

RADIUS = 0.35  # the stack's centre clearance (nav.clearance)
NONE = np.empty((0, 2))


def _plan(nav: Navigation) -> Plan:
    """The goal's plan (the tests set a goal first)."""
    assert nav.plan is not None
    return nav.plan


def _segment(x0: float, y0: float, x1: float, y1: float, step: float = 0.02) -> np.ndarray:
    n = max(2, round(math.hypot(x1 - x0, y1 - y0) / step) + 1)
    return np.stack((np.linspace(x0, x1, n), np.linspace(y0, y1, n)), axis=1)


def _door_wall(x: float, gap: float, centre: float = 0.0, reach: float = 3.0) -> np.ndarray:
    """A wall along y at ``x`` with a door of width ``gap`` centred on ``centre``."""
    lo, hi = centre - gap / 2, centre + gap / 2
    return np.concatenate((_segment(x, hi, x, reach), _segment(x, -reach, x, lo)))


def _settle(
    nav: Navigation, pose: tuple[float, float, float], t: float = 0.0
) -> tuple[float, object]:
    """Step at rest until no search is in progress (a search may span ticks)."""
    out = nav.step(t, pose, 0.0, 0.0, NONE)
    while getattr(nav, "searching", False):
        t += 0.05
        out = nav.step(t, pose, 0.0, 0.0, NONE)
    return t, out


def _params(**kw: object) -> NavigationParams:
    return NavigationParams(dwa=DwaParams(radius=RADIUS), **kw)  # type: ignore[arg-type]


@pytest.mark.parametrize("offset", [0.0, 0.013, 0.027, 0.041])
def test_a_door_at_the_passable_limit_is_planned_through(offset: float) -> None:
    """Passable limit: 2 x centre clearance + one map cell (0.75 m). A 0.76 m door at
    any alignment to the grid is planned through the middle, not around or refused."""
    nav = Navigation(_params(), (0.0, 0.0))
    nav.set_goal((3.0, offset))
    nav.observe(_door_wall(1.5 + offset, 0.76, centre=offset))
    _, out = _settle(nav, (0.0, offset, 0.0))
    path = _plan(nav).path
    assert path is not None, out
    door = path[np.abs(path[:, 0] - (1.5 + offset)) < 0.2]
    assert door.shape[0] > 0
    # through the door, within a cell of its middle
    assert np.abs(door[:, 1] - offset).max() <= 0.06


def test_the_local_planner_drives_through_a_door_at_the_limit() -> None:
    """In the door the DWA checks its arcs against the scan's exact returns, not the
    map's lower bound (short by up to resolution x sqrt 2): it keeps moving."""
    nav = Navigation(_params(), (0.0, 0.0))
    nav.set_goal((3.0, 0.0))
    wall = _door_wall(1.5, 0.76)
    t = 0.0
    pose = (1.2, 0.0, 0.0)
    nav.observe(wall)
    v = 0.2
    for _ in range(30):
        out = nav.step(t, pose, v, 0.0, NONE)
        assert out.state in ("driving", "avoiding"), out
        v = out.v
        x, y, yaw = pose
        step = out.v * 0.05
        pose = (x + step * math.cos(yaw), y + step * math.sin(yaw), yaw + out.omega * 0.05)
        t += 0.05
    assert pose[0] > 1.6  # through the door
    assert abs(pose[1]) < 0.04


def test_a_gap_under_the_limit_is_not_planned_through() -> None:
    nav = Navigation(_params(), (0.0, 0.0))
    nav.set_goal((3.0, 0.0))
    nav.observe(_door_wall(1.5, 0.64, reach=9.9))
    _settle(nav, (0.0, 0.0, 0.0))
    path = _plan(nav).path
    if path is not None:
        door = path[np.abs(path[:, 0] - 1.5) < 0.1]
        assert door.shape[0] == 0 or np.abs(door[:, 1]).min() > 0.3


# -- bounded planning per tick -----------------------------------------------------------


def test_a_search_in_slices_is_the_search_in_one_go() -> None:
    from grid_search import astar

    from otonav.nav._global_path import AstarSearch

    rng = np.random.default_rng(3)
    free = rng.random((60, 60)) > 0.3
    penalty = rng.random((60, 60)).astype(np.float32)
    whole = astar(free, penalty, (0, 0), (59, 59))
    search = AstarSearch(free, penalty, (0, 0), (59, 59))
    steps = 0
    while (sliced := search.advance(37)) is None:
        steps += 1
        assert search.expansions == 37 * steps
    assert sliced == whole
    assert steps > 1


def test_proving_no_path_is_spread_over_steps_each_within_its_budget() -> None:
    """The robot boxed in, the goal outside in a room as large as the map: the proof
    floods the whole room. No step expands more than ``expansions_per_tick`` cells;
    the proof still comes."""
    params = _params(expansions_per_tick=500)
    nav = Navigation(params, (0.0, 0.0))
    nav.set_goal((5.0, 0.0))
    box = np.concatenate(
        (
            _segment(-0.8, -0.8, 0.8, -0.8),
            _segment(0.8, -0.8, 0.8, 0.8),
            _segment(0.8, 0.8, -0.8, 0.8),
            _segment(-0.8, 0.8, -0.8, -0.8),
        )
    )
    room = np.concatenate(
        (
            _segment(-9.5, -9.5, 9.5, -9.5, step=0.5),
            _segment(9.5, -9.5, 9.5, 9.5, step=0.5),
            _segment(9.5, 9.5, -9.5, 9.5, step=0.5),
            _segment(-9.5, 9.5, -9.5, -9.5, step=0.5),
        )
    )
    nav.observe(np.concatenate((box, room)))
    t, steps, out = 0.0, 0, None
    before = nav.planner.expansions
    while steps < 400:
        out = nav.step(t, (0.0, 0.0, 0.0), 0.0, 0.0, NONE)
        assert nav.planner.expansions - before <= 500
        before = nav.planner.expansions
        steps += 1
        t += 0.05
        if out.stage == "spin" or out.state == "unreachable":
            break
    assert out is not None
    assert out.stage == "spin"
    assert "no path" in out.reason
    assert steps > 10  # the proof took many steps (about 40 000 cells)


# -- no stalls -----------------------------------------------------------------------


def _drive(
    nav: Navigation, motion: object, until: float, stop: object
) -> tuple[float, list[tuple[float, str, str, str]]]:
    """Step at 20 Hz with the pose ``motion(t)`` (what the robot really does, whatever
    is commanded) until ``stop(out)`` or ``until`` s; returns the time and the log."""
    log: list[tuple[float, str, str, str]] = []
    t = 0.0
    while t < until:
        out = nav.step(t, motion(t), 0.0, 0.0, NONE)  # type: ignore[operator]
        log.append((t, out.state, out.stage, out.reason))
        if stop(out):  # type: ignore[operator]
            return t, log
        t = round(t + 0.05, 6)
    return t, log


def test_a_robot_oscillating_across_its_path_is_in_recovery_within_the_window() -> None:
    """It moves all the time (0.4 m side to side) but gets no nearer along the path:
    the progress check looks at what the robot does, not how much it moves."""
    params = _params()
    nav = Navigation(params, (0.0, 0.0))
    nav.set_goal((4.0, 0.0))
    t, log = _drive(
        nav,
        lambda t: (0.0, 0.2 * math.sin(2.0 * t), 0.0),
        30.0,
        lambda out: out.state == "recovering",
    )
    assert log[-1][1] == "recovering", log[-1]
    assert t <= params.progress_window + 0.05
    assert "rung 1/3" in log[-1][3]


def test_turning_slowly_while_nearly_facing_the_target_is_not_progress() -> None:
    """Issue 24's U trap, outer corner: the robot drives 0.26 m, then stands with the
    target 0.55 rad off (through the wall's corner) and turns ever slower toward it.
    Turning counts only while the target is beyond the DWA's rotate threshold: the
    robot is in recovery one window after its last real progress."""
    params = _params()
    nav = Navigation(params, (0.0, 0.0))
    nav.set_goal((4.0, 0.0))

    def motion(t: float) -> tuple[float, float, float]:
        if t < 1.3:
            return (0.2 * t, 0.0, 0.55)  # sliding ahead, facing 0.55 rad off
        return (0.26, 0.0, 0.55 * math.exp(-(t - 1.3)))  # then turning ever slower

    t, log = _drive(nav, motion, 30.0, lambda out: out.state == "recovering")
    assert log[-1][1] == "recovering", log[-1]
    assert t <= params.progress_window + 0.05  # (with the credit for that turn: 6.7 s)


def test_turning_toward_a_target_behind_is_progress() -> None:
    """A robot facing away from its target turns in place first: a half turn at the
    DWA's rate is progress, not a stall (no recovery while it turns)."""
    params = _params()
    nav = Navigation(params, (0.0, 0.0))
    nav.set_goal((-4.0, 0.0))  # behind
    _t, log = _drive(
        nav,
        lambda t: (0.0, 0.0, min(1.0 * t, math.pi)),  # 1 rad/s, then facing it
        params.progress_window + 0.5,
        lambda out: out.state == "recovering",
    )
    assert all(state != "recovering" for _, state, _, _ in log), log[-1]


def test_a_stuck_robot_climbs_the_ladder_again_and_never_calls_the_goal_unreachable() -> None:
    """Wheels spinning in place in an open field: every rung runs, each named with its
    reason; the ladder then starts over (``round 2``) instead of declaring a goal
    unreachable that no search proved unreachable (issue 42)."""
    params = _params()
    nav = Navigation(params, (0.0, 0.0))
    nav.set_goal((4.0, 0.0))
    _t, log = _drive(
        nav,
        lambda t: (0.0, 0.0, 0.0),
        60.0,
        lambda out: out.state == "unreachable" or "(round 2)" in out.reason,
    )
    assert all(state != "unreachable" for _, state, _, _ in log), log[-1]
    assert "rung 1/3 (round 2)" in log[-1][3]
    rungs = [(stage, reason) for _, state, stage, reason in log if state == "recovering"]
    assert [s for s, _ in dict.fromkeys(rungs)][:1] == ["spin"]
    for k, name in enumerate(("spin", "backup", "follow"), 1):
        reasons = {reason for stage, reason in rungs if stage == name and "round" not in reason}
        assert reasons, name
        assert all(r.startswith(f"{name}: rung {k}/3, ") for r in reasons), reasons


def test_the_spin_rung_clears_the_map_around_the_robot() -> None:
    params = _params()
    nav = Navigation(params, (0.0, 0.0))
    nav.set_goal((4.0, 0.0))
    nav.observe(_segment(0.6, -0.3, 0.6, 0.3))  # a smear just ahead, and a far wall
    nav.observe(_segment(3.0, 2.0, 3.0, 3.0))
    far = int(nav.planner.map.occupied.sum())
    _drive(nav, lambda t: (0.0, 0.0, 0.0), 10.0, lambda out: out.stage == "spin")
    row, col, _ = cell_of(nav.planner.map, np.array([0.6]), np.array([0.0]))
    assert not nav.planner.map.occupied[row, col].any()  # the smear is gone
    assert 0 < int(nav.planner.map.occupied.sum()) < far


def test_the_lookahead_scales_with_the_speed_like_regulated_pure_pursuit() -> None:
    """A slow robot aims at the path near it (0.4 m), a fast one 2 s of its speed
    ahead up to ``nav.map.lookahead``: at a door at the limit, standing off its axis,
    the robot lines up on the path instead of heading past the door's corner."""
    params = _params()
    nav = Navigation(params, (0.0, 0.0))
    nav.set_goal((4.0, 0.0))
    _settle(nav, (0.0, 0.0, 0.0))
    assert _plan(nav).path is not None
    for v0, want in ((0.0, 0.4), (-0.05, 0.4), (0.25, 0.5), (0.4, 0.8), (0.5, 0.8)):
        tx, ty = _plan(nav).follow((0.0, 0.0, 0.0), 4.0, v0, params.lookahead)[1]
        assert ty == pytest.approx(0.0, abs=0.06)
        assert want <= tx <= want + 0.15, (v0, tx)
