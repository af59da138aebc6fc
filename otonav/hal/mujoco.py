"""MuJoCo implementation of :class:`~otonav.hal.interface.RobotHardwareInterface`.

This is the only module in otonav that imports :mod:`mujoco`; nothing outside it sees a
MuJoCo type (``mujoco`` has no type stubs, so its objects are ``Any`` here and never
escape through a public signature).

A scene is a built-in name (see :func:`scene_names`) or a path to an MJCF file. The
robot is found by name: body ``chassis`` (free joint, base_link), hinge joints
``left_wheel``/``right_wheel``, actuators ``left_motor``/``right_motor``, sites ``imu``
and ``lidar``, sensors ``imu_gyro``, ``imu_accel``, ``imu_quat``. Static box geoms named
``obstacle*`` and ``wall*`` are the world's obstacles and walls. Robot geoms live in
geom group 1; the lidar casts only against groups 0 and 2.

Time: ``advance(n)`` is the only thing that steps physics; ``ticks`` is an integer
counter (``data.time`` accumulates float error and is not used). Readings taken after an
``advance`` see the state *after* the last step: the first read after stepping runs one
``mj_forward`` (it does not change the trajectory: reading never perturbs physics).
Construction runs 0.25 s of physics with zero command so that at tick 0 the robot rests
settled on its wheels and caster.

Viewer: :meth:`MujocoInterface.open_viewer` opens MuJoCo's passive viewer on the live
world (after :func:`otonav.hal.viewer.check_display`, so a missing display is a
:class:`~otonav.hal.viewer.NoDisplayError`, not MuJoCo's hard exit). The viewer only
draws: call :meth:`ViewerHandle.sync` after the world advanced, and
:meth:`ViewerHandle.close` before the process exits.
"""

from __future__ import annotations

import math
import os
import tempfile
import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any, Final, Literal

import numpy as np
from numpy.typing import NDArray

from otonav.errors import UsageError
from otonav.hal.description import BUILTIN_ROBOTS, Mount, RobotDescription, builtin_robot
from otonav.hal.interface import RobotHardwareInterface
from otonav.hal.types import (
    BoxObstacle,
    GroundTruth,
    ImuSample,
    RangeScan,
    RobotGeometry,
    WheelSetpoint,
    WheelState,
)
from otonav.hal.viewer import NoDisplayError, check_display

# ``import mujoco`` loads GLFW for an offscreen GL context unless MUJOCO_GL says otherwise:
# a windowing library (and ~25 ms) in every headless run. otonav never renders offscreen,
# and ``mujoco.viewer`` loads GLFW itself when a window opens. So unless the user chose a
# backend, mujoco is imported with MUJOCO_GL=disable and the environment is restored
# (docs/adr: set MUJOCO_GL=glfw|egl|osmesa before importing otonav for mujoco.Renderer).
_GL_CHOSEN: Final = "MUJOCO_GL" in os.environ
if not _GL_CHOSEN:
    os.environ["MUJOCO_GL"] = "disable"
try:
    import mujoco
finally:
    if not _GL_CHOSEN:
        del os.environ["MUJOCO_GL"]

__all__ = [
    "BUG_VARIANT_KV",
    "MujocoInterface",
    "NoDisplayError",
    "SceneError",
    "Variant",
    "ViewerHandle",
    "compile_scene",
    "scene_names",
    "scene_path",
]

Variant = Literal["shipped", "no_caster_unlimited_torque"]

BUG_VARIANT_KV: Final = 10.0
"""Velocity-actuator gain (N m s/rad) of the ``no_caster_unlimited_torque`` variant."""

_ROBOT_FRAGMENT: Final = "robot.xml"
_RAY_GROUPS: Final = np.array([1, 0, 1, 0, 0, 0], dtype=np.uint8)  # groups 0 and 2
_ROBOT_GROUP: Final = 1
_OBSTACLE_HEIGHT: Final = 0.5  # m, height of boxes added through extra_obstacles
VIEWER_DISTANCE: Final = 4.0
"""m from the tracked robot to the viewer's camera."""
VIEWER_ELEVATION: Final = -40.0
"""degrees: the tracking camera looks down at the robot from this angle."""
VIEWER_AZIMUTH: Final = 135.0
"""degrees, MuJoCo's convention: the tracking camera's heading around the robot."""
_SETTLE_TIME: Final = 0.25  # s of physics run at construction, before tick 0


def _one_line(exc: BaseException) -> str:
    """MuJoCo's messages span lines (``Element 'geom', line 1``): one line for users."""
    return " ".join(str(exc).split())


class SceneError(UsageError):
    """An MJCF scene that cannot be found, parsed, compiled or used as an otonav world."""


# -- scenes ----------------------------------------------------------------------------


def _assets() -> Traversable:
    return resources.files("otonav.hal").joinpath("assets")


def scene_names() -> tuple[str, ...]:
    """Names of the built-in scenes (the MJCF files shipped in ``otonav/hal/assets``)."""
    root = _assets()
    names = (
        entry.name.removesuffix(".xml")
        for entry in root.iterdir()
        if entry.name.endswith(".xml") and entry.name != _ROBOT_FRAGMENT
    )
    return tuple(sorted(names))


@contextmanager
def scene_path(scene: str | os.PathLike[str]) -> Iterator[Path]:
    """Context manager yielding a real filesystem path for a scene name or MJCF path.

    Built-in scenes are read through :mod:`importlib.resources`; if the package is not
    on a filesystem (e.g. zipped), the assets are copied to a temporary directory for
    the duration of the ``with`` block, so ``<include file="robot.xml"/>`` resolves.
    """
    if isinstance(scene, str) and scene in scene_names():
        root = _assets()
        filename = f"{scene}.xml"
        if isinstance(root, Path):
            yield root / filename
            return
        with tempfile.TemporaryDirectory(prefix="otonav-assets-") as tmp:
            for entry in root.iterdir():
                if entry.name.endswith(".xml"):
                    (Path(tmp) / entry.name).write_bytes(entry.read_bytes())
            yield Path(tmp) / filename
        return
    path = Path(scene)
    if not path.is_file():
        raise SceneError(
            f"scene {str(scene)!r} is neither a built-in scene {scene_names()} "
            f"nor an existing MJCF file"
        )
    yield path


