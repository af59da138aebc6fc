"""The global planner's grid from the map: coarse cells that pass a gap at the robot's
real limit (issue 24, ADR 0043).

Units: m; arrays are rows = y, columns = x, as in :mod:`otonav.nav._costmap`.

The map answers, per fine cell (5 cm), a lower bound ``M`` on the distance to the
nearest return: the distance between the two cell centres ``d`` less the slack
``s = resolution * sqrt 2``. A* runs on a coarser grid (``stride`` fine cells a side,
10 cm by default) because it costs per cell. Two choices make that grid exact enough
for doors at the passable limit ``2 c + resolution`` (``c`` the centre clearance):

* **max-pooling**, not sampling: a coarse cell is as good as its best fine cell. A
  door's free band (the fine cells near its middle) is one fine cell wide at the limit;
  sampling one fine cell per block misses it at half the alignments, the block's best
  cell never does. The band is continuous, so the coarse cells it crosses are
  8-connected, and A* finds them.
* **the threshold on the centre distance**, not on the lower bound: free when
  ``d >= c - resolution / 2``, i.e. ``M >= c - resolution / 2 - s``. Against a wall
  square to the grid, a return's cell centre is within half a cell of the return
  across the wall, so a fine cell centre on a door's middle passes exactly when the
  door is at least ``2 c + resolution`` wide, and a narrower door never passes. (The
  old test, ``M >= c`` at one sampled cell, refused doors under ``2 (c + s) +
  stride`` = 0.94 m.) A* only chooses the route; the local planner checks every arc
  against the scan's exact returns (:mod:`otonav.nav._local_clearance`).

The path runs through each coarse cell's best fine cell (:func:`best_points`): the
middle of a door, not a block corner 3.5 cm off it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

__all__ = ("best_points", "free_threshold", "pooled")


def free_threshold(radius: float, resolution: float) -> float:
    """The smallest map value (the lower bound ``M``) a fine cell may have and still
    be free for the global planner, m (module docstring)."""
    return radius - 0.5 * resolution - resolution * math.sqrt(2.0)


def pooled(fine: NDArray[np.float32], stride: int) -> NDArray[np.float32]:
    """The largest value in every ``stride`` x ``stride`` block of ``fine`` (a square
    grid; a ragged edge is dropped). At ``stride`` 1 that is ``fine`` itself, returned
    as is, not copied (the replan's set-up at the map's own resolution): read it only,
    a write would go into the map."""
    if stride == 1:
        return fine
    n = fine.shape[0] // stride
    # np.maximum over the stride**2 strided views: ~0.15 ms where a reshape and
    # .max(axis=(1, 3)) took ~3.3 ms (measured, 400 x 400 at stride 2).
    out: NDArray[np.float32] = fine[0 : n * stride : stride, 0 : n * stride : stride].copy()
    for i in range(stride):
        for j in range(stride):
            if i or j:
                np.maximum(out, fine[i : n * stride : stride, j : n * stride : stride], out=out)
    return out


def best_points(
    fine: NDArray[np.float32],
    stride: int,
    rows: NDArray[np.intp],
    cols: NDArray[np.intp],
) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """For coarse cells ``(rows, cols)``, the fine (row, col) of the largest value in
    each block (the first one on ties, row-major). At ``stride`` 1 every block is its
    one cell: ``rows`` and ``cols`` themselves are returned, not copies."""
    if stride == 1:
        return rows, cols
    n = fine.shape[0] // stride
    blocks = fine[: n * stride, : n * stride].reshape(n, stride, n, stride)
    picked = blocks[rows, :, cols, :].reshape(rows.shape[0], stride * stride)
    k = picked.argmax(axis=1)
    return rows * stride + k // stride, cols * stride + k % stride
