"""The global planner routes only within what the robot has observed (issue 24, ADR
0059): the convex hull of returns, free beam ends, laser positions and the goal, grown
by a margin. Plain numbers, no simulator."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from otonav.nav import Navigation, NavigationParams
from otonav.nav._dwa import DwaParams
from otonav.nav._observed_hull import ObservedHull, convex_hull, free_ends
from otonav.nav._planner import Plan
from otonav.nav._scan import ScanRays

pytestmark = pytest.mark.unit

NONE = np.empty((0, 2))


def _plan(nav: Navigation) -> Plan:
    """The goal's plan (the tests set a goal first)."""
    assert nav.plan is not None
    return nav.plan


def _segment(x0: float, y0: float, x1: float, y1: float, step: float = 0.02) -> np.ndarray:
    n = max(2, round(math.hypot(x1 - x0, y1 - y0) / step) + 1)
    return np.stack((np.linspace(x0, x1, n), np.linspace(y0, y1, n)), axis=1)


def _inside_brute(poly: np.ndarray, px: float, py: float, margin: float) -> bool:
    """Within ``margin`` of a convex CCW polygon (distance to its edges, or inside)."""
    n = poly.shape[0]
    inside = True
    best = math.inf
    for i in range(n):
        ax, ay = poly[i]
        bx, by = poly[(i + 1) % n]
        ex, ey = bx - ax, by - ay
        if ex * (py - ay) - ey * (px - ax) < 0.0:
            inside = False
        t = min(max(((px - ax) * ex + (py - ay) * ey) / (ex * ex + ey * ey), 0.0), 1.0)
        best = min(best, math.hypot(px - ax - t * ex, py - ay - t * ey))
    return inside or best <= margin


# -- the hull itself ---------------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(3, 60))
def test_the_hull_holds_every_point_and_each_vertex_is_a_point(seed: int, n: int) -> None:
    rng = np.random.default_rng(seed)
    p = rng.uniform(-3.0, 3.0, (n, 2))
    hull = convex_hull(p[:, 0], p[:, 1])
    # every vertex is one of the points
    assert all(np.any(np.all(p == v, axis=1)) for v in hull)
    if hull.shape[0] >= 3:
        # counter-clockwise and convex: every turn is to the left
        a, b, c = hull, np.roll(hull, -1, axis=0), np.roll(hull, -2, axis=0)
        turn = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
        assert (turn > 0.0).all()
        # every point inside (or on) it
        for px, py in p:
            assert _inside_brute(hull, px, py, 1e-9)


def test_the_hull_of_a_square_and_points_inside_is_the_square() -> None:
    x = np.array([0.0, 1.0, 1.0, 0.0, 0.5, 0.2, 0.5])
    y = np.array([0.0, 0.0, 1.0, 1.0, 0.5, 0.7, 0.0])  # (0.5, 0) is on an edge: dropped
    hull = convex_hull(x, y)
    assert hull.tolist() == [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]


def test_fewer_than_three_distinct_points_are_their_own_hull() -> None:
    assert convex_hull(np.array([1.0, 1.0]), np.array([2.0, 2.0])).tolist() == [[1.0, 2.0]]
    two = convex_hull(np.array([3.0, 1.0, 2.0]), np.array([0.0, 0.0, 0.0]))
    assert two.tolist() == [[1.0, 0.0], [3.0, 0.0]]


def test_points_added_in_batches_give_the_hull_of_them_all() -> None:
    rng = np.random.default_rng(7)
    p = rng.uniform(-5.0, 5.0, (300, 2))
    hull = ObservedHull(0.0, 0.0)
    grew = [hull.add(p[i : i + 50, 0], p[i : i + 50, 1]) for i in range(0, 300, 50)]
    whole = convex_hull(np.append(p[:, 0], 0.0), np.append(p[:, 1], 0.0))
    assert np.array_equal(hull.vertices, whole)
    assert grew[0]
    assert hull.version == sum(grew)
    # points inside change nothing, and say so
    version = hull.version
    assert not hull.add(np.array([0.1, -0.2]), np.array([0.0, 0.3]))
    assert not hull.add(np.empty(0), np.empty(0))
    assert hull.version == version


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**31 - 1), st.floats(0.0, 0.6))
def test_the_mask_holds_every_cell_within_the_margin_and_none_far_beyond(
    seed: int, margin: float
) -> None:
    rng = np.random.default_rng(seed)
    p = rng.uniform(-2.0, 2.0, (12, 2))
    hull = ObservedHull(p[0, 0], p[0, 1])
    hull.add(p[1:, 0], p[1:, 1])
    poly = hull.vertices
    cell, n = 0.1, 60
    mask = hull.mask(-3.0, -3.0, cell, n, n, margin)
    assert mask.shape == (n, n)
    xs = -3.0 + (np.arange(n) + 0.5) * cell
    for r in range(0, n, 3):
        for c in range(0, n, 3):
            px, py = xs[c], xs[r]
            if _inside_brute(poly, px, py, margin):
                assert mask[r, c], (px, py)
            elif not _inside_brute(poly, px, py, margin + 1.5):
                # (mitred corners reach a little farther than the margin, never far)
                assert not mask[r, c], (px, py)


def test_the_mask_of_an_axis_aligned_room_stops_at_its_walls_plus_the_margin() -> None:
    x = np.array([-2.0, 2.0, 2.0, -2.0])
    y = np.array([-1.0, -1.0, 1.0, 1.0])
    hull = ObservedHull(0.0, 0.0)
    hull.add(x, y)
    mask = hull.mask(-5.0, -5.0, 0.1, 100, 100, 0.25)
    rows, cols = np.nonzero(mask)
    centres_x = -5.0 + (cols + 0.5) * 0.1
    centres_y = -5.0 + (rows + 0.5) * 0.1
    assert centres_x.min() == pytest.approx(-2.25)
    assert centres_x.max() == pytest.approx(2.25)
    assert centres_y.min() == pytest.approx(-1.25)
    assert centres_y.max() == pytest.approx(1.25)
    assert mask.sum() == 46 * 26


