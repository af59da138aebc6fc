"""The scan matcher (otonav.nav._scan_match) against its module docstring written as plain
loops (issue 24, test rigor), on random rooms, scans and predictions:

* the correlative search is the brute-force minimum over its window (``0, +-step, ...``
  up to the window in x, y and yaw, the prediction's neighbours first on a tie) of the
  capped squared distances plus the prior;
* refinement never ends at a higher cost than it starts (a step is accepted only if it
  does not raise the cost), the cost being the point-to-line residuals of the matched
  points, ``max_distance^2`` per unmatched point, and the prior;
* ``match_scan`` reports the inlier share and the rms of the pose it returns, trusts it
  exactly when the share reaches ``min_inliers``, and keeps the prediction otherwise."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator

import numpy as np
import pytest
from synthetic_scans import Segment, box, scan

from otonav.nav._scan_map import ScanMap
from otonav.nav._scan_match import (
    MatchParams,
    Pose,
    correlative_search,
    match_scan,
    refine,
    transform,
)

pytestmark = pytest.mark.unit


def _ladder(window: float, step: float) -> list[float]:
    out = [0.0]
    k = 1
    while k * step <= window + 1e-9 * step:
        out += [k * step, -k * step]
        k += 1
    return out


def _search(grid: ScanMap, pts: np.ndarray, pred: Pose, p: MatchParams) -> tuple[Pose, float]:
    best, best_cost = pred, math.inf
    for da in _ladder(p.angular_window, p.angular_step):
        for dx in _ladder(p.linear_window, p.linear_step):
            for dy in _ladder(p.linear_window, p.linear_step):
                yaw = pred[2] + da
                x, y = transform((pred[0], pred[1], yaw), pts)
                d = np.minimum(grid.nearest(x + dx, y + dy), p.max_distance)
                prior = p.prior * (dx * dx + dy * dy + p.yaw_scale**2 * da * da)
                cost = float((d * d).sum()) + prior
                if cost < best_cost:
                    best_cost = cost
                    best = (pred[0] + dx, pred[1] + dy, math.remainder(yaw, math.tau))
    return best, best_cost


def _fit(
    grid: ScanMap, pts: np.ndarray, pose: Pose, pred: Pose, p: MatchParams
) -> tuple[float, float, float]:
    """(cost, inlier share, rms) at ``pose``, point by point."""
    x, y = transform(pose, pts)
    qx, qy, nx, ny, found = grid.correspond(x, y)
    cost, inliers, squares = 0.0, 0, 0.0
    for i in range(pts.shape[0]):
        ex, ey = x[i] - qx[i], y[i] - qy[i]
        if not (found[i] and math.hypot(ex, ey) < p.max_distance):
            cost += p.max_distance**2
            continue
        if nx[i] == 0.0 and ny[i] == 0.0:
            continue  # near, but a return with no normal: left out of the fit
        r = nx[i] * ex + ny[i] * ey
        cost += r * r
        squares += r * r
        inliers += 1
    dyaw = p.yaw_scale * math.remainder(pose[2] - pred[2], math.tau)
    cost += p.prior * ((pose[0] - pred[0]) ** 2 + (pose[1] - pred[1]) ** 2 + dyaw**2)
    rms = math.sqrt(squares / inliers) if inliers else math.nan
    return cost, inliers / pts.shape[0], rms


def _world(rng: np.random.Generator) -> list[Segment]:
    walls = box(0.0, 0.0, float(rng.uniform(2.0, 3.0)), float(rng.uniform(1.5, 2.5)))
    for _ in range(int(rng.integers(1, 4))):
        walls += box(
            float(rng.uniform(-1.2, 1.2)),
            float(rng.uniform(-1.0, 1.0)),
            float(rng.uniform(0.1, 0.4)),
            float(rng.uniform(0.1, 0.4)),
        )
    return walls


def _params(rng: np.random.Generator) -> MatchParams:
    return MatchParams(
        linear_window=float(rng.choice([0.0, 0.05, 0.1, 0.15])),
        linear_step=float(rng.choice([0.03, 0.05])),
        angular_window=float(rng.choice([0.0, 0.04, 0.06])),
        angular_step=float(rng.choice([0.02, 0.03])),
        max_distance=float(rng.uniform(0.15, 0.4)),
        prior=float(rng.choice([0.0, 0.3, 1.0, 4.0])),
        yaw_scale=float(rng.uniform(0.5, 2.0)),
        iterations=int(rng.integers(0, 12)),
        min_inliers=float(rng.uniform(0.2, 0.95)),
    )


Case = tuple[np.random.Generator, ScanMap, np.ndarray, Pose, MatchParams]


def _cases(seed: int, n: int) -> Iterator[Case]:
    rng = np.random.default_rng(seed)
    for _ in range(n):
        world = _world(rng)
        grid = ScanMap(0.0, 0.0, half_size=4.0, resolution=float(rng.choice([0.05, 0.1])))
        start = (
            float(rng.uniform(-0.8, 0.8)),
            float(rng.uniform(-0.6, 0.6)),
            float(rng.uniform(-3, 3)),
        )
        x, y = transform(start, scan(world, start, beams=180))
        grid.insert(start[0], start[1], x, y)
        truth = (
            start[0] + float(rng.uniform(-0.3, 0.3)),
            start[1] + float(rng.uniform(-0.3, 0.3)),
            start[2] + float(rng.uniform(-0.4, 0.4)),
        )
        pts = scan(world, truth, beams=int(rng.integers(40, 120)))
        if rng.random() < 0.2:  # strays: new ground the map has not seen
            pts = np.concatenate((pts, rng.uniform(-6, 6, (20, 2))))
        pred = (
            truth[0] + float(rng.uniform(-0.12, 0.12)),
            truth[1] + float(rng.uniform(-0.12, 0.12)),
            truth[2] + float(rng.uniform(-0.08, 0.08)),
        )
        yield rng, grid, pts, pred, _params(rng)


@pytest.mark.parametrize("seed", range(3))
def test_the_correlative_search_is_the_brute_force_minimum_of_its_window(seed: int) -> None:
    moved = 0
    for _, grid, pts, pred, p in _cases(500 + seed, 12):
        best, cost = correlative_search(grid, pts, pred, p)
        want, want_cost = _search(grid, pts, pred, p)
        assert best == pytest.approx(want, abs=1e-12)
        assert cost == pytest.approx(want_cost, rel=1e-9, abs=1e-12)
        moved += best != pred
    assert moved >= 3


@pytest.mark.parametrize("seed", range(3))
def test_refinement_never_ends_above_its_start_and_match_reports_its_pose(seed: int) -> None:
    improved = trusted = refused = 0
    for rng, grid, pts, pred, p in _cases(600 + seed, 12):
        start = (pred[0] + float(rng.uniform(-0.05, 0.05)), pred[1], pred[2])
        pose, steps = refine(grid, pts, start, pred, p)
        assert 0 <= steps <= p.iterations
        before, after = _fit(grid, pts, start, pred, p)[0], _fit(grid, pts, pose, pred, p)[0]
        assert after <= before + 1e-12
        improved += after < before - 1e-9
        if steps == 0:
            assert pose == start
        r = match_scan(grid, pts, pred, p)
        assert r.iterations <= p.iterations
        assert r.ok == (r.inliers >= p.min_inliers)
        if not r.ok:
            assert r.pose == pred
            refused += 1
            continue
        _, share, rms = _fit(grid, pts, r.pose, pred, p)
        trusted += 1
        assert r.inliers == pytest.approx(share, abs=1e-12)
        if math.isnan(rms):
            assert math.isnan(r.rms)
        else:
            assert r.rms == pytest.approx(rms, rel=1e-9, abs=1e-12)
    assert improved >= 3
    assert trusted >= 3


def test_match_params_bounds_name_the_field() -> None:
    for name in ("linear_window", "angular_window", "prior", "yaw_scale"):
        with pytest.raises(ValueError, match=rf"MatchParams\.{name} must be finite and >= 0"):
            MatchParams(**{name: -0.1})  # type: ignore[arg-type]
        with pytest.raises(ValueError, match=rf"MatchParams\.{name}"):
            MatchParams(**{name: math.inf})  # type: ignore[arg-type]
        assert getattr(MatchParams(**{name: 0.0}), name) == 0.0  # type: ignore[arg-type]
    for name in ("linear_step", "angular_step", "max_distance"):
        with pytest.raises(ValueError, match=rf"MatchParams\.{name} must be finite and > 0"):
            MatchParams(**{name: 0.0})  # type: ignore[arg-type]
        with pytest.raises(ValueError, match=rf"MatchParams\.{name}"):
            MatchParams(**{name: math.nan})  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="iterations must be an integer >= 0, got -1"):
        MatchParams(iterations=-1)
    for bad in (-0.01, 1.01):
        with pytest.raises(ValueError, match=r"min_inliers must be in \[0, 1\]"):
            MatchParams(min_inliers=bad)
    assert (MatchParams(min_inliers=1.0).min_inliers, MatchParams(iterations=0).iterations) == (
        1.0,
        0,
    )


def _far_scan() -> tuple[ScanMap, np.ndarray]:
    """A mapped room and a scan none of whose points lies near it (new ground)."""
    grid = ScanMap(0.0, 0.0, half_size=6.0, resolution=0.05)
    room = box(0.0, 0.0, 1.0, 1.0)
    x, y = transform((0.0, 0.0, 0.0), scan(room, (0.0, 0.0, 0.0), beams=90))
    grid.insert(0.0, 0.0, x, y)
    a = np.linspace(0.0, 2 * math.pi, 40, endpoint=False)
    return grid, np.stack((4.5 * np.cos(a), 4.5 * np.sin(a)), axis=1)


@pytest.mark.parametrize(
    ("start", "prediction"),
    [
        ((0.3, 0.1, 0.1), (0.5, 0.8, 0.3)),
        ((-0.2, 0.4, -0.3), (0.1, -0.3, 0.2)),
        ((0.6, -0.5, 0.4), (-0.4, 0.2, -0.1)),
        ((0.1, 0.9, 0.2), (0.0, 1.0, 0.2)),
    ],
)
def test_where_the_scan_matches_nothing_the_prior_brings_the_pose_to_the_prediction(
    start: Pose, prediction: Pose
) -> None:
    """No point near the map: the cost is the prior alone (plus a constant), whose
    minimum is the prediction; one Gauss-Newton step on a quadratic lands there."""
    grid, pts = _far_scan()
    p = MatchParams(prior=2.0, yaw_scale=1.5)
    pose, steps = refine(grid, pts, start, prediction, p)
    assert pose == pytest.approx(prediction, abs=1e-9)
    assert steps >= 1


def test_with_no_prior_an_exact_tie_in_the_search_keeps_the_prediction() -> None:
    """Every candidate of the window costs the same (nothing near the map, no prior):
    the tie goes to the candidate nearest the prediction, the prediction itself."""
    grid, pts = _far_scan()
    prediction = (0.2, -0.1, 0.4)
    best, cost = correlative_search(grid, pts, prediction, MatchParams(prior=0.0))
    assert best == prediction
    assert cost == pytest.approx(pts.shape[0] * MatchParams().max_distance ** 2)


def test_an_empty_map_takes_no_gauss_newton_step() -> None:
    result = match_scan(
        ScanMap(0.0, 0.0, half_size=2.0), _far_scan()[1], (0.1, 0.2, 0.3), MatchParams()
    )
    assert result == (((0.1, 0.2, 0.3)), False, 0.0, result.rms, 0)
    assert math.isnan(result.rms)


def test_match_params_are_frozen_and_slotted() -> None:
    p = MatchParams()
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.prior = 2.0  # type: ignore[misc]
    assert not hasattr(p, "__dict__")


@pytest.mark.parametrize(
    ("offset", "prior", "yaw_scale"),
    [
        ((0.04, 0.05, 0.03), 2.0, 1.5),
        ((-0.03, -0.04, -0.04), 8.0, 0.7),
        ((0.0, 0.06, 0.0), 0.5, 2.0),
        ((0.05, -0.03, 0.02), 1.0, 1.0),
    ],
)
@pytest.mark.parametrize("normal", [(0.0, 1.0), (1.0, 0.0)])
def test_along_one_straight_wall_refinement_ends_at_the_documented_minimum(
    offset: tuple[float, float, float], prior: float, yaw_scale: float, normal: tuple[float, float]
) -> None:
    """One long wall (y = 1 or x = 1): every matched point's residual is its distance
    beyond the wall's line (point to line), whichever return it pairs with, so the
    documented cost sum(r^2) + prior * (dx^2 + dy^2 + (yaw_scale * dyaw)^2) is smooth;
    its minimum (found here by Newton's method on exact derivatives) is where
    refinement ends."""
    nx, ny = normal
    wall: list[Segment] = [(-6.0, 1.0, 6.0, 1.0)] if ny else [(1.0, -6.0, 1.0, 6.0)]
    grid = ScanMap(0.0, 0.0, half_size=6.0, resolution=0.05)
    x, y = transform((0.0, 0.0, 0.0), scan(wall, (0.0, 0.0, 0.0), beams=360))
    grid.insert(0.0, 0.0, x, y)
    truth = (0.2, -0.1, 0.05)
    pts = scan(wall, truth, beams=180)
    along = pts[:, 0] * ny - pts[:, 1] * nx  # along the wall, in base_link
    pts = pts[np.abs(along) < 2.5]  # well inside the mapped stretch
    pred = (truth[0] + offset[0], truth[1] + offset[1], truth[2] + offset[2])
    p = MatchParams(prior=prior, yaw_scale=yaw_scale, iterations=30)
    w = np.array([prior, prior, prior * yaw_scale**2])
    q = np.array(pred)
    for _ in range(50):
        c, s = math.cos(q[2]), math.sin(q[2])
        px, py = pts[:, 0], pts[:, 1]
        r = nx * (q[0] + c * px - s * py) + ny * (q[1] + s * px + c * py) - 1.0
        j = np.stack(
            (
                np.full_like(r, nx),
                np.full_like(r, ny),
                nx * (-s * px - c * py) + ny * (c * px - s * py),
            ),
            axis=1,
        )
        ddr = nx * (-c * px + s * py) + ny * (-s * px - c * py)
        g = 2 * (j.T @ r) + 2 * w * (q - np.array(pred))
        h = 2 * (j.T @ j) + 2 * np.diag(w)
        h[2, 2] += 2 * float(r @ ddr)
        q = q + np.linalg.solve(h, -g)
    pose, _ = refine(grid, pts, pred, pred, p)
    assert pose == pytest.approx(tuple(q), abs=1e-4)  # the steps stop under 1e-4
    assert abs(q[2] - pred[2]) > 1e-3 or offset[2] == 0.0  # the scan moved the yaw
