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
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any, Final, Literal

import numpy as np
from numpy.typing import NDArray

from otonav.hal.interface import RobotHardwareInterface
from otonav.hal.types import (
    BoxObstacle,
    GroundTruth,
    ImuSample,
    RangeScan,
    RobotGeometry,
    WheelCommand,
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


class SceneError(ValueError):
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
        if timestep is not None:
            spec.option.timestep = timestep
        for i, box in enumerate(extra_obstacles):
            _add_box(spec, f"obstacle_extra_{i}", box)
        if variant == "no_caster_unlimited_torque":
            _apply_bug_variant(spec, label)
        self._variant: Variant = variant
        self._model: Any = _compile(spec, label)
        self._data: Any = mujoco.MjData(self._model)
        m = self._model

        def need(obj: Any, name: str) -> int:
            ident = int(mujoco.mj_name2id(m, obj, name))
            if ident < 0:
                kind = str(obj).rsplit(".", 1)[-1].removeprefix("mjOBJ_").lower()
                raise SceneError(f"MJCF file {label}: no {kind} named {name!r}")
            return ident

        obj = mujoco.mjtObj
        self._chassis = need(obj.mjOBJ_BODY, "chassis")
        base_joint = int(m.body_jntadr[self._chassis])
        if base_joint < 0 or m.jnt_type[base_joint] != mujoco.mjtJoint.mjJNT_FREE:
            raise SceneError(f"MJCF file {label}: body 'chassis' needs a free joint")
        self._base_qpos = int(m.jnt_qposadr[base_joint])
        self._base_qvel = int(m.jnt_dofadr[base_joint])
        left_joint = need(obj.mjOBJ_JOINT, "left_wheel")
        right_joint = need(obj.mjOBJ_JOINT, "right_wheel")
        self._wheel_qpos = (int(m.jnt_qposadr[left_joint]), int(m.jnt_qposadr[right_joint]))
        self._wheel_qvel = (int(m.jnt_dofadr[left_joint]), int(m.jnt_dofadr[right_joint]))
        self._left_act = need(obj.mjOBJ_ACTUATOR, "left_motor")
        self._right_act = need(obj.mjOBJ_ACTUATOR, "right_motor")
        self._lidar_site = need(obj.mjOBJ_SITE, "lidar")
        self._imu_site = need(obj.mjOBJ_SITE, "imu")

        def sensor_slice(name: str) -> slice:
            ident = need(obj.mjOBJ_SENSOR, name)
            adr = int(m.sensor_adr[ident])
            return slice(adr, adr + int(m.sensor_dim[ident]))

        self._gyro = sensor_slice("imu_gyro")
        self._accel = sensor_slice("imu_accel")
        self._quat = sensor_slice("imu_quat")

        # The lidar must not see the robot: every geom of the robot's tree in group 1.
        robot_root = int(m.body_rootid[self._chassis])
        visible = [
            mujoco.mj_id2name(m, obj.mjOBJ_GEOM, g) or f"#{g}"
            for g in range(m.ngeom)
            if int(m.body_rootid[m.geom_bodyid[g]]) == robot_root
            and int(m.geom_group[g]) != _ROBOT_GROUP
        ]
        if visible:
            raise SceneError(
                f"MJCF file {label}: robot geoms {visible} must be in geom group "
                f"{_ROBOT_GROUP}, or the lidar sees the robot itself"
            )

        self._geometry = self._read_geometry(left_joint, right_joint)
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

    def _read_geometry(self, left_joint: int, right_joint: int) -> RobotGeometry:
        m = self._model
        left_body = int(m.jnt_bodyid[left_joint])
        right_body = int(m.jnt_bodyid[right_joint])
        left_geoms = [g for g in range(m.ngeom) if int(m.geom_bodyid[g]) == left_body]
        if not left_geoms:
            raise SceneError(f"MJCF file {self._label}: wheel 'left_wheel' has no geom")
        radius = float(m.geom_size[left_geoms[0]][0])
        separation = float(np.linalg.norm(m.body_pos[left_body] - m.body_pos[right_body]))
        if int(m.site_bodyid[self._lidar_site]) != self._chassis:
            raise SceneError(f"MJCF file {self._label}: site 'lidar' must be on 'chassis'")
        lidar = m.site_pos[self._lidar_site]
        if int(m.site_bodyid[self._imu_site]) != self._chassis:
            raise SceneError(f"MJCF file {self._label}: site 'imu' must be on 'chassis'")
        imu = m.site_pos[self._imu_site]
        return RobotGeometry(
            wheel_radius=radius,
            wheel_separation=separation,
            laser_offset_x=float(lidar[0]),
            laser_offset_z=float(lidar[2]),
            base_height=float(m.qpos0[self._base_qpos + 2]),
            imu_offset=(float(imu[0]), float(imu[1]), float(imu[2])),
            footprint=self._read_footprint(),
        )

    def _read_footprint(self) -> tuple[tuple[float, float], ...]:
        """The rectangle in base_link (CCW corners, m) that bounds every collision geom
        of the robot projected on the floor, at the model's rest pose (qpos0)."""
        m = self._model
        d = mujoco.MjData(m)
        mujoco.mj_kinematics(m, d)
        root = int(m.body_rootid[self._chassis])
        origin = d.xpos[self._chassis].copy()
        to_base = d.xmat[self._chassis].reshape(3, 3).T
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        xy: list[NDArray[np.float64]] = []
        for g in range(m.ngeom):
            collides = int(m.geom_contype[g]) != 0 or int(m.geom_conaffinity[g]) != 0
            if int(m.body_rootid[m.geom_bodyid[g]]) != root or not collides:
                continue
            size = m.geom_size[g]
            kind = int(m.geom_type[g])
            if kind in (mujoco.mjtGeom.mjGEOM_SPHERE,):
                half = np.array([size[0], size[0], size[0]])
            elif kind in (mujoco.mjtGeom.mjGEOM_CYLINDER, mujoco.mjtGeom.mjGEOM_CAPSULE):
                extra = size[0] if kind == mujoco.mjtGeom.mjGEOM_CAPSULE else 0.0
                half = np.array([size[0], size[0], size[1] + extra])
            else:  # box, ellipsoid: half sizes along the geom's axes
                half = np.array(size[:3], dtype=np.float64)
            corners = (signs * half) @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g]
            xy.append(((corners - origin) @ to_base.T)[:, :2])
        if not xy:
            raise SceneError(f"MJCF file {self._label}: the robot has no collision geom")
        points = np.concatenate(xy)
        x0, y0 = (float(v) for v in points.min(axis=0))
        x1, y1 = (float(v) for v in points.max(axis=0))
        return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))

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

    def write(self, cmd: WheelCommand) -> None:
        self._check_open()
        if not (math.isfinite(cmd.left) and math.isfinite(cmd.right)):
            raise ValueError(f"wheel command must be finite, got {cmd}")
        self._data.ctrl[self._left_act] = cmd.left
        self._data.ctrl[self._right_act] = cmd.right

    def read_wheels(self) -> WheelState:
        qpos, qvel = self._data.qpos, self._data.qvel
        return WheelState(
            left_position=float(qpos[self._wheel_qpos[0]]),
            right_position=float(qpos[self._wheel_qpos[1]]),
            left_velocity=float(qvel[self._wheel_qvel[0]]),
            right_velocity=float(qvel[self._wheel_qvel[1]]),
        )

    def wheel_values(self) -> tuple[float, float, float, float]:
        # The drive emulator's read at every 10 ms instant: the same four doubles as
        # read_wheels, without building a WheelState (1.1 -> ~0.35 us).
        qpos, qvel = self._data.qpos, self._data.qvel
        (pl, pr), (vl, vr) = self._wheel_qpos, self._wheel_qvel
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

    def obstacles(self) -> tuple[BoxObstacle, ...]:
        return self._obstacles

    def walls(self) -> tuple[BoxObstacle, ...]:
        return self._walls

    def close(self) -> None:
        self._closed = True

    def _check_open(self) -> None:
        if self._closed:
            raise RuntimeError(f"MujocoInterface for {self._label} is closed")
