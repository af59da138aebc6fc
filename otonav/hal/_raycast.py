"""A lidar ray caster for a world's static boxes and planes, in numpy (ADR 0057).

MuJoCo's ``mj_multiRay`` tests every geom of the world for every beam (~5.5 ns a box a
beam, ADR 0048), so a scan's cost grows with the world. A beam only ever meets the few
boxes in its direction before the first one stops it; this caster finds those and
returns **the same floats and geom ids as** ``mj_multiRay``:

1. *Per box*: MuJoCo's own cutoff (the box is dropped when its centre is farther than
   ``cutoff + rbound`` from the lidar, the same arithmetic); the box's extent across
   the scan plane (no beam can meet a box that does not cross it) and the disc that
   holds its outline projected on that plane, whose angular interval seen from the
   lidar (1e-9 rad of slack) names the beams that can meet it; the box's distance to
   the lidar bounds every hit on it from below.
2. *Per (beam, box) pair*: an ordinary slab test (any rounding) gives where the beam
   enters each box. The boxes the last scan hit and the nearest ones go first; their
   clear hits bound each beam, so the boxes wholly behind them and the pairs past them
   are dropped, and only the pairs that could come first (or graze) go on.
3. *MuJoCo's arithmetic* (``ray_box``/``ray_plane`` of MuJoCo 4.0, every operation in
   the same order, no fused multiply-add) decides those pairs; per beam the smallest
   distance wins, ties to the lower geom id (MuJoCo's loop order). Planes are cast
   against every beam steep enough to meet them the same way (MuJoCo 4.0 does not drop
   a plane by the cutoff), and a static body's bounding sphere test too.
4. *What cannot be replicated bit for bit* is MuJoCo's per-geom angular bounds (its
   ``atan2``); they only ever drop a pair whose hit lies on the box's silhouette. A
   winner that does not enter its face squarely and well inside is checked against
   them; a beam within 1e-9 rad of them, or whose pruning bound in step 2 no exact hit
   met, is returned as *unsure*: the caller casts it with MuJoCo itself.

Everything here is numpy; the MuJoCo side (which geoms are static, the fallback cast)
lives in :mod:`otonav.hal.mujoco._lidar`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from otonav.hal._types import LidarSpec

__all__ = ["StaticGeometry", "StaticGeoms", "StaticRayCaster"]

_MINVAL: Final = 1e-15  # MuJoCo's mjMINVAL
_PI: Final = math.pi
_SLACK: Final = 1e-9  # m and rad: far above float64 rounding at lidar ranges (~1e-15)
_CLEAR: Final = 1e-6  # m: a slab-test hit with a chord this long is certainly a hit
_CORNERS: Final = np.array(
    [[(v & 1) * 2 - 1, (v >> 1 & 1) * 2 - 1, (v >> 2 & 1) * 2 - 1] for v in range(8)],
    dtype=np.float64,
)  # MuJoCo's order of a box's corners
_SIGNS: Final = np.array([[1.0, 1.0, 1.0, 1.0], [1.0, 1.0, -1.0, -1.0], [1.0, -1.0, 1.0, -1.0]])
_NEAR_FIRST: Final = 16  # boxes cast before the rest, nearest first
_WIDE: Final = 24  # beams: a box wider than this is cast after the narrow ones
_FACING: Final = 1e-3  # cosine: a face seen less squarely than this is checked
_NO_ID: Final = np.iinfo(np.int64).max

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
Mask = NDArray[np.bool_]
_Found = list[tuple[I64, F64, I64, Mask]]  # (beams, distances, geom ids, deep) per caster


@dataclass(frozen=True, slots=True)
class StaticGeoms:
    """Static geoms of one type as MuJoCo placed them: their MuJoCo ``ids``, ``pos``
    (``geom_xpos``), ``mat`` (``geom_xmat``, row-major), ``size``, ``rbound``, ``aabb``
    and ``body``, their row in :class:`StaticGeometry`'s bodies."""

    ids: NDArray[np.int32]
    pos: F64
    mat: F64
    size: F64
    rbound: F64
    aabb: F64
    body: I64


