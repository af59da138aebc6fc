"""The navigator's memory of the scans: a grid in odom of the cells where the lidar saw
something, and for every cell the distance to the nearest such cell.

Frames and units: odom, m. The grid is a square of ``2 * half_size`` m centred on
``(centre_x, centre_y)`` (the start pose), ``resolution`` m per cell (default 5 cm).
Outside it nothing is known.

* **Unknown is free.** A cell is occupied once a return fell in it. A route through
  space never seen is allowed; when the lidar sees it blocked the route is replanned.
* **Seen through is free** (:meth:`ClearanceMap.clear_seen`, ADR 0026): an occupied
  cell that a scan's beams pass beyond (the beam nearest its bearing and both
  neighbours report a return, or nothing, farther than the cell plus a margin) is
  cleared, and the distances around it are recomputed. So a moving obstacle's trail
  or a misread does not wall the robot in for ever. The navigator runs it before a
  replan, not on every scan (cost where it matters only).
* **Distances, not costs.** :meth:`ClearanceMap.clearance` answers, for any points, a
  lower bound on the distance to the nearest recorded return, capped at
  ``max_distance``: the distance between cell centres minus ``resolution * sqrt(2)``
  (each of the two points may sit anywhere in its cell), stored that way per cell.
  The local planner checks its rollouts against it and the global planner its cells,
  so both use the one centre clearance of :mod:`otonav.nav._footprint`.
* **Incremental.** Marking a new cell stamps a precomputed disk of distances around it
  (``np.minimum`` on a window); a cell already occupied costs nothing. A 20 x 20 m map
  at 5 cm is 400 x 400 float32 (0.6 MB); a stamp of 0.65 m (27 x 27 cells) costs a few us;
  at 2.5 cm the acceptance run marked 3453 cells at ~10-20 us each (measured).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from otonav.nav._scan import ScanRays
from otonav.params import NavigationParams

_NAV = NavigationParams()

__all__ = ("ClearanceMap", "GridFrame", "square_grid")


class GridFrame(NamedTuple):
    """A square grid's cells per side and the map coordinates of its corner (m)."""

    size: int
    origin_x: float
    origin_y: float


def square_grid(
    owner: str,
    centre_x: float,
    centre_y: float,
    half_size: float,
    resolution: float,
    max_distance: float,
) -> GridFrame:
    """The frame of a grid of ``half_size`` m around a centre, at ``resolution`` m a cell,
    its settings checked (``owner`` names the class in the error): the navigator's
    clearance map and the localizer's scan map are laid out alike."""
    for name, value in (
        ("half_size", half_size),
        ("resolution", resolution),
        ("max_distance", max_distance),
    ):
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"{owner}.{name} must be finite and > 0 m, got {value!r}")
    if resolution > half_size:
        raise ValueError(f"resolution {resolution} m must be <= half_size {half_size} m")
    size = max(1, round(2.0 * half_size / resolution))
    return GridFrame(size, centre_x - half_size, centre_y - half_size)


