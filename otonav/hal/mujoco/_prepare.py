"""The robot's description put into a scene, on the ``MjSpec`` before compiling: its
model loaded (MJCF or URDF, assets found), wheel actuators driven as velocity loops, a
free base, casters made frictionless, lidar and IMU sites and sensors, physics options
merged. Each choice recorded with where it came from."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ElementTree
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Final

import numpy as np

from otonav.hal._description import BUILTIN_ROBOTS, Mount, RobotDescription
from otonav.hal.mujoco._lib import mujoco
from otonav.hal.mujoco._scene import SceneError, _one_line

__all__ = ["ROBOT_PREFIX"]

_ROBOT_GROUP: Final = 1
ROBOT_PREFIX: Final = "robot/"
"""Names of an attached robot's elements in the compiled world (the scene's own names
never clash with the robot's)."""
_SERVO_SLIP: Final = 0.1
"""rad/s of speed error at which a velocity loop otonav makes reaches its torque limit."""
_DEFAULT_TORQUE_G: Final = 0.2
"""A wheel with no stated torque limit gets 0.2 m g r: both wheels can then accelerate
the robot at 0.4 g (ample for any base limit) without lifting a caster off the floor."""


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
        self.ctrl_scale: dict[str, float] = {}
        self.base = self._mover(self._body(robot.base, "base"))
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

    @staticmethod
    def _mover(body: Any) -> Any:
        """The body that moves ``body``: itself, or the first ancestor up a chain of
        fixed (jointless) links that has a joint or sits in the world (base_footprint
        above base_link, as a URDF's fixed joints nest them)."""
        while not body.joints and body.parent is not None and body.parent.name != "world":
            body = body.parent
        return body

    def _wheel(self, name: str, key: str) -> Any:
        if key == "right_wheel" and name == self.robot.left_wheel:
            raise self.fail(
                key,
                f"names the same joint as {self.robot.key}left_wheel ({name!r}); "
                "name the right wheel's joint",
            )
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

    def casters(self, resting: Sequence[int]) -> None:
        """Geoms of the robot other than the wheels that rest on the floor with them
        (``resting``: indexes into the spec's geoms) are casters: made frictionless
        (condim 1, priority 1 so the floor's friction does not win the contact), as a
        URDF cannot say (its friction tags are Gazebo's); otherwise they drag like
        brakes."""
        geoms = self.spec.geoms
        made, kept = [], []
        for index in resting:
            geom = geoms[index]
            name = repr(geom.name) if geom.name else f"#{index} of body {geom.parent.name!r}"
            if int(geom.condim) == 1 and int(geom.priority) >= 1:
                kept.append(name)
                continue
            made.append(f"{name} (condim {int(geom.condim)}, priority {int(geom.priority)})")
            geom.condim = 1
            geom.priority = max(1, int(geom.priority))
        if made:
            self.sources["casters"] = f"made frictionless by otonav: {', '.join(made)}"
        elif kept:
            self.sources["casters"] = f"frictionless in the model: {', '.join(kept)}"

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


_XACRO_NS: Final = "{http://ros.org/wiki/xacro}"
_XACRO_SUBST: Final = re.compile(r"\$[{(]")


def _xacro_use(path: Path) -> str | None:
    """What in ``path`` is xacro (an element or a ``${...}``/``$(...)``), or None. MuJoCo
    would read such a file without its macros (ADR 0068): a caster silently gone."""
    text = path.read_text(errors="replace")
    if "xacro" not in text and "${" not in text:
        return None
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError:
        return None  # MuJoCo's own parse error says where
    for element in root.iter():
        if isinstance(element.tag, str) and element.tag.startswith(_XACRO_NS):
            return f"<xacro:{element.tag.removeprefix(_XACRO_NS)}>"
        for value in element.attrib.values():
            if _XACRO_SUBST.search(value):
                return repr(value)
    return None


def _load_robot(robot: RobotDescription) -> tuple[Any, str]:
    """The robot's model as a spec, its asset files found where the model says."""
    path = Path(robot.model)
    label = robot.label
    if not path.is_file():
        raise SceneError(
            f"{robot.key}model: {label!r} is neither a built-in robot "
            f"({', '.join(BUILTIN_ROBOTS)}) nor an existing MJCF or URDF file"
        )
    xacro = _xacro_use(path)
    if xacro is not None:
        expanded = (
            path.name.removesuffix(".xacro") if path.name.endswith(".xacro") else "robot.urdf"
        )
        raise SceneError(
            f"{robot.key}model: {label} uses xacro ({xacro}), which otonav does not expand: "
            f"expand it first (xacro {path.name} > {expanded}) and name the result"
        )
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:
        raise SceneError(f"{robot.key}model: {label} does not parse: {_one_line(exc)}") from None
    _absolute_assets(spec, path)
    spec.compiler.fusestatic = False  # URDF's default: it would fuse the base into the world
    return spec, label
