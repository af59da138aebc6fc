"""Scan-to-map matching: where a scan fits the map best, near a predicted pose.

Units: m, rad; poses ``(x, y, yaw)`` of base_link in the map frame; scan points in
base_link. Two stages, both deterministic:

1. **Correlative search** (Olson 2009, "Real-time correlative scan matching"): every
   pose of a window around the prediction (``linear_window`` m in x and y at
   ``linear_step``, ``angular_window`` rad at ``angular_step``) is scored by the sum of
   the squared distances (:meth:`ScanMap.nearest`, capped) of the scan's points to the
   map, plus a small pull toward the prediction (``prior``): where the map cannot tell
   poses apart (a corridor's length) the prediction wins, and an exact tie goes to the
   candidate nearest it.
2. **Gauss-Newton** (Hector SLAM's refinement, on point-to-line residuals as in
   point-to-plane ICP), from the prediction and, when the search found another best
   candidate, from that one too; the lower final cost wins (the prediction's on an exact
   tie, as in the search). Each scan point is paired with the stored return nearest its
   cell (:meth:`ScanMap.correspond`, looked up again at every step) and its residual is
   the distance along that return's normal; minimise
   ``sum(r_i^2) + prior * |pose - prediction|^2`` (yaw weighted by ``yaw_scale`` m per
   rad). Points farther than
   ``max_distance`` from any stored return (new ground, outliers) are left out. The
   prior keeps a direction the scan does not constrain at the prediction instead of
   letting it wander (a corridor, a single wall). Each step is accepted if it does not
   raise the cost (an equal cost counts: at the minimum the step is zero, it is taken,
   counted in ``MatchResult.iterations``, and ends the refinement as converged); a step
   that raises it is retried with Levenberg-Marquardt damping (1e-3, tenfold up to 1;
   when none is accepted the refinement stops). It also stops after a step that moves x,
   y and yaw each by less than 1e-4 (m, rad), and after ``iterations`` steps.

A match is trusted (``ok``) when at least ``min_inliers`` of the points lie within
``max_distance`` of the map; otherwise the caller keeps its prediction.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from otonav.nav._geometry import wrap_angle
from otonav.nav._scan_map import ScanMap
from otonav.params import MatchParams

__all__ = (
    "MatchParams",
    "MatchResult",
    "Pose",
    "compose",
    "correlative_search",
    "inverse",
    "match_scan",
    "refine",
    "transform",
)

Pose = tuple[float, float, float]
Array = NDArray[np.float64]


class MatchResult(NamedTuple):
    """Where the scan fits.

    Attributes:
        pose: the matched pose (the prediction when not ``ok``).
        ok: enough points matched to trust it.
        inliers: fraction of points within ``max_distance`` of the map.
        rms: root mean square distance of those points to the map after the match, m.
        iterations: Gauss-Newton steps taken.
    """

    pose: Pose
    ok: bool
    inliers: float
    rms: float
    iterations: int


def compose(a: Pose, b: Pose) -> Pose:
    """``a * b``: the pose ``b`` (given in ``a``'s frame) in ``a``'s parent frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap_angle(a[2] + b[2]))


def inverse(a: Pose) -> Pose:
    """The pose that composes with ``a`` to the identity."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], wrap_angle(-a[2]))


def transform(pose: Pose, points: Array) -> tuple[Array, Array]:
    """``(N, 2)`` points of ``pose``'s frame in its parent frame, as x and y arrays."""
    c, s = math.cos(pose[2]), math.sin(pose[2])
    px, py = points[:, 0], points[:, 1]
    return pose[0] + c * px - s * py, pose[1] + s * px + c * py


def _offsets(window: float, step: float) -> Array:
    """``0, +-step, +-2 step ...`` up to ``window``, nearest zero first."""
    k = math.floor(window / step + 1e-9)
    ladder = [0.0]
    for i in range(1, k + 1):
        ladder += [i * step, -i * step]
    return np.array(ladder)


def correlative_search(
    grid: ScanMap, points: Array, prediction: Pose, params: MatchParams
) -> tuple[Pose, float]:
    """The best pose of the search window (module docstring) and its cost."""
    cap = params.max_distance
    lin = _offsets(params.linear_window, params.linear_step)
    ang = _offsets(params.angular_window, params.angular_step)
    dx = np.repeat(lin, lin.shape[0])
    dy = np.tile(lin, lin.shape[0])
    n = points.shape[0]
    best_cost, best = math.inf, prediction
    x0, y0, yaw0 = prediction
    scale2 = params.yaw_scale**2
    for da in ang.tolist():  # nearest the prediction first: a tie keeps the earlier
        yaw = yaw0 + da
        c, s = math.cos(yaw), math.sin(yaw)
        px = x0 + c * points[:, 0] - s * points[:, 1]
        py = y0 + s * points[:, 0] + c * points[:, 1]
        d = grid.nearest(
            (px[None, :] + dx[:, None]).ravel(), (py[None, :] + dy[:, None]).ravel()
        ).reshape(dx.shape[0], n)
        np.minimum(d, cap, out=d)
        cost = (d * d).sum(axis=1) + params.prior * (dx * dx + dy * dy + scale2 * da * da)
        i = int(cost.argmin())
        if cost[i] < best_cost:
            best_cost = float(cost[i])
            best = (x0 + float(dx[i]), y0 + float(dy[i]), wrap_angle(yaw))
    return best, best_cost