@dataclass(frozen=True, slots=True)
class StaticGeometry:
    """The static geoms a lidar may hit, boxes and planes apart, and the bounding
    sphere of each static body (``body_center``, ``body_ssz`` the squared radius; NaN
    centre: the body has none and is never skipped)."""

    boxes: StaticGeoms
    planes: StaticGeoms
    body_center: F64
    body_ssz: F64


def _sphere_hit(center: F64, ssz: F64, pnt: F64, vec: F64) -> Mask:
    """MuJoCo's ``ray_sphere(center, ssz) >= 0``; ``center``/``ssz`` broadcast against
    the rays ``vec`` (..., 3), the same operations in the same order."""
    d0 = pnt[0] - center[..., 0]
    d1 = pnt[1] - center[..., 1]
    d2 = pnt[2] - center[..., 2]
    v0, v1, v2 = vec[..., 0], vec[..., 1], vec[..., 2]
    a = v0 * v0 + v1 * v1 + v2 * v2
    b = v0 * d0 + v1 * d1 + v2 * d2
    c = d0 * d0 + d1 * d1 + d2 * d2 - ssz
    det = b * b - a * c
    ok = det >= _MINVAL
    root = np.sqrt(np.where(ok, det, 0.0))
    result: Mask = ok & (((-b - root) / a >= 0) | ((-b + root) / a >= 0))
    return result


def _ray_map(pos: F64, mat: F64, pnt: F64, vec: F64) -> tuple[F64, F64]:
    """MuJoCo's ``ray_map``: the ray in each geom's frame (``pos`` (P, 3), ``mat``
    (P, 9), ``vec`` (P, 3)); column j is ``mat[j]*dif[0] + mat[3+j]*dif[1] + ...``."""
    dif = pnt - pos
    lpnt = mat[:, 0:3] * dif[:, 0:1] + mat[:, 3:6] * dif[:, 1:2] + mat[:, 6:9] * dif[:, 2:3]
    lvec = mat[:, 0:3] * vec[:, 0:1] + mat[:, 3:6] * vec[:, 1:2] + mat[:, 6:9] * vec[:, 2:3]
    return lpnt, lvec


_FACE0: Final = (1, 0, 0)  # MuJoCo's iface: the two other axes of each face's normal
_FACE1: Final = (2, 2, 1)


def ray_box(pos: F64, mat: F64, size: F64, pnt: F64, vec: F64) -> F64:
    """MuJoCo 4.0's ``ray_box`` for P (box, ray) pairs: distance along ``vec`` to the
    nearest face, -1 for none; the same floats as ``mju_rayGeom`` (tested)."""
    ssz = size[:, 0] * size[:, 0] + size[:, 1] * size[:, 1] + size[:, 2] * size[:, 2]
    near = _sphere_hit(pos, ssz, pnt, vec)
    lpnt, lvec = _ray_map(pos, mat, pnt, vec)
    best = np.full(len(pos), np.inf)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for i in range(3):
            j0, j1 = _FACE0[i], _FACE1[i]
            usable = np.abs(lvec[:, i]) > _MINVAL
            for side in (-1.0, 1.0):
                sol = (side * size[:, i] - lpnt[:, i]) / lvec[:, i]
                p0 = lpnt[:, j0] + sol * lvec[:, j0]
                p1 = lpnt[:, j1] + sol * lvec[:, j1]
                take = (
                    usable
                    & (sol >= 0)
                    & (np.abs(p0) <= size[:, j0])
                    & (np.abs(p1) <= size[:, j1])
                    & (sol < best)
                )
                best = np.where(take, sol, best)
    result: F64 = np.where(near & (best < np.inf), best, -1.0)
    return result


def _entry_face(pos: F64, mat: F64, size: F64, pnt: F64, vec: F64, axis: I64, side: F64) -> F64:
    """MuJoCo's ``ray_box`` distance to one face (``axis``, ``side``) per pair: its
    ``ray_map`` row for that axis and ``(side*size - lpnt)/lvec``, the same floats."""
    rows = np.arange(len(pos))
    m0 = mat[rows, axis]
    m1 = mat[rows, axis + 3]
    m2 = mat[rows, axis + 6]
    lpnt = m0 * (pnt[0] - pos[:, 0]) + m1 * (pnt[1] - pos[:, 1]) + m2 * (pnt[2] - pos[:, 2])
    lvec = m0 * vec[:, 0] + m1 * vec[:, 1] + m2 * vec[:, 2]
    with np.errstate(over="ignore"):
        result: F64 = (side * size[rows, axis] - lpnt) / lvec
    return result


