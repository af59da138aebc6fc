"""The robot's geometry read from the compiled world at its rest pose: mass and extent
before otonav changes the model (:func:`_probe`), then wheel radius and separation,
sensor offsets and footprint, each with its source (:class:`_Derivation`); a value given
in the description wins over the derived one."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Final

import numpy as np
from numpy.typing import NDArray

from otonav.hal._types import RobotGeometry
from otonav.hal.mujoco._lib import mujoco
from otonav.hal.mujoco._prepare import ROBOT_PREFIX, _RobotSpec
from otonav.hal.mujoco._scene import SceneError, _one_line

__all__: list[str] = []


_CASTER_GAP: Final = 3e-3  # m: a geom (not a wheel's) this close to the floor is a caster


@dataclass(frozen=True, slots=True)
class _Probe:
    mass: float  # kg, the robot's
    wheel_radius: float  # m, rough (bounding sphere of the left wheel's geoms)
    top: float  # m, the highest point of the robot above its base's origin
    bottom: float  # m, the lowest point of its collision geoms above the floor
    resting: tuple[int, ...]  # the geoms other than the wheels' on the floor: casters


def _probe(parts: _RobotSpec) -> _Probe:
    """Mass and extent of the robot as modelled, before otonav changes anything."""
    try:
        model = parts.spec.copy().compile()
    except ValueError as exc:  # a missing mesh file, a bad attribute
        raise parts.fail("model", f"{parts.file} does not compile: {_one_line(exc)}") from None
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    base = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, parts.base.name))
    wheel_bodies = [
        int(model.jnt_bodyid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j.name)])
        for j in parts.joints.values()
    ]
    wheels = set(wheel_bodies)
    geoms = _subtree_geoms(model, base)
    radius = max(
        (float(model.geom_rbound[g]) for g in geoms if model.geom_bodyid[g] == wheel_bodies[0]),
        default=0.0,
    )
    lows: dict[int, float] = {}
    highs = []
    for g in geoms:
        corners = _geom_corners(model, data, g)[:, 2]
        highs.append(float(corners.max()))
        if _collides(model, g):
            lows[g] = float(corners.min())
    bottom = min(lows.values(), default=0.0)
    return _Probe(
        mass=float(model.body_subtreemass[base]),
        wheel_radius=radius,
        top=max(highs, default=0.0) - float(data.xpos[base][2]),
        bottom=bottom,
        resting=tuple(
            g
            for g, low in lows.items()
            if low - bottom < _CASTER_GAP and int(model.geom_bodyid[g]) not in wheels
        ),
    )


def _subtree_geoms(model: Any, body: int) -> list[int]:
    """The geoms of ``body`` and of every body under it."""
    under = {body}
    for b in range(body + 1, model.nbody):
        if int(model.body_parentid[b]) in under:
            under.add(b)
    return [g for g in range(model.ngeom) if int(model.geom_bodyid[g]) in under]


def _collides(model: Any, geom: int) -> bool:
    return int(model.geom_contype[geom]) != 0 or int(model.geom_conaffinity[geom]) != 0


_SIGNS: Final = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])


def _geom_half(model: Any, geom: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Centre and half sizes of a box about ``geom`` in its own frame."""
    size = model.geom_size[geom]
    kind = int(model.geom_type[geom])
    centre = np.zeros(3)
    if kind == mujoco.mjtGeom.mjGEOM_SPHERE:
        half = np.array([size[0], size[0], size[0]])
    elif kind in (mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_CAPSULE):
        extra = size[0] if kind == mujoco.mjtGeom.mjGEOM_CAPSULE else 0.0
        half = np.array([size[0], size[0], size[1] + extra])
    elif kind in (mujoco.mjtGeom.mjGEOM_BOX, mujoco.mjtGeom.mjGEOM_ELLIPSOID):
        half = np.array(size[:3], dtype=np.float64)
    else:  # mesh, hull, sdf...: MuJoCo's own bounding box in the geom frame
        aabb = model.geom_aabb[geom]
        centre, half = np.array(aabb[:3], dtype=np.float64), np.array(aabb[3:], dtype=np.float64)
    return centre, half


