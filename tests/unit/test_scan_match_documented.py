"""What otonav.nav._scan_match's docstrings document at their edges (issue 24, ADR 0060
round three):

* a step is accepted when it does not raise the cost: at the minimum the zero step is
  taken, counted, and ends the refinement;
* the refinement stops after a step that moves x, y *and* yaw each by less than 1e-4:
  a step that moves any one of them more is not the last;
* of the two refined candidates the lower final cost wins, the prediction's on a tie;
* the defaults are the documented ones.
"""

from __future__ import annotations

import numpy as np
import pytest

from otonav.nav._scan_map import ScanMap
from otonav.nav._scan_match import MatchParams, correlative_search, match_scan, refine
from otonav.params import LocalizationConfig

pytestmark = pytest.mark.unit


def _exact_room() -> tuple[ScanMap, np.ndarray]:
    """Returns at cell centres along four walls (40 a wall), stored from the origin: seen
    again from the origin each is its own stored return (residual exactly 0, prior
    exactly 0); every return but a wall's two ends has a normal."""
    res = 0.05
    grid = ScanMap(0.0, 0.0, half_size=2.0, resolution=res)
    centre = (np.arange(-20, 20) + 0.5) * res  # symmetric about 0
    top = np.stack((centre, np.full_like(centre, 1.025)), axis=1)
    right = np.stack((np.full_like(centre, 1.225), centre), axis=1)
    bottom = np.stack((centre[::-1], np.full_like(centre, -0.975)), axis=1)
    left = np.stack((np.full_like(centre, -1.175), centre[::-1]), axis=1)
    pts = np.concatenate((top, right, bottom, left))
    assert grid.insert(0.0, 0.0, pts[:, 0], pts[:, 1]) == pts.shape[0]
    return grid, pts


def test_at_the_minimum_the_zero_step_is_accepted_and_counted() -> None:
    grid, pts = _exact_room()
    prediction = (0.0, 0.0, 0.0)
    params = MatchParams(iterations=10)
    pose, steps = refine(grid, pts, prediction, prediction, params)
    assert pose == prediction
    assert steps == 1  # an equal cost is accepted: one (zero) step, then converged
    result = match_scan(grid, pts, prediction, params)
    assert result.pose == prediction
    assert result.iterations == 1
    assert result.rms == 0.0
    assert refine(grid, pts, prediction, prediction, MatchParams(iterations=0)) == (prediction, 0)


def test_the_defaults_are_the_documented_ones() -> None:
    """``MatchParams()`` against where its defaults are written for a user: the config
    keys ``nav.localization.*`` (docs/how-to/localization.md's table; the generated
    config reference) for the window, the step (one map cell, ADR 0053) and
    ``max_distance``; ADR 0053 §1 for what the stack does not expose: 0.02 rad yaw
    steps, trusted from 30 % inliers, a prior of 1 per m^2 and 1 m per rad of yaw."""
    loc = LocalizationConfig()
    p = MatchParams()
    assert (p.linear_window, p.angular_window, p.max_distance, p.linear_step) == (
        loc.linear_window,
        loc.angular_window,
        loc.max_distance,
        loc.resolution,
    )
    assert (p.angular_step, p.min_inliers, p.prior, p.yaw_scale) == (0.02, 0.3, 1.0, 1.0)


@pytest.mark.parametrize("axis", [0, 1])
def test_a_step_across_two_walls_is_followed_by_the_one_that_confirms_it(axis: int) -> None:
    """The scan seen from the origin, predicted (and started) 3 cm off along x or y: the
    two walls across that axis (38 returns with normals each) pull it back, the prior
    (1 per m^2) toward the prediction; the cost is quadratic in that coordinate, so the
    first step lands on its minimum 0.03 / (76 + 1) and moves it ~3 cm, the others not
    at all. That step is not the last: the second, under 1e-4 in all three, ends it."""
    grid, pts = _exact_room()
    start = (0.03, 0.0, 0.0) if axis == 0 else (0.0, 0.03, 0.0)
    pose, steps = refine(grid, pts, start, start, MatchParams())
    assert steps == 2
    assert pose[axis] == pytest.approx(0.03 / 77.0, abs=1e-12)
    assert abs(pose[1 - axis]) < 1e-12
    assert abs(pose[2]) < 1e-12


def test_a_step_in_yaw_alone_is_followed_by_the_one_that_confirms_it() -> None:
    """Predicted 0.01 rad off in yaw: the first step turns it back by ~0.01 rad and moves
    x and y by ~1e-6 m (the room is symmetric); it is not the last."""
    grid, pts = _exact_room()
    start = (0.0, 0.0, 0.01)
    pose, steps = refine(grid, pts, start, start, MatchParams())
    assert steps == 2
    assert abs(pose[2]) < 0.001


def test_on_an_exact_tie_between_the_two_candidates_the_prediction_wins() -> None:
    """Lone returns (no normals: nothing to fit) 1 m apart, the scan 5 cm short of them
    in x: the search's best is 5 cm on (coarse != prediction), but with no prior and no
    step both refined candidates cost exactly 0 (every point near a return, none an
    inlier): the prediction's is kept (and trusted: no inliers are required here)."""
    grid = ScanMap(0.0, 0.0, half_size=2.0, resolution=0.05)
    rx = np.array([1.025, 0.025, -0.975, 0.025])
    ry = np.array([0.025, 1.025, 0.025, -0.975])
    grid.insert(0.0, 0.0, rx, ry)
    pts = np.stack((rx - 0.05, ry), axis=1)
    params = MatchParams(prior=0.0, iterations=0, min_inliers=0.0)
    best, _ = correlative_search(grid, pts, (0.0, 0.0, 0.0), params)
    assert best == pytest.approx((0.05, 0.0, 0.0), abs=1e-12)
    result = match_scan(grid, pts, (0.0, 0.0, 0.0), params)
    assert (result.pose, result.ok, result.inliers) == ((0.0, 0.0, 0.0), True, 0.0)


def test_with_no_prior_a_scan_that_constrains_nothing_leaves_the_refinement_in_place() -> None:
    """The lone returns above (no normals: no inliers, a zero normal matrix) with no
    prior and the default iterations: the step is undefined, so the refinement stays
    where it started (it raised numpy's LinAlgError: Singular matrix)."""
    grid = ScanMap(0.0, 0.0, half_size=2.0, resolution=0.05)
    rx = np.array([1.025, 0.025, -0.975, 0.025])
    ry = np.array([0.025, 1.025, 0.025, -0.975])
    grid.insert(0.0, 0.0, rx, ry)
    pts = np.stack((rx - 0.05, ry), axis=1)
    params = MatchParams(prior=0.0, min_inliers=0.0)
    assert refine(grid, pts, (0.05, 0.0, 0.0), (0.0, 0.0, 0.0), params) == ((0.05, 0.0, 0.0), 0)
    result = match_scan(grid, pts, (0.0, 0.0, 0.0), params)
    assert result.pose == (0.0, 0.0, 0.0)
