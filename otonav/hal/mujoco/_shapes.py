"""The compiled world's static geoms as the judge measures them (issue 42): boxes
(``wall*`` ones are the walls), upright cylinders, capsules and spheres as disks, meshes
as their footprint on the floor; the rest unjudged."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from otonav.hal._types import BoxObstacle, PolygonObstacle, RoundObstacle
from otonav.hal.mujoco._derive import _collides, _geom_corners
from otonav.hal.mujoco._lib import mujoco
from otonav.nav._observed_hull import convex_hull

__all__: list[str] = []


def _yaw_of_quat(w: float, x: float, y: float, z: float) -> float:
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


@dataclass(frozen=True, slots=True)
class _Shapes:
    obstacles: tuple[BoxObstacle, ...]
    walls: tuple[BoxObstacle, ...]
    rounds: tuple[RoundObstacle, ...]
    polygons: tuple[PolygonObstacle, ...]
    unjudged: tuple[str, ...]


def _static_shapes(m: Any) -> _Shapes:
    """Every static geom the robot can touch: welded to the world, colliding, not a
    plane."""
    d: Any = None
    kinds = mujoco.mjtGeom
    obstacles: list[BoxObstacle] = []
    walls: list[BoxObstacle] = []
    rounds: list[RoundObstacle] = []
    polygons: list[PolygonObstacle] = []
    unjudged: list[str] = []
    for g in range(m.ngeom):
        body = int(m.geom_bodyid[g])
        kind = int(m.geom_type[g])
        if int(m.body_weldid[body]) != 0 or kind == kinds.mjGEOM_PLANE or not _collides(m, g):
            continue
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) or f"geom {g}"
        if d is None and (body != 0 or kind == kinds.mjGEOM_MESH):
            d = mujoco.MjData(m)  # where the kinematics put a welded body's geoms
            mujoco.mj_kinematics(m, d)
        if body == 0:  # the model's floats, as before (no rounding through mj_forward)
            x, y = float(m.geom_pos[g][0]), float(m.geom_pos[g][1])
            w, qx, qy, qz = (float(v) for v in m.geom_quat[g])
            yaw = _yaw_of_quat(w, qx, qy, qz)
            upright = 1.0 - 2.0 * (qx * qx + qy * qy)
        else:
            x, y = float(d.geom_xpos[g][0]), float(d.geom_xpos[g][1])
            xmat = d.geom_xmat[g]
            yaw, upright = math.atan2(float(xmat[3]), float(xmat[0])), float(xmat[8])
        size = m.geom_size[g]
        if kind == kinds.mjGEOM_BOX:
            box = BoxObstacle(x, y, float(size[0]), float(size[1]), yaw)
            (walls if name.startswith("wall") else obstacles).append(box)
        elif kind == kinds.mjGEOM_SPHERE or (
            kind in (kinds.mjGEOM_CYLINDER, kinds.mjGEOM_CAPSULE) and upright > 1.0 - 1e-6
        ):
            rounds.append(RoundObstacle(x, y, float(size[0])))
        elif kind == kinds.mjGEOM_MESH:
            # its vertices on the floor: their convex hull (fewer than 3 corners: a mesh
            # edge-on to the floor, no area to measure from)
            corners = _geom_corners(m, d, g)
            hull = convex_hull(corners[:, 0], corners[:, 1]).tolist()
            if len(hull) >= 3:
                polygons.append(PolygonObstacle(tuple((px, py) for px, py in hull)))
            else:
                unjudged.append(f"{name} (MESH)")
        else:
            unjudged.append(f"{name} ({mujoco.mjtGeom(kind).name.removeprefix('mjGEOM_')})")
    return _Shapes(tuple(obstacles), tuple(walls), tuple(rounds), tuple(polygons), tuple(unjudged))


def _tallest_obstacle(m: Any) -> float | None:
    """m: the top of the tallest static ``obstacle*`` geom (not the arena's walls)."""
    tops = []
    for g in range(m.ngeom):
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
        if name.startswith("obstacle") and int(m.geom_bodyid[g]) == 0:
            tops.append(float(m.geom_pos[g][2] + m.geom_rbound[g]))
            if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX:  # upright: its half height
                tops[-1] = float(m.geom_pos[g][2] + m.geom_size[g][2])
    return max(tops, default=None)