def _mesh_vertices(model: Any, geom: int) -> NDArray[np.float64]:
    """A mesh geom's vertices in its own frame."""
    mesh = int(model.geom_dataid[geom])
    start, count = int(model.mesh_vertadr[mesh]), int(model.mesh_vertnum[mesh])
    return np.asarray(model.mesh_vert[start : start + count], dtype=np.float64)


def _geom_corners(model: Any, data: Any, geom: int) -> NDArray[np.float64]:
    """Points that bound ``geom``, world frame: a mesh's own vertices (its bounding box
    turns with the mesh's principal axes, arbitrary about a wheel's axle, and reached
    ~14 mm under a tyre), else the 8 corners of its bounding box."""
    if int(model.geom_type[geom]) == mujoco.mjtGeom.mjGEOM_MESH:
        local = _mesh_vertices(model, geom)
    else:
        centre, half = _geom_half(model, geom)
        local = _SIGNS * half + centre
    points: NDArray[np.float64] = (
        local @ data.geom_xmat[geom].reshape(3, 3).T + data.geom_xpos[geom]
    )
    return points


def _shown_name(model: Any, kind: Any, ident: int) -> str:
    """An element's name as the user wrote it (without the attached robot's prefix)."""
    name = mujoco.mj_id2name(model, kind, ident) or f"#{ident}"
    return str(name).removeprefix(ROBOT_PREFIX)


def _actuator_of(model: Any, joint: int) -> int:
    for a in range(model.nu):
        if (
            int(model.actuator_trntype[a]) == mujoco.mjtTrn.mjTRN_JOINT
            and int(model.actuator_trnid[a][0]) == joint
        ):
            return a
    raise SceneError(f"no actuator on joint #{joint} after compiling")  # prepared: a bug


def _site_sensor(model: Any, kind: Any, site: int) -> slice:
    for i in range(model.nsensor):
        if (
            int(model.sensor_type[i]) == kind
            and int(model.sensor_objid[i]) == site
            and int(model.sensor_objtype[i]) == mujoco.mjtObj.mjOBJ_SITE
        ):
            adr = int(model.sensor_adr[i])
            return slice(adr, adr + int(model.sensor_dim[i]))
    raise SceneError(f"no {kind.name} sensor on site #{site} after compiling")  # a bug


_CENTRED: Final = 0.005
"""m: how far off base_link (the axle's midpoint, the laser on the centre line) a model
may put them before otonav refuses it (its frames have no room for the offset)."""


