"""The recovery pieces (otonav.nav._recovery) against their docstrings (issue 24, test
rigor): the progress checker against a plain model on random sequences of updates,
new paths and resets (on a grid of exact values, so "by at least ``distance``" and
"within ``window`` s" meet their bounds exactly); the boundary side and the wall
follower against plain formulas on random scans, and their documented properties."""

from __future__ import annotations

import math

import numpy as np
import pytest

from otonav.nav._recovery import ProgressChecker, boundary_side, follow_boundary

pytestmark = pytest.mark.unit


class _Model:
    """ProgressChecker's docstring: the distance to go must shrink by ``distance``
    within ``window`` s; the straight-line distance by ``distance`` within
    ``goal_window`` s; a longer new path raises the reference, not the clock."""

    def __init__(self, distance: float, window: float, goal_window: float) -> None:
        self.distance, self.window, self.goal_window = distance, window, goal_window
        self.path: tuple[float, float] | None = None  # (since, reference)
        self.goal: tuple[float, float] | None = None

    def update(self, now: float, to_go: float, goal: float) -> str | None:
        if self.path is None or self.path[1] - to_go >= self.distance:
            self.path = (now, to_go)
        if self.goal is None or self.goal[1] - goal >= self.distance:
            self.goal = (now, goal)
        if now - self.path[0] >= self.window:
            return f"under {self.distance:g} m of progress along the path in {self.window:g} s"
        if now - self.goal[0] >= self.goal_window:
            return f"no {self.distance:g} m closer to the goal in {self.goal_window:g} s"
        return None

    def rebase(self, to_go: float) -> None:
        if self.path is not None and to_go > self.path[1]:
            self.path = (self.path[0], to_go)


@pytest.mark.parametrize("seed", range(4))
def test_the_progress_checker_is_its_docstring(seed: int) -> None:
    rng = np.random.default_rng(300 + seed)
    fired: set[str] = set()
    for _ in range(40):
        distance = float(rng.choice([0.25, 0.5]))
        window = float(rng.choice([1.0, 2.0]))
        goal_window = float(rng.choice([3.0, 5.0]))
        pc, model = (
            ProgressChecker(distance, window, goal_window),
            _Model(distance, window, goal_window),
        )
        now = float(rng.choice([0.0, 7.5, 40.0]))  # clocks that do not start at 0
        to_go, goal = float(rng.integers(8, 20)), float(rng.integers(8, 20))
        for _ in range(30):
            op = rng.random()
            if op < 0.1:
                pc.rebase(to_go + 1.0)
                model.rebase(to_go + 1.0)
                to_go += float(rng.choice([0.0, 1.0]))
                continue
            if op < 0.13:
                pc.reset()
                model = _Model(distance, window, goal_window)
                continue
            now += 0.5
            to_go += float(rng.choice([-0.5, -0.25, 0.0, 0.25]))
            goal += float(rng.choice([-0.5, -0.25, 0.0, 0.25]))
            got, want = pc.update(now, to_go, goal), model.update(now, to_go, goal)
            assert got == want, (now, to_go, goal)
            if got is not None:
                fired.add(got.split()[0])
    assert fired == {"under", "no"}


def test_a_new_path_before_any_update_is_nothing_to_rebase() -> None:
    pc = ProgressChecker(distance=0.5, window=2.0, goal_window=10.0)
    pc.rebase(9.0)  # no reference yet: nothing to raise
    assert pc.update(0.0, 5.0, 5.0) is None
    assert pc.update(1.5, 4.5, 5.0) is None  # exactly `distance` nearer: progress
    assert pc.update(3.0, 4.5, 5.0) is None  # the clock restarted at 1.5
    assert pc.update(3.5, 4.5, 5.0) is not None


def test_the_checker_is_slotted() -> None:
    assert not hasattr(ProgressChecker(), "__dict__")


def _side(points: np.ndarray, bearing: float) -> int:
    if points.shape[0] == 0:
        return -1 if bearing >= 0.0 else 1
    i = min(range(points.shape[0]), key=lambda k: math.hypot(points[k, 0], points[k, 1]))
    beta = math.atan2(points[i, 1], points[i, 0])
    left = abs(math.remainder(beta - math.pi / 2 - bearing, math.tau))
    right = abs(math.remainder(beta + math.pi / 2 - bearing, math.tau))
    return 1 if left <= right else -1