class _Linearized(NamedTuple):
    cost: float
    r: Array
    """per point residual, m (0 for outliers)"""
    jx: Array
    jy: Array
    """d r / d (x, y) per point"""
    inliers: NDArray[np.bool_]


def _linearize(
    grid: ScanMap, points: Array, pose: Pose, prediction: Pose, params: MatchParams
) -> _Linearized:
    """The refinement's cost at ``pose``: each point against the stored return nearest
    its cell (:meth:`ScanMap.correspond`), along that return's normal (point to line);
    points with no return within ``max_distance``, or whose return has no normal (an
    edge, a lone return: point to point would invent constraints along a wall from
    where the returns happened to fall), are left out of the fit; those with no return
    near count ``max_distance^2`` each in the cost. Plus the prior."""
    px, py = transform(pose, points)
    qx, qy, nx, ny, found = grid.correspond(px, py)
    ex, ey = px - qx, py - qy
    near = found & (np.hypot(ex, ey) < params.max_distance)
    inliers = near & ((nx != 0.0) | (ny != 0.0))
    r: Array = np.where(inliers, nx * ex + ny * ey, 0.0)
    # a point with no return near counts as far as the cap (a truncated quadratic):
    # else a pose that leaves more points unmatched would look better
    missed = params.max_distance**2 * float(points.shape[0] - int(near.sum()))
    jx = np.where(inliers, nx, 0.0)
    jy = np.where(inliers, ny, 0.0)
    ex0, ey0 = pose[0] - prediction[0], pose[1] - prediction[1]
    ea = params.yaw_scale * wrap_angle(pose[2] - prediction[2])
    cost = float(r @ r) + missed + params.prior * (ex0 * ex0 + ey0 * ey0 + ea * ea)
    return _Linearized(cost, r, jx, jy, inliers)


def refine(
    grid: ScanMap, points: Array, start: Pose, prediction: Pose, params: MatchParams
) -> tuple[Pose, int]:
    """Damped Gauss-Newton from ``start`` (module docstring), the correspondences
    looked up again at every step (ICP); the pose and the number of steps taken."""
    pose = start
    lin = _linearize(grid, points, pose, prediction, params)
    damping = 0.0
    prior = params.prior
    w2 = prior * params.yaw_scale**2
    steps = 0
    for _ in range(params.iterations):
        c, s = math.cos(pose[2]), math.sin(pose[2])
        # d(point)/d(yaw) = R'(yaw) p
        dpx = -s * points[:, 0] - c * points[:, 1]
        dpy = c * points[:, 0] - s * points[:, 1]
        J = np.stack((lin.jx, lin.jy, lin.jx * dpx + lin.jy * dpy), axis=1)
        H = J.T @ J
        g = J.T @ lin.r
        ex, ey = pose[0] - prediction[0], pose[1] - prediction[1]
        ea = wrap_angle(pose[2] - prediction[2])
        H += np.diag((prior, prior, w2))
        g += np.array((prior * ex, prior * ey, w2 * ea))
        accepted = False
        while damping <= 1.0:
            A = H + damping * np.diag(np.diag(H))
            try:
                delta = np.linalg.solve(A, -g)
            except np.linalg.LinAlgError:  # no prior and a scan that constrains nothing
                break
            trial = (pose[0] + delta[0], pose[1] + delta[1], wrap_angle(pose[2] + delta[2]))
            t_lin = _linearize(grid, points, trial, prediction, params)
            if t_lin.cost <= lin.cost:
                pose, lin = trial, t_lin
                damping = damping * 0.1 if damping > 1e-6 else 0.0
                accepted = True
                break
            damping = 1e-3 if damping == 0.0 else damping * 10.0
        if not accepted:
            break
        steps += 1
        if abs(delta[0]) < 1e-4 and abs(delta[1]) < 1e-4 and abs(delta[2]) < 1e-4:
            break
    return pose, steps


def match_scan(grid: ScanMap, points: Array, prediction: Pose, params: MatchParams) -> MatchResult:
    """Match ``points`` (base_link, ``(N, 2)`` m) to ``grid`` near ``prediction``
    (module docstring)."""
    n = points.shape[0]
    if n == 0 or grid.cells == 0:
        return MatchResult(prediction, False, 0.0, math.nan, 0)
    coarse, _ = correlative_search(grid, points, prediction, params)
    pose, steps = refine(grid, points, prediction, prediction, params)
    lin = _linearize(grid, points, pose, prediction, params)
    if coarse != prediction:
        # the search's best may be another basin: refine it too, keep the lower cost
        # (where the map cannot tell, the prior makes that the prediction's)
        other, other_steps = refine(grid, points, coarse, prediction, params)
        other_lin = _linearize(grid, points, other, prediction, params)
        if other_lin.cost < lin.cost:
            pose, steps, lin = other, other_steps, other_lin
    share = float(lin.inliers.mean())
    rms = float(np.sqrt((lin.r[lin.inliers] ** 2).mean())) if lin.inliers.any() else math.nan
    ok = share >= params.min_inliers
    return MatchResult(pose if ok else prediction, ok, share, rms, steps)