class _Derivation:
    """The robot's geometry read from the compiled world at its rest pose (qpos0), each
    value's source recorded; a value in the description overrides the derived one."""

    def __init__(self, model: Any, base: int, parts: _RobotSpec) -> None:
        self.model = model
        self.base = base
        self.parts = parts
        self.robot = parts.robot
        self.sources: dict[str, str] = {}
        self.data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, self.data)
        self.origin = self.data.xpos[base].copy()
        self.to_base = self.data.xmat[base].reshape(3, 3).T.copy()
        self.mover = base  # the body that moves the base: itself, or up fixed links
        while int(model.body_jntnum[self.mover]) == 0 and int(model.body_parentid[self.mover]):
            self.mover = int(model.body_parentid[self.mover])

    def in_base(self, world: NDArray[np.float64]) -> NDArray[np.float64]:
        result: NDArray[np.float64] = (world - self.origin) @ self.to_base.T
        return result

    def geometry(self, joints: tuple[int, int], lidar: int, imu: int) -> RobotGeometry:
        signs = (self.wheel_sign(joints[0]), self.wheel_sign(joints[1]))
        radius = self.wheel_radius(joints[0])
        separation = self.separation(*joints)
        laser = self.site_offset(lidar, "lidar")
        imu_pos = self.site_offset(imu, "imu")
        footprint = self.footprint()
        return RobotGeometry(
            wheel_radius=radius,
            wheel_separation=separation,
            laser_offset_x=float(laser[0]),
            laser_offset_z=float(laser[2]),
            base_height=float(self.origin[2]),
            imu_offset=(float(imu_pos[0]), float(imu_pos[1]), float(imu_pos[2])),
            footprint=footprint,
            wheel_joints=(self.robot.left_wheel, self.robot.right_wheel),
            wheel_signs=signs,
        )

    def _given(self, key: str, value: object) -> bool:
        if value is None:
            return False
        self.sources[key] = f"{self.robot.key}{key} (given)"
        return True

    def wheel_sign(self, joint: int) -> float:
        """+1 if the joint's positive turn rolls the robot forward (axle along +y of
        the base), -1 if along -y (a mirrored joint, as many models have)."""
        m = self.model
        along_y = float((self.to_base @ self.data.xaxis[joint])[1])
        if abs(along_y) < 0.9:
            name = _shown_name(m, mujoco.mjtObj.mjOBJ_JOINT, joint)
            key = "left_wheel" if name == self.robot.left_wheel else "right_wheel"
            raise self.parts.fail(
                key,
                f"joint {name!r} turns about an axis that is not the robot's left-right (y) "
                "axis: a wheel's axle must be",
            )
        return 1.0 if along_y > 0 else -1.0

    def wheel_radius(self, joint: int) -> float:
        m = self.model
        body = int(m.jnt_bodyid[joint])
        geoms = [g for g in range(m.ngeom) if int(m.geom_bodyid[g]) == body and _collides(m, g)]
        if not geoms:
            raise self.parts.fail(
                "left_wheel",
                f"joint {self.robot.left_wheel!r} moves body "
                f"{_shown_name(m, mujoco.mjtObj.mjOBJ_BODY, body)!r}, which has no "
                "collision geom: a wheel needs one to roll on",
            )
        if self._given("wheel_radius", self.robot.wheel_radius):
            return float(self.robot.wheel_radius or 0.0)
        geom = geoms[0]
        name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, geom)
        if name:
            name = repr(str(name).removeprefix(ROBOT_PREFIX))
        else:
            name = f"of body {_shown_name(m, mujoco.mjtObj.mjOBJ_BODY, body)!r}"
        kind = int(m.geom_type[geom])
        size = m.geom_size[geom]
        # The axle in the geom's frame: the wheel is round about it.
        axis = self.data.geom_xmat[geom].reshape(3, 3).T @ self.data.xaxis[joint]
        k = int(np.argmax(np.abs(axis)))
        aligned = abs(float(axis[k])) > 0.999
        round_about_z = kind in (mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_CAPSULE)
        if round_about_z and not (aligned and k == 2):
            raise self.parts.fail(
                "left_wheel",
                f"the wheel's geom {name} is a {mujoco.mjtGeom(kind).name[7:].lower()} whose "
                "axis is not the joint's axle, so it cannot roll: turn it (MJCF angles are "
                'degrees unless <compiler angle="radian"/>)',
            )
        if kind == mujoco.mjtGeom.mjGEOM_SPHERE or round_about_z:
            radius = float(size[0])
        elif kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID and aligned:
            radius = float(max(size[i] for i in range(3) if i != k))
        elif kind == mujoco.mjtGeom.mjGEOM_MESH:
            verts = _mesh_vertices(m, geom)
            unit = axis / np.linalg.norm(axis)
            off_axle = verts - np.outer(verts @ unit, unit)
            radius = float(np.max(np.linalg.norm(off_axle, axis=1)))
        else:
            radius = float(m.geom_rbound[geom])
        kind_name = mujoco.mjtGeom(kind).name.removeprefix("mjGEOM_").lower()
        self.sources["wheel_radius"] = f"derived from the {kind_name} geom {name}"
        return radius

    def separation(self, left: int, right: int) -> float:
        m = self.model
        anchors = self.in_base(np.array([self.data.xanchor[left], self.data.xanchor[right]]))
        if float(anchors[0][1]) <= float(anchors[1][1]):
            raise self.parts.fail(
                "left_wheel",
                f"joint {self.robot.left_wheel!r} is at y = {anchors[0][1]:.3f} m, not left of "
                f"{self.robot.right_wheel!r} (y = {anchors[1][1]:.3f} m; left is +y in the "
                f"base frame): swap {self.robot.key}left_wheel and {self.robot.key}right_wheel",
            )
        if self._given("wheel_separation", self.robot.wheel_separation):
            return float(self.robot.wheel_separation or 0.0)
        lb, rb = int(m.jnt_bodyid[left]), int(m.jnt_bodyid[right])
        middle = anchors.mean(axis=0)
        if abs(float(middle[0])) > _CENTRED or abs(float(middle[1])) > _CENTRED:
            raise self.parts.fail(
                "base",
                f"body {self.robot.base!r} is ({middle[0]:.3f}, {middle[1]:.3f}) m from the "
                "wheel axle's midpoint; otonav's base_link is that midpoint: name a body there "
                "as the base",
            )
        if int(m.body_parentid[lb]) == self.base and int(m.body_parentid[rb]) == self.base:
            separation = float(np.linalg.norm(m.body_pos[lb] - m.body_pos[rb]))
        else:
            separation = abs(float(anchors[0][1] - anchors[1][1]))
        self.sources["wheel_separation"] = (
            f"derived from the joints {self.robot.left_wheel!r} and {self.robot.right_wheel!r}"
        )
        return separation

    def site_offset(self, site: int, key: str) -> NDArray[np.float64]:
        """The site's position in base_link; its axes must be the base's."""
        m = self.model
        if int(m.site_bodyid[site]) == self.base:
            pos: NDArray[np.float64] = np.array(m.site_pos[site], dtype=np.float64)
        else:
            pos = self.in_base(self.data.site_xpos[site])
        turn = self.to_base @ self.data.site_xmat[site].reshape(3, 3)
        if not np.allclose(turn, np.eye(3), atol=1e-6):
            raise self.parts.fail(
                key,
                f"site {_shown_name(m, mujoco.mjtObj.mjOBJ_SITE, site)!r} is turned "
                "against the base; otonav's sensor frames have the base's axes: mount it with "
                f"{self.robot.key}{key}: {{body: ..., pos: [x, y, z]}}",
            )
        if key == "lidar" and abs(float(pos[1])) > _CENTRED:
            raise self.parts.fail(
                key,
                f"the lidar is {pos[1]:.3f} m off the robot's centre line; otonav's laser frame "
                "is on it (y = 0): mount it there",
            )
        self.sources[f"{key}_offset"] = (
            f"({', '.join(f'{v:.4g}' for v in pos)}) m in base_link, from the site"
        )
        return pos

    def footprint(self) -> tuple[tuple[float, float], ...]:
        """The rectangle in base_link (CCW corners, m) that bounds every collision geom
        of the robot projected on the floor, at the rest pose (qpos0)."""
        if self._given("footprint", self.robot.footprint):
            return tuple(self.robot.footprint or ())
        m = self.model
        geoms = [g for g in _subtree_geoms(m, self.mover) if _collides(m, g)]
        if not geoms:
            raise self.parts.fail("model", f"the robot {self.robot.base!r} has no collision geom")
        points = np.concatenate(
            [self.in_base(_geom_corners(m, self.data, g))[:, :2] for g in geoms]
        )
        x0, y0 = (float(v) for v in points.min(axis=0))
        x1, y1 = (float(v) for v in points.max(axis=0))
        self.sources["footprint"] = (
            f"derived: the rectangle bounding {len(geoms)} collision geoms on the floor"
        )
        return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
