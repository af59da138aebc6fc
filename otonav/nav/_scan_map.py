"""The localizer's map: an occupancy grid built from scans at their corrected poses, and
the distance field the scan matcher (:mod:`otonav.nav._scan_match`) aligns scans to.

Frames and units: map, m. The grid is a square of ``2 * half_size`` m centred on
``(centre_x, centre_y)``, ``resolution`` m per cell, rows along y.

* **Occupancy** (what ``/map`` shows): per cell log-odds, raised by ``HIT`` where a
  return falls and lowered by ``MISS`` along each beam up to one cell short of its
  return, clamped to +-``CLAMP``. A cell no beam touched is unknown.
* **Stored returns** (what scans are matched to): a cell that holds a return for the
  first time keeps that return's exact position and its normal (:func:`normals`, from
  its neighbours in the scan). Per cell, the distance from its centre to the nearest
  stored return, capped at ``max_distance`` (:meth:`ScanMap.nearest`, the correlative
  search's lookup), and which return that is (:meth:`ScanMap.correspond`, the
  point-to-line refinement's). A new stored return updates both on a window around it
  (``np.minimum``, as :class:`otonav.nav._costmap.ClearanceMap` stamps); a cell already
  occupied costs nothing. They never forget (a static world; the occupancy does).
  Exact positions, not cell centres: matching to cell centres pulled poses half a cell
  (2.5 cm measured at 5 cm cells).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from otonav.nav._costmap import square_grid
from otonav.params import LocalizerParams

_LOC = LocalizerParams()

__all__ = ("CLAMP", "HIT", "MISS", "ScanMap", "normals")

Array = NDArray[np.float64]

HIT = 0.85
"""Log-odds added to a cell a return falls in (p = 0.7)."""
MISS = 0.4
"""Log-odds taken from a cell a beam passes through (p = 0.4)."""
CLAMP = 5.0
"""Log-odds bound, both ways: a cell can change its mind within ~6-12 scans."""


def normals(x: Array, y: Array, resolution: float) -> tuple[Array, Array]:
    """Unit normals of a scan's returns (in beam order) from their two neighbours:
    perpendicular to the chord from the previous return to the next when both lie
    within ``4 * resolution + 10 %`` of the return's distance from them (one surface);
    (0, 0) where they do not (an edge, a lone return)."""
    n = x.shape[0]
    out_x, out_y = np.zeros(n), np.zeros(n)
    if n < 3:
        return out_x, out_y
    tx = x[2:] - x[:-2]
    ty = y[2:] - y[:-2]
    chord = np.hypot(tx, ty)
    back = np.hypot(x[1:-1] - x[:-2], y[1:-1] - y[:-2])
    ahead = np.hypot(x[2:] - x[1:-1], y[2:] - y[1:-1])
    limit = 4.0 * resolution
    # one surface: both neighbours near, and the middle return close to the chord
    straight = (back < limit) & (ahead < limit) & (chord > 0.0) & (back + ahead < 1.1 * chord)
    safe = np.where(chord > 0.0, chord, 1.0)
    out_x[1:-1] = np.where(straight, -ty / safe, 0.0)
    out_y[1:-1] = np.where(straight, tx / safe, 0.0)
    return out_x, out_y


class ScanMap:
    """Occupancy log-odds and the capped distance field of one localizer. Mutable,
    plain computation (no I/O, no clock)."""

    def __init__(
        self,
        centre_x: float,
        centre_y: float,
        *,
        half_size: float = _LOC.half_size,
        resolution: float = _LOC.resolution,
        max_distance: float = _LOC.match.max_distance,
    ) -> None:
        frame = square_grid("ScanMap", centre_x, centre_y, half_size, resolution, max_distance)
        self.resolution = resolution
        self.max_distance = max_distance
        self.size, self.origin_x, self.origin_y = frame
        n = self.size
        self.occupied = np.zeros((n, n), dtype=np.bool_)
        self.log_odds = np.zeros((n, n), dtype=np.float32)
        self.known = np.zeros((n, n), dtype=np.bool_)
        k = math.ceil(max_distance / resolution)
        self._k = k
        self._pad = k + 1
        width = n + 2 * self._pad
        self._width = width
        self._field = np.full((width, width), max_distance, dtype=np.float64)
        self._flat = self._field.reshape(-1)
        # Per cell, the index of the nearest stored return (-1: none within the cap);
        # the stored returns (the first one of each occupied cell) and their normals.
        self._nearest = np.full((width, width), -1, dtype=np.intp)
        self._nearest_flat = self._nearest.reshape(-1)
        self._px = np.zeros(1024, dtype=np.float64)
        self._py = np.zeros(1024, dtype=np.float64)
        self._nx = np.zeros(1024, dtype=np.float64)
        self._ny = np.zeros(1024, dtype=np.float64)
        self._offsets = np.arange(-k, k + 1, dtype=np.float64) * resolution
        self.cells = 0
        """How many cells have held a return."""

    # -- building ----------------------------------------------------------------------

    def insert(self, sensor_x: float, sensor_y: float, x: Array, y: Array) -> int:
        """Add one scan: its returns at ``(x, y)`` (map, m) seen from the sensor at
        ``(sensor_x, sensor_y)``. Returns how many cells held a return for the first
        time (each stamps the distance field)."""
        self._misses(sensor_x, sensor_y, x, y)
        row, col, inside = self._cells(x, y)
        flat = (row * self.size + col)[inside]
        if flat.size == 0:
            return 0
        odds = self.log_odds.reshape(-1)
        hit = np.zeros(odds.shape[0], dtype=np.bool_)
        hit[flat] = True
        odds[hit] = np.minimum(odds[hit] + HIT, CLAMP)
        self.known.reshape(-1)[hit] = True
        occupied = self.occupied.reshape(-1)
        fresh = flat[~occupied[flat]]
        if fresh.size == 0:
            return 0
        # Each new cell keeps the first of the scan's returns in it, with its normal:
        # its distances to the window's cell centres, capped, stamped with np.minimum,
        # and where it is now the nearest, its index.
        order = np.argsort(fresh, kind="stable")
        cells, first = np.unique(fresh[order], return_index=True)
        index = np.flatnonzero(inside)[~occupied[flat]][order[first]]
        nx, ny = normals(x, y, self.resolution)
        span, offsets, field, n = 2 * self._k + 1, self._offsets, self._field, self.size
        res, cap, nearest = self.resolution, self.max_distance, self._nearest
        count = self.cells
        self._grow(count + int(cells.size))
        self._px[count : count + cells.size] = x[index]
        self._py[count : count + cells.size] = y[index]
        self._nx[count : count + cells.size] = nx[index]
        self._ny[count : count + cells.size] = ny[index]
        for i, (cell, px, py) in enumerate(
            zip(cells.tolist(), x[index].tolist(), y[index].tolist(), strict=True)
        ):
            occupied[cell] = True
            r, c = divmod(cell, n)  # the window's corner: (r + pad - k, c + pad - k)
            # the point relative to its cell's centre, then to every window centre
            ox = px - (self.origin_x + (c + 0.5) * res)
            oy = py - (self.origin_y + (r + 0.5) * res)
            disk = np.hypot(offsets[None, :] - ox, offsets[:, None] - oy)
            window = field[r + 1 : r + 1 + span, c + 1 : c + 1 + span]
            closer = disk < window
            np.minimum(disk, cap, out=disk)
            np.minimum(window, disk, out=window)
            nearest[r + 1 : r + 1 + span, c + 1 : c + 1 + span][closer] = count + i
        self.cells += int(cells.size)
        return int(cells.size)

    def _grow(self, need: int) -> None:
        if need <= self._px.shape[0]:
            return
        size = max(need, 2 * self._px.shape[0])
        for name in ("_px", "_py", "_nx", "_ny"):
            old = getattr(self, name)
            new = np.zeros(size, dtype=np.float64)
            new[: old.shape[0]] = old
            setattr(self, name, new)

    def _misses(self, sx: float, sy: float, x: Array, y: Array) -> None:
        """Lower the log-odds of the cells each beam crosses before its return's cell
        (each cell once per scan), sampled every cell along the beam (a beam may skip
        a cell it only clips: this is the picture on /map, not what scans match to)."""
        if x.shape[0] == 0:
            return
        inv, n = 1.0 / self.resolution, self.size
        # in cells from the map's origin
        u0, v0 = (sx - self.origin_x) * inv, (sy - self.origin_y) * inv
        du, dv = (x - sx) * inv, (y - sy) * inv
        length = np.hypot(du, dv)
        # samples at 0, 1, ... cells along the beam, up to one cell short of the return
        counts = (np.floor(length - 1.0) + 1.0).clip(0).astype(np.intp)
        total = int(counts.sum())
        if total == 0:
            return
        beam = np.repeat(np.arange(x.shape[0]), counts)
        k = np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts)
        scale = k / length[beam]
        u = u0 + du[beam] * scale
        v = v0 + dv[beam] * scale
        # (a sample one cell short of a diagonal beam's end may share its cell)
        end = np.floor(v0 + dv) * n + np.floor(u0 + du)
        inside = (u >= 0.0) & (u < n) & (v >= 0.0) & (v < n)
        flat = v.astype(np.intp) * n + u.astype(np.intp)
        inside &= flat != end[beam]
        flat = flat[inside]
        if flat.size == 0:
            return
        odds = self.log_odds.reshape(-1)
        crossed = np.zeros(odds.shape[0], dtype=np.bool_)
        crossed[flat] = True
        odds[crossed] = np.maximum(odds[crossed] - MISS, -CLAMP)
        self.known.reshape(-1)[crossed] = True

    def _cells(
        self, x: Array, y: Array
    ) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.bool_]]:
        inv, n = 1.0 / self.resolution, self.size
        col = np.floor((x - self.origin_x) * inv).astype(np.intp)
        row = np.floor((y - self.origin_y) * inv).astype(np.intp)
        inside = (col >= 0) & (col < n) & (row >= 0) & (row < n)
        return row, col, inside

    # -- reading -----------------------------------------------------------------------

    def nearest(self, x: Array, y: Array) -> Array:
        """The distance field at the cell each point falls in (no interpolation), m:
        the distance from that cell's centre to the nearest stored return, capped at
        ``max_distance``. Beyond the map's edge too: the field runs on for
        ``ceil(max_distance / resolution)`` cells past it, so a return on the edge is
        as near from a cell outside as from one inside; farther out every point
        reads ``max_distance``, what the capped distance is there anyway (no return
        is stored outside the map). The correlative search's lookup."""
        inv, pad, hi = 1.0 / self.resolution, self._pad, self._width - 1
        col = np.clip(np.floor((x - self.origin_x) * inv) + pad, 0, hi).astype(np.intp)
        row = np.clip(np.floor((y - self.origin_y) * inv) + pad, 0, hi).astype(np.intp)
        out: Array = self._flat[row * self._width + col]
        return out

    def correspond(
        self, x: Array, y: Array
    ) -> tuple[Array, Array, Array, Array, NDArray[np.bool_]]:
        """For each point, the stored return nearest its cell (within ``max_distance``)
        and that return's unit normal (0, 0 where the scan could not tell one): x, y,
        normal x, normal y, and whether there is one at all."""
        inv, pad, hi = 1.0 / self.resolution, self._pad, self._width - 1
        col = np.clip(np.floor((x - self.origin_x) * inv) + pad, 0, hi).astype(np.intp)
        row = np.clip(np.floor((y - self.origin_y) * inv) + pad, 0, hi).astype(np.intp)
        index = self._nearest_flat[row * self._width + col]
        found = index >= 0
        index = np.where(found, index, 0)
        return self._px[index], self._py[index], self._nx[index], self._ny[index], found

    def occupancy(self) -> tuple[int, int, int, int, NDArray[np.int8]]:
        """The known part of the map as ``nav_msgs/OccupancyGrid`` data: (row0, col0,
        height, width, cells), cells row-major from the lowest row, -1 unknown, else
        0-100 (the probability of occupied, %). Empty (0 x 0) with nothing known."""
        rows = np.flatnonzero(self.known.any(axis=1))
        cols = np.flatnonzero(self.known.any(axis=0))
        if rows.size == 0:
            return 0, 0, 0, 0, np.empty(0, dtype=np.int8)
        r0, r1, c0, c1 = int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
        odds = self.log_odds[r0:r1, c0:c1].astype(np.float64)
        percent = np.rint(100.0 / (1.0 + np.exp(-odds))).astype(np.int8)
        cells = np.where(self.known[r0:r1, c0:c1], percent, np.int8(-1)).astype(np.int8)
        return r0, c0, r1 - r0, c1 - c0, cells.reshape(-1)