def _follow(
    points: np.ndarray, side: int, distance: float, speed: float, max_omega: float, gain: float
) -> tuple[float, float]:
    if points.shape[0] == 0:
        return speed, side * 0.5 * max_omega
    d = [math.hypot(x, y) for x, y in points.tolist()]
    i = d.index(min(d))
    beta = math.atan2(points[i, 1], points[i, 0])
    error = math.remainder(beta - side * math.pi / 2 + side * gain * (d[i] - distance), math.tau)
    return speed * max(math.cos(error), 0.0), min(max(gain * error, -max_omega), max_omega)


@pytest.mark.parametrize("seed", range(3))
def test_the_side_and_the_follower_are_their_formulas_on_random_scans(seed: int) -> None:
    rng = np.random.default_rng(400 + seed)
    sides = set()
    for _ in range(150):
        n = int(rng.choice([0, 1, 2, 7]))
        pts = rng.uniform(-2.0, 2.0, (n, 2)) * rng.uniform(0.2, 1.0, 2)  # |x| != |y|
        bearing = float(rng.choice([0.0, rng.uniform(-3.1, 3.1)]))
        side = boundary_side(pts, bearing)
        assert side == _side(pts, bearing)
        sides.add((n > 0, side))
        gain = float(rng.uniform(0.5, 3.0))
        args = (
            float(rng.uniform(0.2, 0.6)),
            float(rng.uniform(0.1, 0.5)),
            float(rng.uniform(0.5, 2.0)),
        )
        got = follow_boundary(
            pts, side, distance=args[0], speed=args[1], max_omega=args[2], gain=gain
        )
        assert got == pytest.approx(_follow(pts, side, *args, gain), abs=1e-12)
    assert sides == {(True, 1), (True, -1), (False, 1), (False, -1)}


@pytest.mark.parametrize("side", [1, -1])
def test_the_follower_keeps_its_obstacle_at_the_distance_on_its_side(side: int) -> None:
    """The obstacle abeam on ``side``: at the distance, straight on at full speed; too
    far, bend toward it; too near, away; facing it, turn without driving into it; with
    nothing seen, turn toward that side, never faster than the limit."""

    def at(d: float) -> np.ndarray:
        return np.array([[0.0, side * d], [1.0, side * 5.0]])

    v, w = follow_boundary(at(0.4), side, distance=0.4, speed=0.3, max_omega=1.0)
    assert (v, w) == pytest.approx((0.3, 0.0), abs=1e-12)
    v, w = follow_boundary(at(0.6), side, distance=0.4, speed=0.3, max_omega=1.0)
    assert w * side > 0.0
    assert 0.0 < v < 0.3
    v, w = follow_boundary(at(0.3), side, distance=0.4, speed=0.3, max_omega=1.0)
    assert w * side < 0.0
    assert 0.0 < v < 0.3
    ahead = np.array([[0.3, 0.0]])
    v, w = follow_boundary(ahead, side, distance=0.4, speed=0.3, max_omega=1.0, gain=3.0)
    assert v == 0.0  # more than 90 degrees off the tangent: turn on the spot
    assert abs(w) == 1.0
    v, w = follow_boundary(np.empty((0, 2)), side, distance=0.4, speed=0.3, max_omega=2.0)
    assert v == 0.3
    assert 0.0 < w * side <= 2.0
    assert (v, w) == (0.3, side * 1.0)  # half the limit


def test_with_nothing_seen_the_side_is_the_one_the_goal_is_not_on() -> None:
    empty = np.empty((0, 2))
    assert boundary_side(empty, 0.5) == -1
    assert boundary_side(empty, -0.5) == 1
    assert boundary_side(empty, 0.0) == -1


@pytest.mark.parametrize("distance", [0.3, 1.0, 2.5])
def test_on_an_exact_tie_the_side_is_the_obstacle_on_the_left(distance: float) -> None:
    """boundary_side's docstring: both tangents equally good (the nearest return dead
    ahead, the goal straight through it, each tangent a quarter turn off the goal)
    gives +1, the obstacle on the left; a hair either way picks the nearer tangent
    (the goal a little left: the tangent heading left, the obstacle on the right)."""
    ahead = np.array([[distance, 0.0], [distance + 1.0, 0.5]])
    assert boundary_side(ahead, 0.0) == 1
    assert boundary_side(ahead, 1e-9) == -1
    assert boundary_side(ahead, -1e-9) == 1