def _load_spec(scene: str | os.PathLike[str]) -> tuple[Any, str]:
    """Parse a scene into an ``mujoco.MjSpec``; returns (spec, label naming the file)."""
    with scene_path(scene) as path:
        label = str(path)
        try:
            spec = mujoco.MjSpec.from_file(str(path))
        except ValueError as exc:
            raise SceneError(f"MJCF file {label} does not parse: {_one_line(exc)}") from exc
    return spec, label


def _compile(spec: Any, label: str) -> Any:
    try:
        return spec.compile()
    except ValueError as exc:
        raise SceneError(f"MJCF file {label} does not compile: {_one_line(exc)}") from exc


def compile_scene(path_or_name: str | os.PathLike[str]) -> None:
    """Parse and compile a scene; raise :class:`SceneError` naming the file if it fails."""
    spec, label = _load_spec(path_or_name)
    _compile(spec, label)


# -- helpers ---------------------------------------------------------------------------


def _yaw_of_quat(w: float, x: float, y: float, z: float) -> float:
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _add_box(spec: Any, name: str, box: BoxObstacle) -> None:
    half_yaw = box.yaw / 2.0
    spec.worldbody.add_geom(
        name=name,
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[box.half_x, box.half_y, _OBSTACLE_HEIGHT / 2.0],
        pos=[box.x, box.y, _OBSTACLE_HEIGHT / 2.0],
        quat=[math.cos(half_yaw), 0.0, 0.0, math.sin(half_yaw)],
        group=0,
        rgba=[0.85, 0.35, 0.2, 1.0],
    )


def _apply_bug_variant(spec: Any, label: str) -> None:
    """The seeds' pitch bug: no caster, no torque limit, a stiff velocity loop."""
    caster = spec.geom("caster")
    if caster is None:
        raise SceneError(f"{label}: variant needs a geom named 'caster' to remove")
    spec.delete(caster)
    for name in ("left_motor", "right_motor"):
        act = spec.actuator(name)
        if act is None:
            raise SceneError(f"{label}: no actuator named {name!r}")
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_FALSE
        act.gainprm[0] = BUG_VARIANT_KV
        act.biasprm[2] = -BUG_VARIANT_KV


# -- the robot: a description put into a scene ------------------------------------------

ROBOT_PREFIX: Final = "robot/"
"""Names of an attached robot's elements in the compiled world (the scene's own names
never clash with the robot's)."""
_SERVO_SLIP: Final = 0.1
"""rad/s of speed error at which a velocity loop otonav makes reaches its torque limit."""
_DEFAULT_TORQUE_G: Final = 0.2
"""A wheel with no stated torque limit gets 0.2 m g r: both wheels can then accelerate
the robot at 0.4 g (ample for any base limit) without lifting a caster off the floor."""
_MOUNT_ABOVE: Final = 0.02  # m: a default lidar sits this far above the robot's top
_REST_TOLERANCE: Final = 1e-3  # m: a model resting within this of the floor is not moved
_CASTER_GAP: Final = 3e-3  # m: a base sphere this close to the floor is a caster


def _names(elements: Sequence[Any]) -> str:
    shown = [e.name for e in elements if e.name]
    return ", ".join(shown) if shown else "none named"


