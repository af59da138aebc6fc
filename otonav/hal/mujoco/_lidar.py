"""The world's lidar (:class:`Lidar`): beams from a site, cast by ``mj_multiRay``;
in a world of many static boxes those are cast in numpy (ADR 0057), MuJoCo casting the
moving geoms and any beam the numpy caster is not sure of: the same returns."""

from __future__ import annotations

from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from otonav.hal._raycast import StaticGeometry, StaticGeoms, StaticRayCaster
from otonav.hal._types import LidarSpec, RangeScan
from otonav.hal.mujoco._lib import mujoco
from otonav.limits import LIDAR_CASTER_MIN_BOXES

__all__ = ["MIN_STATIC_BOXES", "Lidar", "castable", "ray_caster"]

RAY_GROUPS: Final = np.array([1, 0, 1, 0, 0, 0], dtype=np.uint8)  # groups 0 and 2
MIN_STATIC_BOXES: Final = LIDAR_CASTER_MIN_BOXES
"""Below this many static boxes MuJoCo casts everything: its one call (~50 us for the
empty arena's walls and floor, +1.8 us a box) is cheaper than the caster's numpy steps
(~0.55 ms, +0.45 us a box; ADR 0057, benchmarks/ray_bench.py)."""


def castable(m: Any, groups: NDArray[np.uint8], exclude_body: int) -> NDArray[np.bool_]:
    """Per geom: would ``mj_multiRay`` test it (MuJoCo's ``ray_eliminate``, static
    geoms included)? Excluded body, invisible by colour or material, geom group."""
    body = np.asarray(m.geom_bodyid)
    matid = np.asarray(m.geom_matid)
    alpha = np.asarray(m.geom_rgba)[:, 3]
    mat_alpha = np.asarray(m.mat_rgba)[:, 3] if m.nmat else np.zeros(0)
    invisible = np.where(matid < 0, alpha == 0, False)
    with_mat = matid >= 0
    if with_mat.any():
        invisible[with_mat] = mat_alpha[matid[with_mat]] == 0
    group = np.clip(np.asarray(m.geom_group), 0, len(groups) - 1)
    result: NDArray[np.bool_] = (body != exclude_body) & ~invisible & (groups[group] != 0)
    return result


def ray_caster(
    m: Any, d: Any, spec: LidarSpec, exclude_body: int
) -> tuple[StaticRayCaster | None, bool]:
    """The caster for this world's static geoms and whether MuJoCo must still cast the
    moving ones; ``(None, True)``: MuJoCo casts everything (fewer than
    :data:`MIN_STATIC_BOXES` boxes, a static geom of another type, or mocap bodies, whose
    'static' geoms move). ``d`` must have been through ``mj_forward``."""
    cast = castable(m, RAY_GROUPS, exclude_body)
    weld = np.asarray(m.body_weldid)[np.asarray(m.geom_bodyid)]
    static = cast & (weld == 0)
    moving = bool((cast & (weld != 0)).any())
    kind = np.asarray(m.geom_type)
    box = static & (kind == mujoco.mjtGeom.mjGEOM_BOX)
    plane = static & (kind == mujoco.mjtGeom.mjGEOM_PLANE)
    if m.nmocap > 0 or (static & ~box & ~plane).any() or box.sum() < MIN_STATIC_BOXES:
        return None, True
    bodies = np.unique(np.asarray(m.geom_bodyid)[static])
    body_row = np.full(m.nbody, -1, dtype=np.int64)
    body_row[bodies] = np.arange(len(bodies))
    center = np.full((len(bodies), 3), np.nan)
    ssz = np.zeros(len(bodies))
    for row, b in enumerate(bodies):
        adr = int(m.body_bvhadr[b])
        if adr >= 0:
            aabb = np.asarray(m.bvh_aabb[adr], dtype=np.float64)
            center[row] = aabb[0:3] + np.asarray(d.xipos[b])  # MuJoCo's mju_add3
            half = aabb[3:6]
            ssz[row] = half[0] * half[0] + half[1] * half[1] + half[2] * half[2]

    def part(mask: NDArray[np.bool_]) -> StaticGeoms:
        ids = np.flatnonzero(mask)
        return StaticGeoms(
            ids=ids.astype(np.int32),
            pos=np.array(d.geom_xpos[ids], dtype=np.float64).reshape(-1, 3),
            mat=np.array(d.geom_xmat[ids], dtype=np.float64).reshape(-1, 9),
            size=np.array(m.geom_size[ids], dtype=np.float64).reshape(-1, 3),
            rbound=np.array(m.geom_rbound[ids], dtype=np.float64),
            aabb=np.array(m.geom_aabb[ids], dtype=np.float64).reshape(-1, 6),
            body=body_row[np.asarray(m.geom_bodyid)[ids]],
        )

    geometry = StaticGeometry(part(box), part(plane), center, ssz)
    caster = StaticRayCaster(geometry, spec)
    return caster, moving