def ray_plane(pos: F64, mat: F64, size: F64, pnt: F64, vec: F64) -> F64:
    """MuJoCo 4.0's ``ray_plane`` for P (plane, ray) pairs (front face only, within the
    rendered rectangle when its size is positive); -1 for none."""
    lpnt, lvec = _ray_map(pos, mat, pnt, vec)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        x = -lpnt[:, 2] / lvec[:, 2]
        p0 = lpnt[:, 0] + x * lvec[:, 0]
        p1 = lpnt[:, 1] + x * lvec[:, 1]
    inside = ((size[:, 0] <= 0) | (np.abs(p0) <= size[:, 0])) & (
        (size[:, 1] <= 0) | (np.abs(p1) <= size[:, 1])
    )
    take = (lvec[:, 2] <= -_MINVAL) & (x >= 0) & inside
    result: F64 = np.where(take, x, -1.0)
    return result


def _unsure_angles(aabb: F64, pos: F64, mat: F64, pnt: F64, vec: F64, which: I64) -> Mask:
    """Per ray: could MuJoCo's bounding angles (``mju_multiRayPrepare``: azimuth and
    elevation of the geom's AABB corners) have skipped geom ``which[ray]`` (a row of
    ``aabb``/``pos``/``mat``)? True when the ray lies outside them or within ``_SLACK``
    rad of an edge, or a choice between the full sphere and the corners' span is that
    close."""
    signs = _CORNERS
    loc = [aabb[:, None, j] + signs[None, :, j] * aabb[:, None, 3 + j] for j in range(3)]
    world = [
        mat[:, 3 * i, None] * loc[0]
        + mat[:, 3 * i + 1, None] * loc[1]
        + mat[:, 3 * i + 2, None] * loc[2]
        + (pos[:, i, None] - pnt[i])
        for i in range(3)
    ]
    az = np.arctan2(world[1], world[0])
    el = np.arctan2(np.sqrt(world[0] * world[0] + world[1] * world[1]), world[2])
    az_lo, az_hi = az.min(axis=1), az.max(axis=1)
    el_lo, el_hi = el.min(axis=1), el.max(axis=1)
    # MuJoCo's point_in_box: the lidar inside the geom's AABB, in the geom's frame
    d = pnt - pos
    rel = (
        np.stack(
            [
                mat[:, i] * d[:, 0] + mat[:, 3 + i] * d[:, 1] + mat[:, 6 + i] * d[:, 2]
                for i in range(3)
            ],
            axis=1,
        )
        - aabb[:, 0:3]
    )
    slack = np.abs(rel) - aabb[:, 3:6]
    inside = (slack <= 0).all(axis=1)
    span = az_hi - az_lo
    full = inside | (span > _PI)
    full_unsure = (np.abs(slack) <= _SLACK).any(axis=1) | (np.abs(span - _PI) <= _SLACK)
    ray_az = np.arctan2(vec[:, 1], vec[:, 0])
    ray_el = np.arctan2(np.sqrt(vec[:, 0] * vec[:, 0] + vec[:, 1] * vec[:, 1]), vec[:, 2])
    within = (
        (ray_az >= az_lo[which] + _SLACK)
        & (ray_az <= az_hi[which] - _SLACK)
        & (ray_el >= el_lo[which] + _SLACK)
        & (ray_el <= el_hi[which] - _SLACK)
    )
    unsure: Mask = full_unsure[which] | ~(full[which] | within)
    return unsure