class ClearanceMap:
    """Occupied cells and the (capped) distance field around them. Mutable: owned by
    one navigator; every method is plain computation (no I/O, no clock)."""

    def __init__(
        self,
        centre_x: float,
        centre_y: float,
        *,
        half_size: float = _NAV.map_half_size,
        resolution: float = _NAV.map_resolution,
        max_distance: float = 0.6,
    ) -> None:
        frame = square_grid("ClearanceMap", centre_x, centre_y, half_size, resolution, max_distance)
        self.resolution = resolution
        self.max_distance = max_distance
        self.size, self.origin_x, self.origin_y = frame
        self.occupied = np.zeros((self.size, self.size), dtype=np.bool_)
        # Per cell, what clearance() answers: the distance to the nearest occupied cell
        # less the slack (0 at least; the cap stays the cap). A border of k + 1 cells
        # all round: a stamp never needs clipping (~1 us less per new cell), the k
        # cells next to the map hold true bounds for points just outside it, and the
        # outermost ring, never stamped, stays at the cap: the answer farther out.
        k = math.ceil(max_distance / resolution)
        self._pad = k + 1
        self._lower = np.full(
            (self.size + 2 * self._pad, self.size + 2 * self._pad), max_distance, dtype=np.float32
        )
        offsets = np.arange(-k, k + 1, dtype=np.float64) * resolution
        self._k = k
        kernel = np.hypot(offsets[:, None], offsets[None, :])
        slack = resolution * math.sqrt(2.0)
        self.slack = slack
        """m: how far :meth:`clearance` may fall short of the distance between the
        query point and the return that set it (each may sit anywhere in its cell)."""
        # min over returns of max(d - slack, 0) is max(min d - slack, 0): stamping the
        # slack-reduced disk keeps the lower bound exact under np.minimum.
        self._kernel = np.where(
            kernel >= max_distance, max_distance, np.maximum(kernel - slack, 0.0)
        ).astype(np.float32)
        self._flat = self._lower.reshape(-1)  # a view: every update shows through it
        self._cells = memoryview(self._flat.data)  # float32 items, read as Python floats
        self._width = self.size + 2 * self._pad
        self.marked = 0
        self.cleared = 0

    def mark_xy(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> int:
        """Record returns (odom x and y arrays, m); returns how many cells were new.

        Cheap test first: a static world seen again marks cells it already holds, and
        then the update is a dozen numpy calls on the N points (no sort: the new
        cells are deduplicated in a set). Measured on the acceptance course: 87 -> ~35 us
        per scan in the stack."""
        if x.shape[0] == 0:
            return 0
        inv, n = 1.0 / self.resolution, self.size
        col = np.floor((x - self.origin_x) * inv).astype(np.intp)
        row = np.floor((y - self.origin_y) * inv).astype(np.intp)
        # Negative indices wrap to huge unsigned values: one comparison per axis.
        inside = (col.view(np.uintp) < n) & (row.view(np.uintp) < n)
        flat = (row * n + col)[inside]
        occupied = self.occupied.ravel()
        fresh = flat[~occupied[flat]]
        if fresh.size == 0:
            return 0
        # A set, not np.unique: a scan brings a few new cells, and np.unique's first
        # call imports numpy.ma (~8 ms, inside the first run of every process). The
        # stamps' order does not matter (np.minimum).
        new = set(fresh.tolist())
        span, kernel, lower = 2 * self._k + 1, self._kernel, self._lower
        for cell in new:
            occupied[cell] = True
            r, c = divmod(cell, n)  # the stamp's corner: (r + pad - k, c + pad - k)
            window = lower[r + 1 : r + 1 + span, c + 1 : c + 1 + span]
            np.minimum(window, kernel, out=window)
        self.marked += len(new)
        return len(new)

    def clear_seen(self, rays: ScanRays, *, reach: float, margin: float) -> int:
        """Clear the occupied cells within ``reach`` m of the laser that ``rays`` saw
        through (module docstring), ``margin`` m short of the beams' returns; returns
        how many. The distances are recomputed where a cleared cell could have set
        them: reset to the cap, then every occupied cell near there stamped again
        (stamping is idempotent elsewhere). Cells outside the scan's field of view,
        or behind its returns, are kept."""
        n, res = self.size, self.resolution
        inv = 1.0 / res
        c0 = max(math.floor((rays.x - reach - self.origin_x) * inv), 0)
        c1 = min(math.floor((rays.x + reach - self.origin_x) * inv) + 1, n)
        r0 = max(math.floor((rays.y - reach - self.origin_y) * inv), 0)
        r1 = min(math.floor((rays.y + reach - self.origin_y) * inv) + 1, n)
        if c0 >= c1 or r0 >= r1:
            return 0
        rows, cols = np.nonzero(self.occupied[r0:r1, c0:c1])
        if rows.size == 0:
            return 0
        rows += r0
        cols += c0
        dx = self.origin_x + (cols + 0.5) * res - rays.x
        dy = self.origin_y + (rows + 0.5) * res - rays.y
        d = np.hypot(dx, dy)
        beams = rays.ranges.shape[0]
        raw = np.rint(
            np.remainder(np.arctan2(dy, dx) - rays.yaw - rays.angle_min, math.tau)
            / rays.angle_increment
        ).astype(np.intp)
        full_circle = abs(beams * rays.angle_increment - math.tau) < rays.angle_increment
        beam = raw % beams if full_circle else np.minimum(raw, beams - 1)
        in_view = np.ones(raw.shape, dtype=np.bool_) if full_circle else raw < beams
        gone = in_view & (d <= reach) & (rays.seen_free()[beam] > d + margin)
        if not gone.any():
            return 0
        rr, cc = rows[gone], cols[gone]
        self.occupied[rr, cc] = False
        k = self._k
        ra, rb = max(int(rr.min()) - k, 0), min(int(rr.max()) + k + 1, n)
        ca, cb = max(int(cc.min()) - k, 0), min(int(cc.max()) + k + 1, n)
        self._restamp(ra, rb, ca, cb)
        cleared = int(rr.size)
        self.cleared += cleared
        return cleared

    def clear_near(self, x: float, y: float, radius: float) -> int:
        """Forget every occupied cell within ``radius`` m of ``(x, y)`` (a recovery:
        the next scans mark what is really there); returns how many."""
        n, res, k = self.size, self.resolution, self._k
        inv = 1.0 / res
        c0 = max(math.floor((x - radius - self.origin_x) * inv), 0)
        c1 = min(math.floor((x + radius - self.origin_x) * inv) + 1, n)
        r0 = max(math.floor((y - radius - self.origin_y) * inv), 0)
        r1 = min(math.floor((y + radius - self.origin_y) * inv) + 1, n)
        if c0 >= c1 or r0 >= r1:
            return 0
        rows, cols = np.nonzero(self.occupied[r0:r1, c0:c1])
        cx = self.origin_x + (cols + c0 + 0.5) * res - x
        cy = self.origin_y + (rows + r0 + 0.5) * res - y
        gone = np.hypot(cx, cy) <= radius
        if not gone.any():
            return 0
        rr, cc = rows[gone] + r0, cols[gone] + c0
        self.occupied[rr, cc] = False
        ra, rb = max(int(rr.min()) - k, 0), min(int(rr.max()) + k + 1, n)
        ca, cb = max(int(cc.min()) - k, 0), min(int(cc.max()) + k + 1, n)
        self._restamp(ra, rb, ca, cb)
        self.cleared += int(rr.size)
        return int(rr.size)

    def _restamp(self, ra: int, rb: int, ca: int, cb: int) -> None:
        """Recompute the distances in rows ``ra:rb``, columns ``ca:cb`` from the
        occupied cells that can reach them."""
        n, k, pad = self.size, self._k, self._pad
        self._lower[ra + pad : rb + pad, ca + pad : cb + pad] = self.max_distance
        sa, sb = max(ra - k, 0), min(rb + k, n)
        ta, tb = max(ca - k, 0), min(cb + k, n)
        near_r, near_c = np.nonzero(self.occupied[sa:sb, ta:tb])
        span, kernel, lower = 2 * k + 1, self._kernel, self._lower
        for r, c in zip((near_r + sa).tolist(), (near_c + ta).tolist(), strict=True):
            window = lower[r + 1 : r + 1 + span, c + 1 : c + 1 + span]
            np.minimum(window, kernel, out=window)

    def interior(self) -> NDArray[np.float32]:
        """:meth:`clearance` at every map cell (a read-only view, rows = y): the
        global planner pools it into its coarser grid (:mod:`otonav.nav._plan_grid`)."""
        pad = self._pad
        view = self._lower[pad : pad + self.size, pad : pad + self.size]
        view.flags.writeable = False
        return view

    def coarse(self, stride: int) -> NDArray[np.float32]:
        """clearance() at the centre cell of every ``stride`` x ``stride`` block: the
        global planner's grid (a view, rows = y)."""
        start, stop = self._pad + stride // 2, self._pad + self.size
        return self._lower[start:stop:stride, start:stop:stride]

    def clearance(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float32]:
        """Lower bound on the distance from each point to the nearest recorded return,
        m, capped at ``max_distance`` (outside the map: ``max_distance``).

        The cell indices stay floats until the last step (in-place floor, offset and
        clamp: integers this small are exact in float64) and one flat ``take`` reads
        them: 9 points cost ~10 us instead of ~21 us with ``np.clip`` and 2-D fancy
        indexing (measured; the DWA asks ~600 points per sampled step)."""
        inv, pad, hi = 1.0 / self.resolution, self._pad, self._width - 1
        col = _cell_index(x - self.origin_x, inv, pad, hi)
        row = _cell_index(y - self.origin_y, inv, pad, hi)
        row *= self._width
        row += col
        return self._flat.take(row.astype(np.intp))

    def clearance_at(self, x: float, y: float) -> float:
        """:meth:`clearance` of one point, in plain Python (~0.3 us: a handful of
        points are cheaper this way than through numpy's per-call overhead)."""
        inv, pad, hi = 1.0 / self.resolution, self._pad, self._width - 1
        col = min(max(math.floor((x - self.origin_x) * inv) + pad, 0), hi)
        row = min(max(math.floor((y - self.origin_y) * inv) + pad, 0), hi)
        return self._cells[row * self._width + col]


def _cell_index(offset: NDArray[np.float64], inv: float, pad: int, hi: int) -> NDArray[np.float64]:
    """Padded cell indices along one axis, clamped to the grid, as floats, computed in
    place in ``offset`` (metres from the origin; a fresh array the caller gives away)."""
    offset *= inv
    np.floor(offset, out=offset)
    offset += pad
    np.maximum(offset, 0.0, out=offset)
    np.minimum(offset, hi, out=offset)
    return offset