class Lidar:
    """``spec``'s beams from site ``site`` of the compiled world ``m``, ``d``, blind to
    body ``body`` (the robot's own). ``d`` must have been through ``mj_forward``; a
    :meth:`scan` reads ``d`` as it is (the world brings it up to date first)."""

    def __init__(self, m: Any, d: Any, spec: LidarSpec, *, site: int, body: int) -> None:
        self.spec = spec
        self._m, self._d, self._site, self._body = m, d, site, body
        n = spec.beams
        angles = spec.angles()
        self._beams_local = np.zeros((n, 3))  # beam directions in the site frame
        self._beams_local[:, 0] = np.cos(angles)
        self._beams_local[:, 1] = np.sin(angles)
        self._vec = np.zeros((n, 3))
        self._vec_flat = self._vec.reshape(-1)  # a view: filled by matmul(out=)
        self._origin = np.zeros(3)
        self._geom = np.full(n, -1, dtype=np.int32)
        self._dist = np.full(n, -1.0)
        self._is_floor = np.asarray(m.geom_type == mujoco.mjtGeom.mjGEOM_PLANE, dtype=np.bool_)
        self._caster, self._cast_moving = ray_caster(m, d, spec, body)
        if self._caster is not None:
            self._moving_geom = np.full(n, -1, dtype=np.int32)
            self._moving_dist = np.full(n, -1.0)

    def scan(self) -> RangeScan:
        d = self._d
        rot = d.site_xmat[self._site].reshape(3, 3)
        np.matmul(self._beams_local, rot.T, out=self._vec)
        self._origin[:] = d.site_xpos[self._site]
        if self._caster is None:
            self._cast(self._vec_flat, self._geom, self._dist, static=True)
        else:
            self._cast_static_apart(rot)
        return self.spec.scan(self._dist, self._geom >= 0)

    def _cast(
        self,
        vec: NDArray[np.float64],
        geom: NDArray[np.int32],
        dist: NDArray[np.float64],
        *,
        static: bool,
    ) -> None:
        mujoco.mj_multiRay(
            self._m,
            self._d,
            self._origin,
            vec,
            RAY_GROUPS,
            1 if static else 0,
            self._body,
            geom,
            dist,
            None,
            len(geom),
            self.spec.range_max,
        )

    def _cast_static_apart(self, rot: NDArray[np.float64]) -> None:
        """The numpy caster for the static geoms, MuJoCo for the moving ones (none:
        no call) and for any beam the caster is not sure of: the same returns as one
        ``mj_multiRay`` over everything (ADR 0057)."""
        assert self._caster is not None
        geom, dist = self._geom, self._dist
        unsure = self._caster.cast(self._origin, rot, self._vec, geom, dist)
        if self._cast_moving:
            mg, md = self._moving_geom, self._moving_dist
            self._cast(self._vec_flat, mg, md, static=False)
            # one cast keeps the nearest, the first (lower id) of equal distances
            take = (md >= 0) & ((dist < 0) | (md < dist) | ((md == dist) & (mg < geom)))
            geom[take] = mg[take]
            dist[take] = md[take]
        if unsure.any():
            beams = np.flatnonzero(unsure)
            sub_geom = np.full(len(beams), -1, dtype=np.int32)
            sub_dist = np.full(len(beams), -1.0)
            vec = np.ascontiguousarray(self._vec[beams]).reshape(-1)
            self._cast(vec, sub_geom, sub_dist, static=True)
            geom[beams] = sub_geom
            dist[beams] = sub_dist

    def hit_geoms(self) -> NDArray[np.int32]:
        """Geom id hit by each beam of the last :meth:`scan` (-1: miss). A copy."""
        return self._geom.copy()

    def floor_mask(self) -> NDArray[np.bool_]:
        """Per beam of the last :meth:`scan`: did it hit a floor plane within range?"""
        geoms, dist = self._geom, self._dist
        in_range = (geoms >= 0) & (dist >= self.spec.range_min) & (dist <= self.spec.range_max)
        mask = np.zeros(self.spec.beams, dtype=np.bool_)
        mask[in_range] = self._is_floor[geoms[in_range]]
        return mask