class _Slabs:
    """The slab test of (beam, box) pairs in each box's frame, any rounding: where a
    beam enters and leaves a box, and whether that is clear of every edge and face
    plane (``_CLEAR``) or grazes one (then only MuJoCo's arithmetic can say)."""

    def __init__(self, lp: F64, size: F64, ax: F64, ay: F64, cos: F64, sin: F64) -> None:
        # one row per box (lidar, half sizes, the lidar's x and y axes, in the box's
        # frame): one gather per batch of pairs instead of four
        self.rows = np.concatenate([lp, size, ax, ay], axis=1)
        self.cos, self.sin = cos[:, None], sin[:, None]

    def pairs(
        self, boxes: I64, lo: I64, count: I64, nb: int, bound: F64, lower: F64 | None = None
    ) -> tuple[I64, I64, F64, Mask, Mask]:
        """Test every beam each of ``boxes`` may meet (``lower``: only where the beam's
        ``bound`` does not stop it first); the clear hits lower ``bound``. Returns per
        pair: box, beam, first hit, clear, grazing. Call under ``np.errstate`` ignoring
        division, invalid and overflow (beams parallel to a face)."""
        c = count[boxes]
        total = int(c.sum())
        box = np.repeat(boxes, c)
        first = np.cumsum(c) - c
        beam = (np.repeat(lo[boxes] - first, c) + np.arange(total)) % nb
        if lower is not None:
            ahead = lower[box] <= bound[beam]
            box, beam = box[ahead], beam[ahead]
        p, s, lv, t1, t2 = self._slabs(box, beam)
        lo_t = np.fmin(t1, t2)
        hi_t = np.fmax(t1, t2)
        t_in = np.maximum(np.maximum(lo_t[:, 0], lo_t[:, 1]), lo_t[:, 2])
        t_out = np.minimum(np.minimum(hi_t[:, 0], hi_t[:, 1]), hi_t[:, 2])
        # along a face's plane (or nearly): the slab test cannot say; MuJoCo's can
        along = (np.abs(lv) <= _SLACK) & (np.abs(np.abs(p) - s) <= _CLEAR)
        edge = along[:, 0] | along[:, 1] | along[:, 2]
        edge |= np.isnan(t_in) | np.isnan(t_out)
        chord = t_out - np.maximum(t_in, 0.0)
        clear = (chord > _CLEAR) & (np.abs(t_in) > _CLEAR) & ~edge
        first_hit = np.where(t_in >= 0, t_in, t_out)
        graze = ~clear & (edge | ((t_out >= -_CLEAR) & (t_in - t_out <= _CLEAR)))
        if clear.any():
            reach = first_hit[clear]
            np.minimum.at(bound, beam[clear], reach + _SLACK * (1.0 + reach))
        return box, beam, first_hit, clear, graze

    def _slabs(self, box: I64, beam: I64) -> tuple[F64, F64, F64, F64, F64]:
        """Per pair: the lidar and the beam in the box's frame, and where the beam
        crosses each face's plane (the same floats for a pair, whatever the batch)."""
        rows = self.rows[box]
        p, s = rows[:, 0:3], rows[:, 3:6]
        lv = self.cos[beam] * rows[:, 6:9] + self.sin[beam] * rows[:, 9:12]
        return p, s, lv, (-s - p) / lv, (s - p) / lv

    def faces(self, box: I64, beam: I64, clear: Mask) -> tuple[I64, F64, Mask]:
        """For the pairs that go on to MuJoCo's arithmetic: the face a clear entry from
        outside meets away from its edges (-1: none; then MuJoCo's ray_box returns that
        face's distance, the only other face it meets being the exit), its side, and
        whether the entry is deep inside the face (see ``pairs`` for ``np.errstate``)."""
        p, s, lv, t1, t2 = self._slabs(box, beam)
        lo_t = np.fmin(t1, t2)
        t_in = np.maximum(np.maximum(lo_t[:, 0], lo_t[:, 1]), lo_t[:, 2])
        axis = np.argmax(np.where(np.isnan(lo_t), -np.inf, lo_t), axis=1)
        rows = np.arange(len(box))
        excess = np.abs(p + t_in[:, None] * lv) - s
        excess[rows, axis] = -np.inf
        inner = np.maximum(np.maximum(excess[:, 0], excess[:, 1]), excess[:, 2])
        face = np.where(clear & (t_in > 0) & (inner < -_SLACK), axis, -1)
        facing = lv[rows, axis]
        side = np.where(facing > 0, -1.0, 1.0)
        # entering 1e-6 m inside its face, not edge-on: MuJoCo's bounding angles, which
        # hold the box, hold this beam by far more than atan2's rounding (ADR 0057)
        deep = (face >= 0) & (np.abs(facing) >= _FACING) & (inner < -_CLEAR)
        return face, side, deep