class _RobotSpec:
    """The robot's part of an ``MjSpec`` made ready for otonav: wheel actuators driven
    as velocity loops, a free base, the lidar and IMU sites and sensors, robot geoms out
    of the lidar's groups. Records where each choice came from (``sources``)."""

    def __init__(self, spec: Any, robot: RobotDescription, file_label: str) -> None:
        self.spec = spec
        self.robot = robot
        self.file = file_label
        self.sources: dict[str, str] = {}
        self.wheel_acts: dict[str, Any] = {}
        self.ctrl_scale: dict[str, float] = {}
        self.lidar_site = ""
        self.imu_site = ""
        self.base = self._body(robot.base, "base")
        self.joints = {
            "left_wheel": self._wheel(robot.left_wheel, "left_wheel"),
            "right_wheel": self._wheel(robot.right_wheel, "right_wheel"),
        }

    def fail(self, key: str, message: str) -> SceneError:
        return SceneError(f"{self.robot.key}{key}: {message}")

    def _body(self, name: str, key: str) -> Any:
        body = self.spec.body(name)
        if body is None or name == "world":
            raise self.fail(
                key, f"no body {name!r} in {self.file} (bodies: {_names(self.spec.bodies[1:])})"
            )
        return body

    def _wheel(self, name: str, key: str) -> Any:
        hinges = [j for j in self.spec.joints if j.type == mujoco.mjtJoint.mjJNT_HINGE]
        joint = self.spec.joint(name)
        if joint is None or joint.type != mujoco.mjtJoint.mjJNT_HINGE:
            what = "no hinge joint" if joint is not None else "no joint"
            raise self.fail(key, f"{what} {name!r} in {self.file} (hinge joints: {_names(hinges)})")
        if not self._under_base(joint.parent):
            raise self.fail(key, f"joint {name!r} is not part of the base {self.robot.base!r}")
        return joint

    def _under_base(self, body: Any) -> bool:
        while body is not None and body.name != "world":
            if body.name == self.base.name:
                return True
            body = body.parent
        return False

    def casters(self, floor: float) -> None:
        """Spheres of the base that rest on the floor with the wheels are casters: made
        frictionless (condim 1, priority 1), as a URDF cannot say (its friction tags are
        Gazebo's); otherwise they drag like brakes."""
        made = []
        for geom in self.base.geoms:
            if geom.type != mujoco.mjtGeom.mjGEOM_SPHERE or int(geom.condim) == 1:
                continue
            if float(geom.pos[2]) - float(geom.size[0]) - floor < _CASTER_GAP:
                geom.condim = 1
                geom.priority = 1
                made.append(geom.name or f"sphere at x = {float(geom.pos[0]):.3g} m")
        if made:
            self.sources["casters"] = f"made frictionless by otonav: {', '.join(made)}"

    def prepare(self, mass: float, wheel_radius: float) -> None:
        """Free base, wheel actuators, sensor sites, geom groups (after :meth:`probe`)."""
        joints = self.base.joints
        if not joints:
            self.base.add_freejoint()
            self.sources["base"] = f"body {self.base.name!r}, free joint added by otonav"
        elif joints[0].type != mujoco.mjtJoint.mjJNT_FREE:
            kind = joints[0].type.name.removeprefix("mjJNT_").lower()
            raise self.fail(
                "base",
                f"body {self.base.name!r} has a {kind} joint; otonav's base is a floating "
                "body (a free joint, or none)",
            )
        else:
            self.sources["base"] = f"body {self.base.name!r} (its own free joint)"
        for key, joint in self.joints.items():
            self._actuate(key, joint, mass * 9.81 * _DEFAULT_TORQUE_G * wheel_radius)
        for geom in self.base.find_all(mujoco.mjtObj.mjOBJ_GEOM):
            if int(geom.group) in (0, 2):  # the lidar's groups: it must not see the robot
                geom.group = _ROBOT_GROUP

    def _actuate(self, key: str, joint: Any, default_torque: float) -> None:
        acts = [
            a
            for a in self.spec.actuators
            if a.trntype == mujoco.mjtTrn.mjTRN_JOINT and a.target == joint.name
        ]
        if len(acts) > 1:
            raise self.fail(
                key, f"joint {joint.name!r} has {len(acts)} actuators ({_names(acts)}); give it one"
            )
        if not acts:
            act = self.spec.add_actuator(name=f"otonav_{key}", target=joint.name)
            act.trntype = mujoco.mjtTrn.mjTRN_JOINT
            self._servo(act, default_torque)
            self.sources[f"{key}_actuator"] = (
                f"none in the model: otonav's velocity loop, kv {act.gainprm[0]:.4g}, "
                f"+-{default_torque:.3g} N m"
            )
        elif _is_velocity(acts[0]):
            act = acts[0]
            self.sources[f"{key}_actuator"] = (
                f"velocity actuator {act.name or '(unnamed)'!r}, kv {act.gainprm[0]:.4g}"
            )
        else:
            act = acts[0]
            kind = "motor" if act.biastype == mujoco.mjtBias.mjBIAS_NONE else "position"
            torque = _torque_limit(act) or default_torque
            self._servo(act, torque)
            self.sources[f"{key}_actuator"] = (
                f"{kind} actuator {act.name or '(unnamed)'!r} driven as a velocity loop, "
                f"kv {act.gainprm[0]:.4g}, +-{torque:.3g} N m"
            )
        self.wheel_acts[key] = act
        self.ctrl_scale[key] = float(act.gear[0])

    @staticmethod
    def _servo(act: Any, torque: float) -> None:
        kv = torque / _SERVO_SLIP
        act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        act.gainprm[:3] = [kv, 0.0, 0.0]
        act.biasprm[:3] = [0.0, 0.0, -kv]
        act.gear[:] = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.forcerange[:] = [-torque, torque]

    def mount(self, key: str, mount: Mount | None, default_pos: Sequence[float]) -> str:
        """The name of the site the sensor ``key`` (lidar, imu) reads from."""
        if mount is not None and mount.site is not None:
            site = self.spec.site(mount.site)
            if site is None:
                raise self.fail(
                    key, f"no site {mount.site!r} in {self.file} (sites: {_names(self.spec.sites)})"
                )
            if not self._under_base(site.parent):
                raise self.fail(key, f"site {mount.site!r} is not on the robot {self.base.name!r}")
            self.sources[key] = f"site {mount.site!r} of the model"
            return str(site.name)
        if mount is None:
            own = self._own_site(key)
            if own is not None:
                return own
        body = self.base if mount is None or mount.body is None else self._body(mount.body, key)
        if not self._under_base(body):
            raise self.fail(key, f"body {body.name!r} is not part of the robot {self.base.name!r}")
        pos = list(default_pos) if mount is None or mount.pos is None else list(mount.pos)
        name = f"otonav_{key}"
        body.add_site(name=name, pos=pos, size=[0.01, 0.01, 0.01], group=4)
        where = "otonav's default" if mount is None else "the config's mount"
        self.sources[key] = (
            f"mounted by otonav on body {body.name!r} at ({', '.join(f'{v:.4g}' for v in pos)})"
            f" ({where})"
        )
        return name

    def _own_site(self, key: str) -> str | None:
        """A sensor the model already has: a rangefinder for the lidar, a gyro for the IMU."""
        kinds = {
            "lidar": mujoco.mjtSensor.mjSENS_RANGEFINDER,
            "imu": mujoco.mjtSensor.mjSENS_GYRO,
        }
        for sensor in self.spec.sensors:
            if sensor.type == kinds[key] and sensor.objtype == mujoco.mjtObj.mjOBJ_SITE:
                site = self.spec.site(sensor.objname)
                if site is not None and self._under_base(site.parent):
                    kind = sensor.type.name.removeprefix("mjSENS_").lower()
                    label = sensor.name or "(unnamed)"
                    self.sources[key] = f"at site {site.name!r} of the model's {kind} {label!r}"
                    if key == "imu":
                        return str(site.name)
                    # A rangefinder's ray runs along its site's z: the scan is cast from
                    # the same point, in the base's axes (its own site, unturned).
                    site.parent.add_site(
                        name="otonav_lidar", pos=list(site.pos), size=[0.01, 0.01, 0.01], group=4
                    )
                    return "otonav_lidar"
        return None

    def imu_sensors(self, site: str) -> None:
        """Gyro, accelerometer and orientation on the IMU site (the model's, or added)."""
        have = {
            s.type
            for s in self.spec.sensors
            if s.objtype == mujoco.mjtObj.mjOBJ_SITE and s.objname == site
        }
        kinds = mujoco.mjtSensor
        for kind, suffix in (
            (kinds.mjSENS_GYRO, "gyro"),
            (kinds.mjSENS_ACCELEROMETER, "accel"),
            (kinds.mjSENS_FRAMEQUAT, "quat"),
        ):
            if kind not in have:
                sensor = self.spec.add_sensor(
                    name=f"otonav_imu_{suffix}", type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE
                )
                sensor.objname = site