def test_free_ends_are_the_beams_that_saw_nothing_at_range_max() -> None:
    ranges = np.array([1.0, np.inf, 9.0, np.nan, -np.inf, 8.0])
    rays = ScanRays(1.0, 2.0, math.pi / 2, ranges, 0.0, math.pi / 3, 0.1, 8.0)
    ex, ey = free_ends(rays)
    angles = math.pi / 2 + np.array([1, 2]) * math.pi / 3
    assert ex == pytest.approx(1.0 + 8.0 * np.cos(angles))
    assert ey == pytest.approx(2.0 + 8.0 * np.sin(angles))


# -- what it does to the navigator -------------------------------------------------------


def _params() -> NavigationParams:
    return NavigationParams(dwa=DwaParams(radius=0.35))


def _prove(nav: Navigation, pose: tuple[float, float, float]) -> str:
    """Step at rest until the search ends; the state then (the look-around spin
    that precedes ``unreachable`` is what a proof of "no path" starts)."""
    t, out = 0.0, nav.step(0.0, pose, 0.0, 0.0, NONE)
    while _plan(nav).search is not None:
        t += 0.05
        out = nav.step(t, pose, 0.0, 0.0, NONE)
    return "no path" if out.stage == "spin" and "no path" in out.reason else out.state


def test_a_goal_walled_in_against_a_hidden_wall_is_proven_unreachable() -> None:
    """Dense walled-in worlds (issue 24): a room 10 x 10 m, the goal in a ring against
    its east wall. The ring's east side and the wall behind it cannot be seen, nor can
    the room's north-west corner (behind clutter). The unknown outside of the room then
    joins the two: before the hull, A* routed out of the ring, round the outside and
    in at the corner (a ~20 m path) and the robot drove off to explore it."""
    room = np.concatenate(
        (
            _segment(-5.0, -5.0, 5.0, -5.0),  # south
            _segment(5.0, -5.0, 5.0, -1.1),  # east, below the ring
            _segment(5.0, 1.1, 5.0, 5.0),  # east, above the ring
            _segment(5.0, 5.0, -4.0, 5.0),  # north, up to the hidden corner
            _segment(-5.0, 4.0, -5.0, -5.0),  # west, from the hidden corner
        )
    )
    ring = np.concatenate(
        (
            _segment(4.9, -1.0, 3.2, -1.0),
            _segment(3.2, -1.0, 3.2, 1.0),
            _segment(3.2, 1.0, 4.9, 1.0),
        )
    )
    nav = Navigation(_params(), (0.0, 0.0))
    nav.set_goal((4.0, 0.0))
    nav.observe(np.concatenate((room, ring)))
    assert _prove(nav, (0.0, 0.0, 0.0)) == "no path"


def test_a_way_round_a_wall_into_space_seen_empty_is_still_planned() -> None:
    """An open field, one wall between the robot and the goal. The detour passes
    beyond the wall's end, outside the hull of the returns, the robot and the goal;
    the beams that went past the end saw nothing within range, and their free ends
    (at range_max) are observed space: the path goes round."""
    beams, range_max = 360, 8.0
    angles = np.arange(beams) * 2 * math.pi / beams
    # the wall x = 1.5, |y| <= 2, seen from the origin
    with np.errstate(divide="ignore"):
        r = 1.5 / np.cos(angles)
    ranges = np.where((np.cos(angles) > 0) & (np.abs(r * np.sin(angles)) <= 2.0), r, np.inf)
    hit = np.isfinite(ranges)
    points = np.stack((ranges[hit] * np.cos(angles[hit]), ranges[hit] * np.sin(angles[hit])), 1)
    rays = ScanRays(0.0, 0.0, 0.0, ranges, 0.0, 2 * math.pi / beams, 0.1, range_max)
    nav = Navigation(_params(), (0.0, 0.0))
    nav.set_goal((3.0, 0.0))
    nav.observe(points, rays)
    assert _prove(nav, (0.0, 0.0, 0.0)) in ("driving", "avoiding")
    path = _plan(nav).path
    assert path is not None
    assert np.abs(path[:, 1]).max() > 2.3  # round an end of the wall


def test_a_goal_beyond_everything_observed_is_not_bounded_by_it() -> None:
    """Rooms (issue 24, seed 8 of the family): from the top room the robot sees, through
    its door, only part of the wall below; the goal lies past that wall. The world
    evidently goes on beyond what was observed, so there is no bound: the route round
    the seen part of the wall is planned (with the bound, the hull spiked to the goal
    had no room for it and "no path" was proven at 3 s: a false unreachable)."""
    top_room = np.concatenate(
        (
            _segment(-5.0, 1.4, -2.0, 1.4),
            _segment(-1.0, 1.4, 5.0, 1.4),  # the door: x in (-2, -1)
            _segment(5.0, 1.4, 5.0, 5.0),
            _segment(5.0, 5.0, -5.0, 5.0),
            _segment(-5.0, 5.0, -5.0, 1.4),
        )
    )
    seen_below = _segment(-3.4, -2.0, 0.0, -2.0)  # what the door lets it see
    nav = Navigation(_params(), (-1.0, 3.3))
    nav.set_goal((-2.0, -3.5))
    nav.observe(np.concatenate((top_room, seen_below)))
    assert _prove(nav, (-1.0, 3.3, 0.0)) in ("driving", "avoiding")
    assert _plan(nav).path is not None
    assert not nav.planner.hull.contains(-2.0, -3.5)