class StaticRayCaster:
    """Casts ``spec``'s planar fan of beams (in the lidar's xy plane) against
    :class:`StaticGeometry`, as ``mj_multiRay`` with ``spec.range_max`` as the cutoff
    would (see the module's docstring)."""

    def __init__(self, geometry: StaticGeometry, spec: LidarSpec) -> None:
        self._g = geometry
        self._angle_min = spec.angle_min
        self._inc = spec.increment
        self._nb = spec.beams
        angles = spec.angles()
        self._cos = np.cos(angles)
        self._sin = np.sin(angles)
        self._cutoff = cutoff = spec.range_max
        self._reach = cutoff + geometry.boxes.rbound  # MuJoCo: dist > cutoff + rbound drops it
        self._last_boxes = np.zeros(0, dtype=np.int64)  # boxes hit by the last scan
        self._has_spheres = bool(np.isfinite(geometry.body_center[:, 0]).any())
        # row (n, i): box n's axis i in the world (column i of its row-major xmat)
        self._box_rows = np.ascontiguousarray(
            geometry.boxes.mat.reshape(-1, 3, 3).transpose(0, 2, 1).reshape(-1, 3)
        )
        self._axes = self._box_rows.reshape(-1, 3, 3)  # [n, i, j]: box axis i, world j
        ids = np.concatenate([geometry.boxes.ids, geometry.planes.ids]).astype(np.int64)
        self._row_of = np.zeros(int(ids.max()) + 1 if len(ids) else 1, dtype=np.int64)
        self._row_of[ids] = np.arange(len(ids))
        self._all_aabb = np.concatenate([geometry.boxes.aabb, geometry.planes.aabb])
        self._all_pos = np.concatenate([geometry.boxes.pos, geometry.planes.pos])
        self._all_mat = np.concatenate([geometry.boxes.mat, geometry.planes.mat])

    def cast(self, pnt: F64, rot: F64, vec: F64, geom: NDArray[np.int32], dist: F64) -> Mask:
        """Fill ``geom`` (-1: none) and ``dist`` (-1: none) per beam as ``mj_multiRay``
        would for the static geoms; ``rot`` is the lidar frame (columns: its axes),
        ``vec`` the beams in the world (``rot @ (cos, sin, 0)``). Returns the beams whose
        result is not certain to be MuJoCo's: cast those with MuJoCo."""
        nb = self._nb
        body_ok = self._body_ok(pnt, vec)
        found: _Found = []
        self._planes(pnt, vec, body_ok, found)
        bound = self._boxes(pnt, rot, vec, body_ok, found)
        best_t = np.full(nb, np.inf)
        best_id = np.full(nb, _NO_ID, dtype=np.int64)
        if found:
            beam = np.concatenate([f[0] for f in found])
            t = np.concatenate([f[1] for f in found])
            ids = np.concatenate([f[2] for f in found])
            deep = np.concatenate([f[3] for f in found])
            hit = t >= 0
            beam, t, ids, deep = beam[hit], t[hit], ids[hit], deep[hit]
            np.minimum.at(best_t, beam, t)
            tie = t == best_t[beam]  # MuJoCo keeps the first of equal distances: lower id
            np.minimum.at(best_id, beam[tie], ids[tie])
            winner = tie & (ids == best_id[beam])
            sure = np.zeros(nb, dtype=np.bool_)
            sure[beam[winner & deep]] = True
        else:
            sure = np.zeros(nb, dtype=np.bool_)
        # a pruning bound that no exact hit met: the pairs it dropped may matter
        unsure = np.isfinite(bound) & ~(best_t <= bound)
        won = np.isfinite(best_t)
        check = won & ~sure
        if check.any():
            unsure |= self._winners_unsure(pnt, vec, check, best_id)
        geom.fill(-1)
        dist.fill(-1.0)
        geom[won] = best_id[won]
        dist[won] = best_t[won]
        return unsure

    # -- the parts --------------------------------------------------------------------

    def _body_ok(self, pnt: F64, vec: F64) -> Mask | None:
        """(bodies, beams): does the beam pass MuJoCo's bounding sphere of the body?"""
        if not self._has_spheres:
            return None
        g = self._g
        d = pnt - g.body_center
        inside = (d * d).sum(axis=1) < g.body_ssz - _SLACK
        if bool((inside | ~np.isfinite(g.body_center[:, 0])).all()):
            return None  # inside (or no sphere): MuJoCo's test passes every beam
        ok = _sphere_hit(g.body_center[:, None, :], g.body_ssz[:, None], pnt, vec[None, :, :])
        ok |= ~np.isfinite(g.body_center[:, 0])[:, None]
        return ok

    def _planes(self, pnt: F64, vec: F64, body_ok: Mask | None, found: _Found) -> None:
        g = self._g
        beams = np.arange(self._nb)
        for k in range(len(g.planes.ids)):
            d = g.planes.pos[k] - pnt  # (MuJoCo 4.0 never drops a plane by the cutoff)
            mat = g.planes.mat[k]
            lvec2 = mat[2] * vec[:, 0] + mat[5] * vec[:, 1] + mat[8] * vec[:, 2]
            # ray_plane's first test, and: a beam too shallow to meet the (finite)
            # rectangle, |lvec_z| < h / sqrt(h^2 + R^2), h the lidar's height over the
            # plane, R the rectangle's half-diagonal plus the lidar's offset in the plane
            steep = -_MINVAL
            size = g.planes.size[k]
            height = -(mat[2] * d[0] + mat[5] * d[1] + mat[8] * d[2])
            if size[0] > 0 and size[1] > 0 and height > 0:
                offset = math.sqrt(max(0.0, float(d @ d) - height * height))
                reach = math.hypot(size[0], size[1]) + offset
                steep = min(steep, -0.99 * height / math.hypot(height, reach))
            down = np.flatnonzero(lvec2 <= steep)
            if body_ok is not None:
                down = down[body_ok[g.planes.body[k], down]]
            if len(down) == 0:
                continue
            m = len(down)
            t = ray_plane(
                np.broadcast_to(g.planes.pos[k], (m, 3)),
                np.broadcast_to(mat, (m, 9)),
                np.broadcast_to(g.planes.size[k], (m, 3)),
                pnt,
                vec[down],
            )
            ids = np.full(m, g.planes.ids[k], dtype=np.int64)
            found.append((beams[down], t, ids, np.zeros(m, dtype=np.bool_)))

    def _boxes(self, pnt: F64, rot: F64, vec: F64, body_ok: Mask | None, found: _Found) -> F64:
        """Cast the boxes; returns the per-beam bound used to drop pairs (inf: none)."""
        g = self._g
        nb = self._nb
        bound = np.full(nb, np.inf)
        if len(g.boxes.ids) == 0:
            return bound
        dif = g.boxes.pos - pnt
        d0, d1, d2 = dif[:, 0], dif[:, 1], dif[:, 2]
        d3 = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        local = dif @ rot  # box centres in the lidar frame (pruning only: any rounding)
        frames = (self._box_rows @ rot).reshape(-1, 3, 3)  # [n, i, a]: lidar axis a
        az = frames[:, :, 2]
        size = g.boxes.size
        # the box's half-extent across the scan plane; it must reach the plane
        across = size[:, 0] * np.abs(az[:, 0]) + size[:, 1] * np.abs(az[:, 1])
        across += size[:, 2] * np.abs(az[:, 2])
        # MuJoCo's cutoff (the same floats) and the plane
        # (the boxes dropped go on with the others to the pairs, which leave them out:
        # cheaper than copying the arrays of those kept)
        keep = ~(d3 > self._reach) & (np.abs(local[:, 2]) <= across + _SLACK)
        m = self._axes  # [n, i, j]: box axis i, world j
        # the disc holding the box's outline projected on the scan plane: the largest
        # of |g0 +- g1 +- g2|, g_i = size_i * (box axis i in the lidar's x, y); numpy's
        # reductions over a short last axis cost ~10x its columns (so columns, below)
        gx = size * frames[:, :, 0]
        gy = size * frames[:, :, 1]
        cx = gx @ _SIGNS
        cy = gy @ _SIGNS
        r2 = cx * cx + cy * cy
        r2max = np.maximum(np.maximum(r2[:, 0], r2[:, 1]), np.maximum(r2[:, 2], r2[:, 3]))
        radius = np.sqrt(r2max) * (1.0 + _SLACK) + _SLACK
        plane_d = np.sqrt(local[:, 0] * local[:, 0] + local[:, 1] * local[:, 1])
        full = plane_d <= radius
        half = np.arcsin(np.where(full, 1.0, radius / np.where(full, 1.0, plane_d)))
        centre = np.arctan2(local[:, 1], local[:, 0])
        lo = np.ceil((centre - half - _SLACK - self._angle_min) / self._inc).astype(np.int64)
        hi = np.floor((centre + half + _SLACK - self._angle_min) / self._inc).astype(np.int64)
        count = np.where(full, nb, np.minimum(np.maximum(hi - lo + 1, 0), nb))
        lo = np.where(full, 0, lo % nb)
        # the lidar in each box's frame, and its distance to the box: no hit is nearer
        lp = np.empty_like(size)
        for i in range(3):
            lp[:, i] = -(m[:, i, 0] * dif[:, 0] + m[:, i, 1] * dif[:, 1] + m[:, i, 2] * dif[:, 2])
        out = np.maximum(np.abs(lp) - size, 0.0)
        out *= out
        lower = np.sqrt(out[:, 0] + out[:, 1] + out[:, 2]) - _SLACK
        slab = _Slabs(lp, size, frames[:, :, 0], frames[:, :, 1], self._cos, self._sin)
        # first the boxes that stopped a beam last scan and the nearest ones, not the
        # wide ones (an order only: their clear hits bound the beams for the others)
        n = len(g.boxes.ids)
        first = np.zeros(n, dtype=np.bool_)
        if n > _NEAR_FIRST:
            first[np.argpartition(lower, _NEAR_FIRST)[:_NEAR_FIRST]] = True
        else:
            first[:] = True
        first[self._last_boxes] = True
        first &= count <= _WIDE
        near = np.flatnonzero(first & keep)
        far = np.flatnonzero(~first & keep)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            parts = [slab.pairs(near, lo, count, nb, bound)] if len(near) else []
            if len(far):
                # a box is skipped when every beam it could meet is stopped before it
                doubled = np.concatenate([bound, bound, bound[:1]])
                ends = np.empty(2 * len(far), dtype=np.int64)
                ends[0::2] = lo[far]
                ends[1::2] = lo[far] + count[far]
                reach = np.maximum.reduceat(doubled, ends)[0::2]
                far = far[lower[far] <= reach]
                if len(far):
                    parts.append(slab.pairs(far, lo, count, nb, bound, lower))
            if not parts:
                return bound
            if len(parts) == 1:
                box, beam, first_hit, clear, graze = parts[0]
            else:
                box, beam, first_hit, clear, graze = (
                    np.concatenate([q[k] for q in parts]) for k in range(5)
                )
            limit = bound[beam]
            go = (clear & (first_hit - _SLACK <= limit)) | (graze & (lower[box] <= limit))
            if body_ok is not None:
                go &= body_ok[g.boxes.body[box], beam]
            box, beam, clear = box[go], beam[go], clear[go]
            if len(box) == 0:
                return bound
            face, side, deep = slab.faces(box, beam, clear)
        gid = box
        pos, mat, size = g.boxes.pos[gid], g.boxes.mat[gid], g.boxes.size[gid]
        t = np.empty(len(box))
        lite = face >= 0
        if lite.any():
            t[lite] = _entry_face(
                pos[lite], mat[lite], size[lite], pnt, vec[beam[lite]], face[lite], side[lite]
            )
        rest = ~lite
        if rest.any():
            t[rest] = ray_box(pos[rest], mat[rest], size[rest], pnt, vec[beam[rest]])
        found.append((beam, t, g.boxes.ids[gid].astype(np.int64), deep))
        hit = np.zeros(len(g.boxes.ids), dtype=np.bool_)
        hit[gid[t >= 0]] = True
        self._last_boxes = np.flatnonzero(hit)  # sorted, each once
        return bound

    def _winners_unsure(self, pnt: F64, vec: F64, won: Mask, best_id: NDArray[np.int64]) -> Mask:
        """Beams whose winner MuJoCo's bounding angles might have skipped."""
        beams = np.flatnonzero(won)
        ids, which = np.unique(best_id[beams], return_inverse=True)
        row = self._row_of[ids]
        out = np.zeros(self._nb, dtype=np.bool_)
        out[beams] = _unsure_angles(
            self._all_aabb[row], self._all_pos[row], self._all_mat[row], pnt, vec[beams], which
        )
        return out
