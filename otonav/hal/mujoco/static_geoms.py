"""Which geoms the lidar's numpy caster takes from MuJoCo (ADR 0057): the static ones
(bodies welded to the world) that a beam may hit, when they are all boxes and planes."""

from __future__ import annotations

from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from otonav.hal.mujoco._lib import mujoco
from otonav.hal.raycast import StaticGeometry, StaticRayCaster
from otonav.limits import LIDAR_CASTER_MIN_BOXES

__all__ = ["MIN_STATIC_BOXES", "castable", "ray_caster"]

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
    m: Any,
    d: Any,
    *,
    groups: NDArray[np.uint8],
    exclude_body: int,
    angle_min: float,
    increment: float,
    beams: int,
    cutoff: float,
) -> tuple[StaticRayCaster | None, bool]:
    """The caster for this world's static geoms and whether MuJoCo must still cast the
    moving ones; ``(None, True)``: MuJoCo casts everything (fewer than
    :data:`MIN_STATIC_BOXES` boxes, a static geom of another type, or mocap bodies, whose
    'static' geoms move). ``d`` must have been through ``mj_forward``."""
    cast = castable(m, groups, exclude_body)
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

    def part(mask: NDArray[np.bool_]) -> dict[str, Any]:
        ids = np.flatnonzero(mask)
        return {
            "ids": ids.astype(np.int32),
            "pos": np.array(d.geom_xpos[ids], dtype=np.float64).reshape(-1, 3),
            "mat": np.array(d.geom_xmat[ids], dtype=np.float64).reshape(-1, 9),
            "size": np.array(m.geom_size[ids], dtype=np.float64).reshape(-1, 3),
            "rbound": np.array(m.geom_rbound[ids], dtype=np.float64),
            "aabb": np.array(m.geom_aabb[ids], dtype=np.float64).reshape(-1, 6),
            "body": body_row[np.asarray(m.geom_bodyid)[ids]],
        }

    b, p = part(box), part(plane)
    geometry = StaticGeometry(
        box_ids=b["ids"],
        box_pos=b["pos"],
        box_mat=b["mat"],
        box_size=b["size"],
        box_rbound=b["rbound"],
        box_aabb=b["aabb"],
        box_body=b["body"],
        plane_ids=p["ids"],
        plane_pos=p["pos"],
        plane_mat=p["mat"],
        plane_size=p["size"],
        plane_rbound=p["rbound"],
        plane_aabb=p["aabb"],
        plane_body=p["body"],
        body_center=center,
        body_ssz=ssz,
    )
    caster = StaticRayCaster(
        geometry, angle_min=angle_min, increment=increment, beams=beams, cutoff=cutoff
    )
    return caster, moving
