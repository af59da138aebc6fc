"""The localizer's map (otonav.nav._scan_map) against its module docstring written as plain
loops, on random scans of random boxes seen from random poses, with stray returns and
returns off the map (issue 24, test rigor):

* stored returns: per cell, the first return of the scan that fell in it, the first
  time a scan put one there; each with the normal of :func:`normals`;
* the distance field (``nearest``): per cell, the distance from its centre to the
  nearest stored return, capped at ``max_distance``;
* ``correspond``: the stored return nearest the point's cell centre, if one is closer
  than the cap (the earlier stored on a tie);
* occupancy: per scan, ``-MISS`` once on every cell a beam's samples (one a cell along
  the beam, up to one cell short of its return) fall in, the return's own cell
  excepted, then ``+HIT`` once on every cell a return falls in, clamped to +-CLAMP; a
  cell either touched is known.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_scans import box, scan

from otonav.nav._scan_map import CLAMP, HIT, MISS, ScanMap, normals
from otonav.nav._scan_match import transform

pytestmark = pytest.mark.unit


def _normals(x: np.ndarray, y: np.ndarray, res: float) -> list[tuple[float, float]]:
    out = [(0.0, 0.0)] * len(x)
    for i in range(1, len(x) - 1):
        tx, ty = x[i + 1] - x[i - 1], y[i + 1] - y[i - 1]
        chord = math.hypot(tx, ty)
        back = math.hypot(x[i] - x[i - 1], y[i] - y[i - 1])
        ahead = math.hypot(x[i + 1] - x[i], y[i + 1] - y[i])
        if back < 4 * res and ahead < 4 * res and chord > 0.0 and back + ahead < 1.1 * chord:
            out[i] = (-ty / chord, tx / chord)
    return out


class _Reference:
    """The map by the docstring, cell by cell."""

    def __init__(self, grid: ScanMap) -> None:
        self.g = grid
        self.n = grid.size
        self.stored: list[tuple[float, float, float, float]] = []
        self.occupied: set[int] = set()
        self.odds = np.zeros(self.n * self.n)
        self.known = np.zeros(self.n * self.n, dtype=bool)

    def cell(self, x: float, y: float) -> int | None:
        c = math.floor((x - self.g.origin_x) / self.g.resolution)
        r = math.floor((y - self.g.origin_y) / self.g.resolution)
        return r * self.n + c if 0 <= c < self.n and 0 <= r < self.n else None

    def insert(self, sx: float, sy: float, x: np.ndarray, y: np.ndarray) -> int:
        res, n = self.g.resolution, self.n
        crossed: set[int] = set()
        for px, py in zip(x.tolist(), y.tolist(), strict=True):
            u0, v0 = (sx - self.g.origin_x) / res, (sy - self.g.origin_y) / res
            du, dv = (px - sx) / res, (py - sy) / res
            length = math.hypot(du, dv)
            end = math.floor(v0 + dv) * n + math.floor(u0 + du)
            for k in range(max(math.floor(length - 1.0) + 1, 0)):
                u, v = u0 + du * k / length, v0 + dv * k / length
                if 0.0 <= u < n and 0.0 <= v < n and int(v) * n + int(u) != end:
                    crossed.add(int(v) * n + int(u))
        for c in crossed:
            self.odds[c] = max(self.odds[c] - MISS, -CLAMP)
            self.known[c] = True
        hits: set[int] = set()
        fresh: dict[int, int] = {}
        nrm = _normals(x, y, res)
        for i, (px, py) in enumerate(zip(x.tolist(), y.tolist(), strict=True)):
            hit = self.cell(px, py)
            if hit is None:
                continue
            hits.add(hit)
            if hit not in self.occupied and hit not in fresh:
                fresh[hit] = i
        for c in hits:
            self.odds[c] = min(self.odds[c] + HIT, CLAMP)
            self.known[c] = True
        for c in sorted(fresh):
            i = fresh[c]
            self.stored.append((float(x[i]), float(y[i]), *nrm[i]))
            self.occupied.add(c)
        return len(fresh)

    def centre(self, x: float, y: float) -> tuple[float, float]:
        res = self.g.resolution
        c = math.floor((x - self.g.origin_x) / res)
        r = math.floor((y - self.g.origin_y) / res)
        return self.g.origin_x + (c + 0.5) * res, self.g.origin_y + (r + 0.5) * res

    def nearest(self, x: float, y: float) -> tuple[float, int]:
        """(capped distance, index of the nearest stored return or -1)."""
        cx, cy = self.centre(x, y)
        best, index = self.g.max_distance, -1
        for j, (qx, qy, _, _) in enumerate(self.stored):
            d = math.hypot(cx - qx, cy - qy)
            if d < best:
                best, index = d, j
        return best, index


def _scans(
    rng: np.random.Generator, grid: ScanMap
) -> list[tuple[float, float, np.ndarray, np.ndarray]]:
    world = box(0.0, 0.0, 1.3, 1.1) + box(
        float(rng.uniform(-0.5, 0.5)), float(rng.uniform(-0.5, 0.5)), 0.15, 0.2
    )
    out = []
    for _ in range(3):
        pose = (float(rng.uniform(-0.8, 0.8)), float(rng.uniform(-0.7, 0.7)), 0.0)
        if abs(pose[0]) < 0.8 and abs(pose[1]) < 0.8:
            pose = (pose[0], 0.9 * math.copysign(1.0, pose[1]) * 0.85, float(rng.uniform(-3, 3)))
        pts = scan(world, pose, beams=int(rng.integers(60, 180)))
        stray = rng.uniform(-1.6, 1.6, (int(rng.integers(0, 6)), 2))  # some off the map
        x, y = transform(pose, pts)
        out.append(
            (pose[0], pose[1], np.concatenate((x, stray[:, 0])), np.concatenate((y, stray[:, 1])))
        )
    return out


@pytest.mark.parametrize("seed", range(6))
def test_the_map_is_its_docstring_cell_by_cell(seed: int) -> None:
    rng = np.random.default_rng(seed)
    res = float(rng.choice([0.05, 0.1]))
    cap = float(rng.uniform(0.12, 0.35))
    grid = ScanMap(
        float(rng.uniform(-0.1, 0.1)),
        float(rng.uniform(-0.1, 0.1)),
        half_size=1.2,
        resolution=res,
        max_distance=cap,
    )
    ref = _Reference(grid)
    for sx, sy, x, y in _scans(rng, grid):
        assert grid.insert(sx, sy, x, y) == ref.insert(sx, sy, x, y)
    assert grid.cells == len(ref.stored)
    assert len(ref.stored) > 20
    # the fields at every cell centre and at random points within the map
    n = grid.size
    centres = (np.arange(n) + 0.5) * res
    qx = np.concatenate((np.tile(grid.origin_x + centres, n), rng.uniform(-1.2, 1.2, 300)))
    qy = np.concatenate((np.repeat(grid.origin_y + centres, n), rng.uniform(-1.2, 1.2, 300)))
    inside = [ref.cell(a, b) is not None for a, b in zip(qx.tolist(), qy.tolist(), strict=True)]
    qx, qy = qx[inside], qy[inside]
    d = grid.nearest(qx, qy)
    px, py, nx, ny, found = grid.correspond(qx, qy)
    normals_seen = 0
    for i, (a, b) in enumerate(zip(qx.tolist(), qy.tolist(), strict=True)):
        dist, j = ref.nearest(a, b)
        assert d[i] == pytest.approx(dist, abs=1e-9), (a, b)
        assert bool(found[i]) == (j >= 0), (a, b)
        if j >= 0:
            assert (px[i], py[i], nx[i], ny[i]) == pytest.approx(ref.stored[j], abs=1e-12)
            normals_seen += nx[i] != 0.0 or ny[i] != 0.0
    assert normals_seen > 0
    assert not found.all()
    # occupancy: the known box, -1 unknown, the probability in %
    known = ref.known.reshape(n, n)
    rows, cols = np.flatnonzero(known.any(axis=1)), np.flatnonzero(known.any(axis=0))
    r0, c0, h, w, cells = grid.occupancy()
    assert (r0, c0, h, w) == (rows[0], cols[0], rows[-1] + 1 - rows[0], cols[-1] + 1 - cols[0])
    odds = ref.odds.reshape(n, n)[r0 : r0 + h, c0 : c0 + w]
    want = np.where(
        known[r0 : r0 + h, c0 : c0 + w], np.rint(100.0 / (1.0 + np.exp(-odds))), -1
    ).reshape(-1)
    assert cells.tolist() == want.astype(int).tolist()
    assert grid.log_odds.reshape(-1) == pytest.approx(ref.odds, abs=1e-5)


def test_far_outside_the_map_is_the_cap_and_no_return() -> None:
    grid = ScanMap(0.0, 0.0, half_size=1.0, resolution=0.1, max_distance=0.3)
    grid.insert(0.0, 0.0, np.array([0.95, -0.95, 0.0]), np.array([0.95, -0.95, 0.95]))
    far = np.array([5.0, -5.0, 0.0, 0.0]), np.array([0.0, 0.0, 5.0, -5.0])
    assert grid.nearest(*far).tolist() == [0.3] * 4
    assert not grid.correspond(*far)[4].any()


@pytest.mark.parametrize("seed", range(4))
def test_normals_are_the_chords_of_one_surface(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    res = 0.05
    # a wall with jitter, gaps and a corner, in beam order
    t = np.sort(rng.uniform(0.0, 1.0, 60))
    x = np.where(t < 0.5, t, 0.5 + rng.normal(0, 0.01, 60))
    y = np.where(t < 0.5, 0.3 + rng.normal(0, 0.01, 60), 0.3 + (t - 0.5))
    x[rng.integers(0, 60, 4)] += 0.5  # strays
    nx, ny = normals(x, y, res)
    want = _normals(x, y, res)
    assert np.stack((nx, ny), axis=1) == pytest.approx(np.array(want), abs=1e-12)
    assert 0 < int((nx != 0.0).sum()) < 58
    assert normals(x[:2], y[:2], res)[0].tolist() == [0.0, 0.0]


def test_far_beyond_each_edge_is_the_cap_even_beside_a_return_at_that_edge() -> None:
    """A return in the middle of each edge row/column stamps the distance field a few
    cells beyond the map; a point far beyond that edge reads the cap, and no return."""
    grid = ScanMap(0.0, 0.0, half_size=1.0, resolution=0.1, max_distance=0.3)
    xs, ys = np.array([0.05, 0.05, -0.99, 0.99]), np.array([-0.99, 0.99, 0.05, 0.05])
    grid.insert(0.0, 0.0, xs, ys)
    far = np.array([0.05, 0.05, -5.0, 5.0]), np.array([-5.0, 5.0, 0.05, 0.05])
    assert grid.nearest(*far).tolist() == [0.3] * 4
    assert not grid.correspond(*far)[4].any()


def test_an_empty_map_has_no_occupancy_cells() -> None:
    assert ScanMap(0.0, 0.0, half_size=1.0, resolution=0.1).occupancy()[4].size == 0


def test_three_returns_on_a_line_give_the_middle_one_a_normal() -> None:
    nx, ny = normals(np.array([0.0, 0.05, 0.1]), np.array([1.0, 1.0, 1.0]), 0.05)
    assert (nx.tolist(), np.abs(ny).tolist()) == ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0])


def test_one_scan_of_more_returns_than_twice_the_first_allocation_is_stored() -> None:
    grid = ScanMap(0.0, 0.0, half_size=4.0, resolution=0.05)
    k = np.arange(3000, dtype=np.float64)
    c = (k % 150) * 0.05 - 3.725  # cell centres
    r = (k // 150) * 0.05 - 3.725
    assert grid.insert(0.0, 0.0, c, r) == 3000
    qx, qy, _, _, found = grid.correspond(c, r)
    assert found.all()
    assert (qx.tolist(), qy.tolist()) == (c.tolist(), r.tolist())


def _known(grid: ScanMap) -> set[tuple[int, int]]:
    rows, cols = np.nonzero(grid.known)
    return set(zip(rows.tolist(), cols.tolist(), strict=True))


def test_beams_mark_exactly_the_cells_their_samples_fall_in_up_to_the_map_edges() -> None:
    """Exact binary fractions (1/8 m cells, 16 a side, origin -1): samples land on cell
    edges exactly, where a cell's lower edge is in it and the map's upper edge is not."""

    def fresh() -> ScanMap:
        return ScanMap(0.0, 0.0, half_size=1.0, resolution=0.125)

    # along +x from the map's lower-left corner to beyond the right edge: samples at
    # u = 0, 1, ..., 17 on row 0; the cells 0-15 of row 0, nothing past the edge
    g = fresh()
    g.insert(-1.0, -1.0, np.array([1.375]), np.array([-1.0]))
    assert _known(g) == {(0, c) for c in range(16)}
    # along +y from column 12, row 12, to beyond the top: rows 12-15 only (u = 16 is out)
    g = fresh()
    g.insert(0.5625, 0.5, np.array([0.5625]), np.array([1.5]))
    assert _known(g) == {(r, 12) for r in range(12, 16)}
    g = fresh()
    g.insert(0.5, 0.5625, np.array([1.5]), np.array([0.5625]))
    assert _known(g) == {(12, c) for c in range(12, 16)}
    # one sample: a return 1.5 cells away marks the sensor's cell as a miss
    g = fresh()
    g.insert(0.0625, 0.0625, np.array([0.25]), np.array([0.0625]))
    assert g.log_odds[8, 8] == pytest.approx(-MISS)
    assert g.log_odds[8, 10] == pytest.approx(HIT)
    assert _known(g) == {(8, 8), (8, 10)}
    # a return under a cell away, across a cell edge: no sample, only the hit
    g = fresh()
    g.insert(0.1, 0.0625, np.array([0.175]), np.array([0.0625]))
    assert _known(g) == {(8, 9)}


@pytest.mark.parametrize("seed", range(3))
def test_beyond_the_edge_the_field_is_the_capped_distance_from_the_cell_centre(
    seed: int,
) -> None:
    """``nearest``'s docstring: outside the map too, the distance from the centre of the
    cell a point falls in to the nearest stored return, capped: a return on the edge is
    as near from just outside (within ``max_distance``) as from inside; farther out, the
    cap. Returns in the edge cells, points at cell centres up to 6 cells beyond."""
    rng = np.random.default_rng(700 + seed)
    res, cap = 0.1, float(rng.choice([0.25, 0.3]))
    grid = ScanMap(0.0, 0.0, half_size=1.0, resolution=res, max_distance=cap)
    n = grid.size
    edge = [(i, j) for i in range(n) for j in range(n) if min(i, j, n - 1 - i, n - 1 - j) == 0]
    picked = rng.choice(len(edge), 12, replace=False)
    cells = [edge[k] for k in picked.tolist()]
    off = rng.uniform(0.01, 0.99, (len(cells), 2))
    rx = np.array(
        [grid.origin_x + (c + u) * res for (_, c), (u, _) in zip(cells, off, strict=True)]
    )
    ry = np.array(
        [grid.origin_y + (r + v) * res for (r, _), (_, v) in zip(cells, off, strict=True)]
    )
    assert grid.insert(0.0, 0.0, rx, ry) == len(cells)
    k = np.arange(-6, n + 6)
    cx = grid.origin_x + (k + 0.5) * res
    qx, qy = (a.ravel() for a in np.meshgrid(cx, cx))
    got = grid.nearest(qx, qy)
    want = [
        min(cap, min(math.hypot(x - px, y - py) for px, py in zip(rx, ry, strict=True)))
        for x, y in zip(qx.tolist(), qy.tolist(), strict=True)
    ]
    assert got.tolist() == pytest.approx(want, abs=1e-12)
    outside = (np.abs(qx) > 1.0) | (np.abs(qy) > 1.0)
    assert (got[outside] < cap).sum() > 10  # the field does run on past the edge