def _is_velocity(act: Any) -> bool:
    kv = float(act.gainprm[0])
    return (
        act.gaintype == mujoco.mjtGain.mjGAIN_FIXED
        and act.biastype == mujoco.mjtBias.mjBIAS_AFFINE
        and kv > 0.0
        and float(act.biasprm[0]) == 0.0
        and float(act.biasprm[1]) == 0.0
        and float(act.biasprm[2]) == -kv
    )


def _limited(flag: Any, lo: float, hi: float) -> bool:
    return bool(
        flag == mujoco.mjtLimited.mjLIMITED_TRUE
        or (flag == mujoco.mjtLimited.mjLIMITED_AUTO and lo < hi)
    )


def _torque_limit(act: Any) -> float | None:
    """The joint torque an actuator can give at most, from its force or control range."""
    gear = abs(float(act.gear[0]))
    lo, hi = (float(v) for v in act.forcerange)
    if _limited(act.forcelimited, lo, hi):
        return gear * max(abs(lo), abs(hi))
    lo, hi = (float(v) for v in act.ctrlrange)
    if act.biastype == mujoco.mjtBias.mjBIAS_NONE and _limited(act.ctrllimited, lo, hi):
        return gear * abs(float(act.gainprm[0])) * max(abs(lo), abs(hi))
    return None


def _merge_options(scene: Any, robot: Any) -> None:
    """One set of physics options for the attached world: the scene's, except where the
    scene leaves one at MuJoCo's default and the robot's model sets it (its integrator,
    its timestep). Written into both specs, so attaching has no conflict to report."""
    default = mujoco.MjSpec().option
    for name in dir(default):
        if name.startswith("_") or callable(getattr(default, name)):
            continue
        ours, theirs, fresh = (getattr(o, name) for o in (scene.option, robot.option, default))
        if np.array_equal(np.asarray(ours), np.asarray(fresh)):
            setattr(scene.option, name, theirs)
        else:
            setattr(robot.option, name, ours)


def _absolute_assets(spec: Any, path: Path) -> None:
    """Mesh and texture files relative to the model's own directory (and its
    ``meshdir``/``texturedir``), so the model can be attached to a scene elsewhere."""
    folder = path.resolve().parent
    for items, subdir in ((spec.meshes, spec.meshdir), (spec.textures, spec.texturedir)):
        for item in items:
            file = str(item.file)
            if spec.strippath or "://" in file:  # URDF: package://pkg/meshes/x.stl
                file = file.rsplit("/", 1)[-1]
            if file and not Path(file).is_absolute():
                item.file = str(folder / (subdir or "") / file)
    spec.strippath = False
    spec.meshdir = ""
    spec.texturedir = ""


def _load_robot(robot: RobotDescription) -> tuple[Any, str]:
    """The robot's model as a spec, its asset files found where the model says."""
    path = Path(robot.model)
    label = robot.label
    if not path.is_file():
        raise SceneError(
            f"{robot.key}model: {label!r} is neither a built-in robot "
            f"({', '.join(BUILTIN_ROBOTS)}) nor an existing MJCF or URDF file"
        )
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:
        raise SceneError(f"{robot.key}model: {label} does not parse: {_one_line(exc)}") from None
    _absolute_assets(spec, path)
    spec.compiler.fusestatic = False  # URDF's default: it would fuse the base into the world
    return spec, label


@dataclass(frozen=True, slots=True)
class _Probe:
    mass: float  # kg, the robot's
    wheel_radius: float  # m, rough (bounding sphere of the left wheel's geoms)
    top: float  # m, the highest point of the robot above its base's origin
    bottom: float  # m, the lowest point of its collision geoms above the floor
    floor: float  # m, that lowest point relative to the base's origin


def _probe(parts: _RobotSpec) -> _Probe:
    """Mass and extent of the robot as modelled, before otonav changes anything."""
    try:
        model = parts.spec.copy().compile()
    except ValueError as exc:  # a missing mesh file, a bad attribute
        raise parts.fail("model", f"{parts.file} does not compile: {_one_line(exc)}") from None
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    base = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, parts.base.name))
    joint = int(
        mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, parts.joints["left_wheel"].name)
    )
    wheel = int(model.jnt_bodyid[joint])
    geoms = _subtree_geoms(model, base)
    radius = max(
        (float(model.geom_rbound[g]) for g in geoms if model.geom_bodyid[g] == wheel), default=0.0
    )
    lows, highs = [], []
    for g in geoms:
        corners = _geom_corners(model, data, g)[:, 2]
        highs.append(float(corners.max()))
        if _collides(model, g):
            lows.append(float(corners.min()))
    return _Probe(
        mass=float(model.body_subtreemass[base]),
        wheel_radius=radius,
        top=max(highs, default=0.0) - float(data.xpos[base][2]),
        bottom=min(lows, default=0.0),
        floor=min(lows, default=0.0) - float(data.xpos[base][2]),
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


def _geom_corners(model: Any, data: Any, geom: int) -> NDArray[np.float64]:
    """The 8 corners of ``geom``'s bounding box, world frame."""
    centre, half = _geom_half(model, geom)
    local = _SIGNS * half + centre
    corners: NDArray[np.float64] = (
        local @ data.geom_xmat[geom].reshape(3, 3).T + data.geom_xpos[geom]
    )
    return corners


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

    def in_base(self, world: NDArray[np.float64]) -> NDArray[np.float64]:
        result: NDArray[np.float64] = (world - self.origin) @ self.to_base.T
        return result

    def geometry(
        self, joints: tuple[int, int], lidar: int, imu: int, base_qpos: int
    ) -> RobotGeometry:
        m = self.model
        radius = self.wheel_radius(joints[0])
        separation = self.separation(*joints)
        laser = self.site_offset(lidar, "lidar")
        imu_pos = self.site_offset(imu, "imu")
        footprint = self.footprint()
        self.check_lidar_outside(lidar)
        return RobotGeometry(
            wheel_radius=radius,
            wheel_separation=separation,
            laser_offset_x=float(laser[0]),
            laser_offset_z=float(laser[2]),
            base_height=float(m.qpos0[base_qpos + 2]),
            imu_offset=(float(imu_pos[0]), float(imu_pos[1]), float(imu_pos[2])),
            footprint=footprint,
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
        if kind == mujoco.mjtGeom.mjGEOM_SPHERE or (round_about_z and aligned and k == 2):
            radius = float(size[0])
        elif kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID and aligned:
            radius = float(max(size[i] for i in range(3) if i != k))
        elif kind == mujoco.mjtGeom.mjGEOM_MESH:
            mesh = int(m.geom_dataid[geom])
            start, count = int(m.mesh_vertadr[mesh]), int(m.mesh_vertnum[mesh])
            verts = np.asarray(m.mesh_vert[start : start + count], dtype=np.float64)
            unit = axis / np.linalg.norm(axis)
            off_axle = verts - np.outer(verts @ unit, unit)
            radius = float(np.max(np.linalg.norm(off_axle, axis=1)))
        else:
            radius = float(m.geom_rbound[geom])
        kind_name = mujoco.mjtGeom(kind).name.removeprefix("mjGEOM_").lower()
        self.sources["wheel_radius"] = f"derived from the {kind_name} geom {name}"
        return radius

    def separation(self, left: int, right: int) -> float:
        if self._given("wheel_separation", self.robot.wheel_separation):
            return float(self.robot.wheel_separation or 0.0)
        m = self.model
        lb, rb = int(m.jnt_bodyid[left]), int(m.jnt_bodyid[right])
        anchors = self.in_base(np.array([self.data.xanchor[left], self.data.xanchor[right]]))
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
        geoms = [g for g in _subtree_geoms(m, self.base) if _collides(m, g)]
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

    def check_lidar_outside(self, site: int) -> None:
        """A lidar inside the robot's own collision geometry would cast from inside it."""
        m = self.model
        point = self.data.site_xpos[site]
        for g in _subtree_geoms(m, self.base):
            if not _collides(m, g):
                continue
            centre, half = _geom_half(m, g)
            local = self.data.geom_xmat[g].reshape(3, 3).T @ (point - self.data.geom_xpos[g])
            if np.all(np.abs(local - centre) < half):
                name = _shown_name(m, mujoco.mjtObj.mjOBJ_GEOM, g)
                raise self.parts.fail(
                    "lidar",
                    f"the lidar's origin is inside the robot's collision geom {name!r}: mount it "
                    "above the robot (a pos whose z clears the geom)",
                )


_VIEWER_THREAD: Final = "_launch_internal"  # target of launch_passive's thread


class ViewerHandle:
    """MuJoCo's passive viewer on a :class:`MujocoInterface`'s live world.

    Single-threaded use from the thread that steps the world: :meth:`sync` after the
    world advanced (at most ~60 Hz wall: each sync copies the state for drawing),
    :meth:`is_running` to notice the user closed the window, :meth:`close` when done
    (also as a context manager). ``start_time_s`` is how long the window took to open.
    """

    def __init__(
        self,
        world: MujocoInterface,
        handle: Any,
        threads: Sequence[threading.Thread],
        start_time_s: float,
    ) -> None:
        self._world = world
        self._handle = handle
        self._threads = tuple(threads)
        self.start_time_s = start_time_s
        self._closed = False

    def is_running(self) -> bool:
        """False once the window was closed (by the user or :meth:`close`)."""
        return not self._closed and bool(self._handle.is_running())

    def sync(self) -> None:
        """Show the world's current state (a no-op once the window is closed)."""
        if not self.is_running():
            return
        self._world._sync()  # poses of the last step, as reading does (no physics change)
        self._handle.sync()

    def close(self, timeout: float = 5.0) -> None:
        """Close the window and wait until the viewer's thread has finished tearing
        down, so the process can exit right after (exiting with the viewer still
        closing crashed or hung). Idempotent."""
        if self._closed:
            return
        self._closed = True
        self._handle.close()
        deadline = time.monotonic() + timeout
        for thread in self._threads:
            thread.join(max(0.0, deadline - time.monotonic()))
        alive = [t.name for t in self._threads if t.is_alive()]
        if alive:
            raise RuntimeError(f"MuJoCo viewer did not shut down within {timeout:g} s ({alive})")

    def __enter__(self) -> ViewerHandle:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class MujocoInterface(RobotHardwareInterface):
    """The otonav robot simulated by MuJoCo.

    ``scene``: built-in scene name (``"empty"``, ``"obstacles"``) or an MJCF path.
    ``lidar_beams`` beams over a full circle from -pi; ranges in
    [``lidar_range_min``, ``lidar_range_max``] m, otherwise +inf. ``timestep`` (s)
    overrides the scene's. ``extra_obstacles`` become 0.5 m tall static boxes named
    ``obstacle_extra_<i>``. ``variant="no_caster_unlimited_torque"`` reproduces the
    pitch bug (for regression tests only). ``start`` is the robot's pose (x, y, yaw)
    in the world plane before it settles.
    """

    def __init__(
        self,
        scene: str | os.PathLike[str] = "obstacles",
        *,
        lidar_beams: int = 360,
        lidar_range_min: float = 0.12,
        lidar_range_max: float = 8.0,
        timestep: float | None = None,
        extra_obstacles: Sequence[BoxObstacle] = (),
        variant: Variant = "shipped",
        start: tuple[float, float, float] = (0.0, 0.0, 0.0),
        robot: RobotDescription | None = None,
    ) -> None:
        if lidar_beams < 1:
            raise ValueError(f"lidar_beams must be >= 1, got {lidar_beams}")
        if not 0.0 <= lidar_range_min < lidar_range_max:
            raise ValueError(
                f"need 0 <= lidar_range_min < lidar_range_max, got "
                f"{lidar_range_min}, {lidar_range_max}"
            )
        if timestep is not None and not timestep > 0.0:
            raise ValueError(f"timestep must be positive, got {timestep}")
        if variant not in ("shipped", "no_caster_unlimited_torque"):
            raise ValueError(f"unknown variant {variant!r}")

        spec, label = _load_spec(scene)
        self._label = label
        robot = robot if robot is not None else builtin_robot("otonav")
        self._robot = robot
        if timestep is not None:
            spec.option.timestep = timestep
        for i, box in enumerate(extra_obstacles):
            _add_box(spec, f"obstacle_extra_{i}", box)
        if spec.body(robot.base) is not None:
            # The scene has the robot in it already (a scene that includes robot.xml).
            robot_spec, robot_file, prefix = spec, label, ""
        else:
            included = builtin_robot("otonav").base
            if spec.body(included) is not None:  # an old scene with our robot in it
                raise SceneError(
                    f"MJCF file {label} includes otonav's robot (body {included!r}); remove "
                    f'its <include file="robot.xml"/> to run robot.model: {robot.label}'
                )
            robot_spec, robot_file = _load_robot(robot)
            prefix = ROBOT_PREFIX
        if variant == "no_caster_unlimited_torque":
            _apply_bug_variant(robot_spec, robot_file)
        self._variant: Variant = variant
        parts = _RobotSpec(robot_spec, robot, robot_file)
        probe = _probe(parts)
        parts.casters(probe.floor)
        parts.prepare(probe.mass, probe.wheel_radius)
        lidar_site = parts.mount("lidar", robot.lidar, (0.0, 0.0, probe.top + _MOUNT_ABOVE))
        imu_site = parts.mount("imu", robot.imu, (0.0, 0.0, 0.0))
        parts.imu_sensors(imu_site)
        self._ctrl_scale = (parts.ctrl_scale["left_wheel"], parts.ctrl_scale["right_wheel"])
        if prefix:
            if abs(probe.bottom) > _REST_TOLERANCE:
                parts.base.pos[2] -= probe.bottom  # rest on the floor, not in or above it
            _merge_options(spec, robot_spec)
            spec.worldbody.add_frame().attach_body(parts.base, prefix, "")
        self._model: Any = _compile(spec, label if not prefix else f"{label} with {robot_file}")
        self._data: Any = mujoco.MjData(self._model)
        m = self._model
        obj = mujoco.mjtObj

        def ident(kind: Any, name: str) -> int:
            found = int(mujoco.mj_name2id(m, kind, prefix + name))
            if found < 0:  # prepared above: a bug, not a user's mistake
                raise SceneError(f"{robot_file}: {name!r} missing after compiling")
            return found

        self._chassis = ident(obj.mjOBJ_BODY, robot.base)
        base_joint = int(m.body_jntadr[self._chassis])
        self._base_qpos = int(m.jnt_qposadr[base_joint])
        self._base_qvel = int(m.jnt_dofadr[base_joint])
        left_joint = ident(obj.mjOBJ_JOINT, robot.left_wheel)
        right_joint = ident(obj.mjOBJ_JOINT, robot.right_wheel)
        self._wheel_qpos = (int(m.jnt_qposadr[left_joint]), int(m.jnt_qposadr[right_joint]))
        self._wheel_qvel = (int(m.jnt_dofadr[left_joint]), int(m.jnt_dofadr[right_joint]))
        self._left_act = _actuator_of(m, left_joint)
        self._right_act = _actuator_of(m, right_joint)
        self._lidar_site = ident(obj.mjOBJ_SITE, lidar_site)
        self._imu_site = ident(obj.mjOBJ_SITE, imu_site)
        self._gyro = _site_sensor(m, mujoco.mjtSensor.mjSENS_GYRO, self._imu_site)
        self._accel = _site_sensor(m, mujoco.mjtSensor.mjSENS_ACCELEROMETER, self._imu_site)
        self._quat = _site_sensor(m, mujoco.mjtSensor.mjSENS_FRAMEQUAT, self._imu_site)

        derived = _Derivation(m, self._chassis, parts)
        self._wheel_sign = (derived.wheel_sign(left_joint), derived.wheel_sign(right_joint))
        self._mirrored = self._wheel_sign != (1.0, 1.0)
        self._ctrl_scale = (
            self._ctrl_scale[0] * self._wheel_sign[0],
            self._ctrl_scale[1] * self._wheel_sign[1],
        )
        self._geometry = derived.geometry(
            (left_joint, right_joint), self._lidar_site, self._imu_site, self._base_qpos
        )
        self._sources = {**parts.sources, **derived.sources}
        self._obstacles = self._static_boxes("obstacle")
        self._walls = self._static_boxes("wall")
        self._is_floor = np.asarray(m.geom_type == mujoco.mjtGeom.mjGEOM_PLANE, dtype=np.bool_)

        # Lidar: beam directions in the site frame and preallocated ray buffers.
        self._range_min = float(lidar_range_min)
        self._range_max = float(lidar_range_max)
        self._angle_min = -math.pi
        self._angle_increment = 2.0 * math.pi / lidar_beams
        angles = self._angle_min + self._angle_increment * np.arange(lidar_beams)
        self._beams_local = np.zeros((lidar_beams, 3))
        self._beams_local[:, 0] = np.cos(angles)
        self._beams_local[:, 1] = np.sin(angles)
        self._ray_vec = np.zeros((lidar_beams, 3))
        self._ray_vec_flat = self._ray_vec.reshape(-1)  # a view: filled by matmul(out=)
        self._ray_origin = np.zeros(3)
        self._ray_geom = np.full(lidar_beams, -1, dtype=np.int32)
        self._ray_dist = np.full(lidar_beams, -1.0)
        self._nbeams = lidar_beams

        # Place the robot at its start pose (x, y, yaw) in the world plane.
        x0, y0, yaw0 = start
        p = self._base_qpos
        self._data.qpos[p] = x0
        self._data.qpos[p + 1] = y0
        self._data.qpos[p + 3 : p + 7] = (math.cos(yaw0 / 2), 0.0, 0.0, math.sin(yaw0 / 2))
        # Let the robot settle onto its wheels and caster (contacts start at zero force)
        # so tick 0 is a robot at rest: the IMU reads +g, not free fall.
        mujoco.mj_step(m, self._data, nstep=max(1, round(_SETTLE_TIME / self.tick)))
        self._data.time = 0.0
        self._ticks = 0
        self._stale = True
        self._closed = False
        self._sync()

    # -- model facts ----------------------------------------------------------------------

    def _static_boxes(self, prefix: str) -> tuple[BoxObstacle, ...]:
        m = self._model
        boxes = []
        for g in range(m.ngeom):
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
            if (
                name.startswith(prefix)
                and int(m.geom_bodyid[g]) == 0
                and m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX
            ):
                w, x, y, z = (float(v) for v in m.geom_quat[g])
                boxes.append(
                    BoxObstacle(
                        x=float(m.geom_pos[g][0]),
                        y=float(m.geom_pos[g][1]),
                        half_x=float(m.geom_size[g][0]),
                        half_y=float(m.geom_size[g][1]),
                        yaw=_yaw_of_quat(w, x, y, z),
                    )
                )
        return tuple(boxes)

    @property
    def scene_file(self) -> str:
        """The MJCF file this world was built from."""
        return self._label

    @property
    def variant(self) -> Variant:
        return self._variant

    @property
    def mj_model(self) -> object:
        """The compiled ``mujoco.MjModel`` (for a viewer inside ``otonav.hal`` only)."""
        return self._model

    @property
    def mj_data(self) -> object:
        """The live ``mujoco.MjData`` (for a viewer inside ``otonav.hal`` only)."""
        return self._data

    def open_viewer(self, *, track: bool = True) -> ViewerHandle:
        """Open MuJoCo's passive viewer (no side panels) on this world.

        ``track``: the camera follows the robot (MuJoCo's tracking camera on body
        ``chassis``, from behind-left and above, ~4 m away), so it never drives out of
        the picture; the user can still turn and zoom it. ``track=False``: MuJoCo's
        default free camera, fixed on the model's centre.

        Raises :class:`NoDisplayError` (one line: what is missing, and the fix) when
        there is no display GLFW can open, instead of MuJoCo's hard exit.
        """
        self._check_open()
        check_display()
        import mujoco.viewer  # loads GLFW: only when a viewer is wanted

        self._sync()
        started = time.perf_counter()
        before = set(threading.enumerate())
        handle = mujoco.viewer.launch_passive(
            self._model, self._data, show_left_ui=False, show_right_ui=False
        )
        if track:
            with handle.lock():
                handle.cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
                handle.cam.trackbodyid = self._chassis
                handle.cam.distance = VIEWER_DISTANCE
                handle.cam.elevation = VIEWER_ELEVATION
                handle.cam.azimuth = VIEWER_AZIMUTH
        elapsed = time.perf_counter() - started
        new = [t for t in threading.enumerate() if t not in before]
        threads = [t for t in new if _VIEWER_THREAD in t.name] or new
        return ViewerHandle(self, handle, threads, elapsed)

    # -- time -----------------------------------------------------------------------------

    @property
    def tick(self) -> float:
        return float(self._model.opt.timestep)

    @property
    def ticks(self) -> int:
        return self._ticks

    def advance(self, n: int) -> None:
        self._check_open()
        if n < 0:
            raise ValueError(f"cannot advance by a negative number of ticks ({n})")
        if n == 0:
            return
        mujoco.mj_step(self._model, self._data, nstep=n)
        self._ticks += n
        self._stale = True
        warnings = self._data.warning
        if int(warnings[mujoco.mjtWarning.mjWARN_BADQACC].number) > 0:
            raise RuntimeError(
                f"MuJoCo simulation of {self._label} diverged (bad qacc) before "
                f"t = {self.sim_time:.4f} s; the state was reset by MuJoCo"
            )

    def _sync(self) -> None:
        """Bring derived quantities (sites, sensors, geom poses) up to the current state."""
        if self._stale:
            mujoco.mj_forward(self._model, self._data)
            self._stale = False

    # -- I/O ------------------------------------------------------------------------------

    def write(self, cmd: WheelSetpoint) -> None:
        self._check_open()
        if not (math.isfinite(cmd.left) and math.isfinite(cmd.right)):
            raise ValueError(f"wheel command must be finite, got {cmd}")
        left_scale, right_scale = self._ctrl_scale
        # A velocity actuator with a gear takes actuator speed: gear x wheel speed.
        self._data.ctrl[self._left_act] = cmd.left if left_scale == 1.0 else cmd.left * left_scale
        self._data.ctrl[self._right_act] = (
            cmd.right if right_scale == 1.0 else cmd.right * right_scale
        )

    def read_wheels(self) -> WheelState:
        left_pos, right_pos, left_vel, right_vel = self.wheel_values()
        return WheelState(
            left_position=left_pos,
            right_position=right_pos,
            left_velocity=left_vel,
            right_velocity=right_vel,
        )

    def wheel_values(self) -> tuple[float, float, float, float]:
        # The drive emulator's read at every 10 ms instant: the same four doubles as
        # read_wheels, without building a WheelState (1.1 -> ~0.35 us).
        qpos, qvel = self._data.qpos, self._data.qvel
        (pl, pr), (vl, vr) = self._wheel_qpos, self._wheel_qvel
        if self._mirrored:  # a joint axis along -y: its positive turn drives backwards
            sl, sr = self._wheel_sign
            return sl * qpos.item(pl), sr * qpos.item(pr), sl * qvel.item(vl), sr * qvel.item(vr)
        return qpos.item(pl), qpos.item(pr), qvel.item(vl), qvel.item(vr)

    def read_imu(self) -> ImuSample:
        self._sync()
        s = self._data.sensordata
        q, g, a = s[self._quat], s[self._gyro], s[self._accel]
        return ImuSample(
            orientation=(float(q[0]), float(q[1]), float(q[2]), float(q[3])),
            angular_velocity=(float(g[0]), float(g[1]), float(g[2])),
            linear_acceleration=(float(a[0]), float(a[1]), float(a[2])),
        )

    def read_scan(self) -> RangeScan:
        self._sync()
        d = self._data
        rot = d.site_xmat[self._lidar_site].reshape(3, 3)
        np.matmul(self._beams_local, rot.T, out=self._ray_vec)
        self._ray_origin[:] = d.site_xpos[self._lidar_site]
        mujoco.mj_multiRay(
            self._model,
            d,
            self._ray_origin,
            self._ray_vec_flat,
            _RAY_GROUPS,
            1,
            self._chassis,
            self._ray_geom,
            self._ray_dist,
            None,
            self._nbeams,
            self._range_max,
        )
        dist = self._ray_dist
        hit = self._ray_geom >= 0
        valid = hit & (dist >= self._range_min) & (dist <= self._range_max)
        # REP 117: no return within range_max is +inf; a return closer than range_min
        # (too close to measure) is -inf, so nobody reads it as free space.
        too_close = hit & (dist < self._range_min)
        ranges = np.where(valid, dist, np.where(too_close, -np.inf, np.inf)).astype(np.float32)
        ranges.flags.writeable = False
        return RangeScan(
            angle_min=self._angle_min,
            angle_max=self._angle_min + self._angle_increment * (self._nbeams - 1),
            angle_increment=self._angle_increment,
            range_min=self._range_min,
            range_max=self._range_max,
            ranges=ranges,
        )

    def scan_hit_geoms(self) -> NDArray[np.int32]:
        """Geom id hit by each beam of the last :meth:`read_scan` (-1: miss). A copy."""
        return self._ray_geom.copy()

    def scan_floor_mask(self) -> NDArray[np.bool_]:
        """Per beam of the last :meth:`read_scan`: did it hit a floor plane within range?"""
        geoms, dist = self._ray_geom, self._ray_dist
        in_range = (geoms >= 0) & (dist >= self._range_min) & (dist <= self._range_max)
        mask = np.zeros(self._nbeams, dtype=np.bool_)
        mask[in_range] = self._is_floor[geoms[in_range]]
        return mask

    def scan_floor_hits(self) -> int:
        """How many beams of the last :meth:`read_scan` hit a floor plane within range.

        Non-zero means the chassis is pitched or rolled enough for the lidar to read the
        floor as an obstacle (the seeds' pitch bug).
        """
        return int(np.count_nonzero(self.scan_floor_mask()))

    def geom_name(self, geom_id: int) -> str:
        """Name of a geom id (e.g. from :meth:`scan_hit_geoms`); ``""`` if unnamed."""
        return str(mujoco.mj_id2name(self._model, mujoco.mjtObj.mjOBJ_GEOM, geom_id) or "")

    def ground_truth(self) -> GroundTruth:
        qpos, qvel = self._data.qpos, self._data.qvel
        p, v = self._base_qpos, self._base_qvel
        w, x, y, z = (float(c) for c in qpos[p + 3 : p + 7])
        sin_pitch = max(-1.0, min(1.0, 2.0 * (w * y - z * x)))
        return GroundTruth(
            x=float(qpos[p]),
            y=float(qpos[p + 1]),
            yaw=_yaw_of_quat(w, x, y, z),
            pitch=math.asin(sin_pitch),
            roll=math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y)),
            vx_world=float(qvel[v]),  # free joint: linear velocity is in the world frame
            vy_world=float(qvel[v + 1]),
        )

    def planar_truth(self) -> tuple[float, float, float, float]:
        # The judge's read at every tick: two slices instead of seven floats and the
        # attitude's trigonometry (2.9 -> ~0.4 us, ~1.5 % of the acceptance run).
        p, v = self._base_qpos, self._base_qvel
        x, y = self._data.qpos[p : p + 2].tolist()
        vx, vy = self._data.qvel[v : v + 2].tolist()  # free joint: world-frame velocity
        return x, y, vx, vy

    @property
    def geometry(self) -> RobotGeometry:
        return self._geometry

    def geometry_sources(self) -> dict[str, str]:
        return dict(self._sources)

    @property
    def robot(self) -> RobotDescription:
        """The description this world's robot was built from."""
        return self._robot

    def obstacles(self) -> tuple[BoxObstacle, ...]:
        return self._obstacles

    def walls(self) -> tuple[BoxObstacle, ...]:
        return self._walls

    def close(self) -> None:
        self._closed = True

    def _check_open(self) -> None:
        if self._closed:
            raise RuntimeError(f"MujocoInterface for {self._label} is closed")
