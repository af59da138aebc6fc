"""The lidar's numpy caster for static boxes and planes (ADR 0057) returns exactly what
``mj_multiRay`` returns: the same float64 distances, the same geom ids, so the same
float32 ranges and floor mask, on random worlds (boxes turned every way, overlapping,
straddling range_min and range_max, beams aimed at corners and edges, a pitched and
rolled lidar that sees the floor)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from otonav.bench._clutter import clutter_scenario
from otonav.hal._raycast import ray_box, ray_plane
from otonav.hal.mujoco import MujocoInterface
from otonav.hal.mujoco import _lidar as lidar
from otonav.hal.mujoco._lib import mujoco

_QUAT = st.tuples(*[st.floats(-1.0, 1.0) for _ in range(4)]).filter(
    lambda q: sum(c * c for c in q) > 0.01
)


def _unit(q: tuple[float, ...]) -> np.ndarray:
    a = np.array(q, dtype=np.float64)
    return a / np.linalg.norm(a)


def _mat(quat: np.ndarray) -> np.ndarray:
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, quat)
    return m


@settings(max_examples=400, deadline=None)
@given(
    pos=st.tuples(*[st.floats(-2, 2) for _ in range(3)]),
    quat=_QUAT,
    size=st.tuples(*[st.floats(0.01, 1.5) for _ in range(3)]),
    pnt=st.tuples(*[st.floats(-3, 3) for _ in range(3)]),
    corner=st.tuples(*[st.sampled_from([-1.0, 1.0]) for _ in range(3)]),
    along=st.sampled_from([0, 1, 2, None]),
    where=st.floats(-1.0, 1.0),
    jitter=st.sampled_from([0.0, 1e-12, -1e-12, 1e-3]),
)
def test_ray_box_is_mujocos_arithmetic(
    pos: tuple[float, ...],
    quat: tuple[float, ...],
    size: tuple[float, ...],
    pnt: tuple[float, ...],
    corner: tuple[float, ...],
    along: int | None,
    where: float,
    jitter: float,
) -> None:
    """Rays at a corner, along an edge, or at a face: ray_box gives mju_rayGeom's floats."""
    p, s, o = np.array(pos), np.array(size), np.array(pnt)
    m = _mat(_unit(quat))
    local = np.array(corner) * s
    if along is not None:
        local[along] = where * s[along]  # a point on an edge through the corner
    target = p + m.reshape(3, 3) @ local
    vec = target - o + jitter
    if np.linalg.norm(vec) < 1e-6:
        return
    ours = ray_box(p[None], m[None], s[None], o, vec[None])[0]
    theirs = mujoco.mju_rayGeom(p, m, s, o, vec, mujoco.mjtGeom.mjGEOM_BOX)
    assert ours == theirs


@settings(max_examples=300, deadline=None)
@given(
    quat=_QUAT,
    size=st.tuples(st.sampled_from([0.0, 0.5, 6.0]), st.sampled_from([0.0, 0.5, 6.0])),
    pnt=st.tuples(*[st.floats(-3, 3) for _ in range(3)]),
    vec=st.tuples(*[st.floats(-1, 1) for _ in range(3)]),
)
def test_ray_plane_is_mujocos_arithmetic(
    quat: tuple[float, ...],
    size: tuple[float, float],
    pnt: tuple[float, ...],
    vec: tuple[float, ...],
) -> None:
    v = np.array(vec)
    if np.linalg.norm(v) < 1e-6:
        return
    p, m, s, o = np.zeros(3), _mat(_unit(quat)), np.array([*size, 0.1]), np.array(pnt)
    ours = ray_plane(p[None], m[None], s[None], o, v[None])[0]
    theirs = mujoco.mju_rayGeom(p, m, s, o, v, mujoco.mjtGeom.mjGEOM_PLANE)
    assert ours == theirs


# -- whole scans against mj_multiRay ----------------------------------------------------

Box = tuple[float, float, float, float, float, float, tuple[float, ...]]
_BOX = st.tuples(
    st.floats(-3.0, 3.0),  # x
    st.floats(-3.0, 3.0),  # y
    st.floats(-0.2, 0.8),  # z
    st.floats(0.005, 0.6),  # half sizes
    st.floats(0.005, 0.6),
    st.floats(0.005, 0.6),
    st.one_of(st.just((1.0, 0.0, 0.0, 0.0)), _QUAT),
)


def _scene(path: Path, boxes: list[Box], floor: float) -> Path:
    geoms = []
    for i, (x, y, z, hx, hy, hz, q) in enumerate(boxes):
        w, a, b, c = (float(v) for v in _unit(q))
        geoms.append(
            f'<geom name="obstacle_{i}" type="box" pos="{x!r} {y!r} {z!r}" '
            f'size="{hx!r} {hy!r} {hz!r}" quat="{w!r} {a!r} {b!r} {c!r}" group="0"/>'
        )
    path.write_text(
        '<mujoco><option timestep="0.002"/><worldbody>'
        f'<geom name="floor" type="plane" size="{floor!r} {floor!r} 0.1" group="0"/>'
        + "".join(geoms)
        + "</worldbody></mujoco>"
    )
    return path


def _pair(
    scene: Path, monkeypatch: pytest.MonkeyPatch, **kw: Any
) -> tuple[MujocoInterface, MujocoInterface]:
    """The same world twice: the numpy caster on, and MuJoCo casting everything."""
    monkeypatch.setattr(lidar, "MIN_STATIC_BOXES", 0)
    fast = MujocoInterface(scene, **kw)
    monkeypatch.setattr(lidar, "MIN_STATIC_BOXES", 10**9)
    ref = MujocoInterface(scene, **kw)
    assert fast._lidar._caster is not None
    assert ref._lidar._caster is None
    return fast, ref


def _pose(
    world: MujocoInterface, x: float, y: float, z: float, yaw: float, pitch: float, roll: float
) -> None:
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    q = [
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ]
    p = world._base_qpos
    world._data.qpos[p : p + 3] = (x, y, z)
    world._data.qpos[p + 3 : p + 7] = q
    world._stale = True


def _same_scan(fast: MujocoInterface, ref: MujocoInterface) -> None:
    a, b = fast.read_scan(), ref.read_scan()

    assert np.array_equal(a.ranges, b.ranges)
    assert np.array_equal(fast.scan_hit_geoms(), ref.scan_hit_geoms())
    assert np.array_equal(fast._lidar._dist, ref._lidar._dist)  # every float64, bit for bit
    assert np.array_equal(fast.scan_floor_mask(), ref.scan_floor_mask())


@settings(
    max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    boxes=st.lists(_BOX, min_size=1, max_size=25),
    floor=st.sampled_from([0.0, 1.5, 6.0]),
    beams=st.sampled_from([7, 90, 360, 720]),
    ranges=st.sampled_from([(0.12, 8.0), (0.3, 1.5), (0.0, 3.0)]),
    poses=st.lists(
        st.tuples(
            st.floats(-3, 3),
            st.floats(-3, 3),
            st.floats(0.0, 0.6),
            st.floats(-math.pi, math.pi),
            st.floats(-0.7, 0.7),
            st.floats(-0.7, 0.7),
            st.booleans(),
        ),
        min_size=1,
        max_size=4,
    ),
)
def test_scans_are_mj_multirays(
    tmp_path_factory: pytest.TempPathFactory,
    monkeypatch: pytest.MonkeyPatch,
    boxes: list[Box],
    floor: float,
    beams: int,
    ranges: tuple[float, float],
    poses: list[tuple[Any, ...]],
) -> None:
    scene = _scene(tmp_path_factory.mktemp("w") / "w.xml", boxes, floor)
    fast, ref = _pair(
        scene,
        monkeypatch,
        lidar_beams=beams,
        lidar_range_min=ranges[0],
        lidar_range_max=ranges[1],
    )
    for x, y, z, yaw, pitch, roll, aim in poses:
        for world in (fast, ref):
            _pose(world, x, y, z, yaw, pitch, roll)
        if aim:
            # turn the lidar so that beam 0 points exactly at a corner of the first box
            fast._sync()
            origin = fast._data.site_xpos[fast._lidar_site]
            _x, _y, _z, hx, hy, hz, _q = boxes[0]
            gid = int(mujoco.mj_name2id(fast._model, mujoco.mjtObj.mjOBJ_GEOM, "obstacle_0"))
            corner = fast._data.geom_xpos[gid] + fast._data.geom_xmat[gid].reshape(3, 3) @ (
                np.array([hx, hy, hz])
            )
            bearing = math.atan2(corner[1] - origin[1], corner[0] - origin[0])
            for world in (fast, ref):
                _pose(world, x, y, z, bearing + math.pi, 0.0, 0.0)
        _same_scan(fast, ref)


def test_a_pitched_lidar_sees_the_floor_through_the_caster(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The seeds' pitch bug still shows: floor hits, MuJoCo's floor geom id, same mask."""
    scene = _scene(tmp_path / "w.xml", [(2.0, 0.0, 0.25, 0.1, 0.1, 0.25, (1, 0, 0, 0))], 6.0)
    fast, ref = _pair(scene, monkeypatch)
    for world in (fast, ref):
        _pose(world, 0.0, 0.0, 0.1, 0.0, 0.3, 0.0)  # nose down 0.3 rad
    _same_scan(fast, ref)
    assert int(fast.scan_floor_mask().sum()) > 10
    floor = int(mujoco.mj_name2id(fast._model, mujoco.mjtObj.mjOBJ_GEOM, "floor"))
    assert floor in set(fast.scan_hit_geoms().tolist())


def test_the_clutter_course_scans_as_mujoco_along_a_drive() -> None:
    """1000 boxes (the bench's course), the caster on by default: every scan of a drive
    along the lane is MuJoCo's, and no beam needed MuJoCo's fallback."""
    scenario = clutter_scenario(1000)
    boxes = [b.to_obstacle() for b in scenario.obstacles]
    fast = MujocoInterface("empty", extra_obstacles=boxes, start=(-3.0, 0.0, 0.0))
    assert fast._lidar._caster is not None  # 1000 >= MIN_STATIC_BOXES
    ref_geom = np.empty(fast._lidar.spec.beams, dtype=np.int32)
    ref_dist = np.empty(fast._lidar.spec.beams)
    unsure = 0
    cast = fast._lidar._caster.cast
    for step in range(30):
        _pose(fast, -3.0 + 0.2 * step, 0.3 * math.sin(step), 0.05, 0.1 * step, 0.0, 0.0)
        fast.read_scan()
        got_geom, got_dist = fast.scan_hit_geoms(), fast._lidar._dist.copy()
        fast._lidar._cast(fast._lidar._vec_flat, ref_geom, ref_dist, static=True)
        assert np.array_equal(got_geom, ref_geom)
        assert np.array_equal(got_dist, ref_dist)
        rot = fast._data.site_xmat[fast._lidar_site].reshape(3, 3)
        unsure += int(cast(fast._lidar._origin, rot, fast._lidar._vec, ref_geom, ref_dist).sum())
    assert unsure == 0


def test_small_worlds_keep_one_mujoco_call() -> None:
    """Below MIN_STATIC_BOXES MuJoCo casts everything (cheaper there), as before."""
    few = [b.to_obstacle() for b in clutter_scenario(lidar.MIN_STATIC_BOXES - 5).obstacles]
    assert MujocoInterface("empty", extra_obstacles=few)._lidar._caster is None
    many = [b.to_obstacle() for b in clutter_scenario(lidar.MIN_STATIC_BOXES).obstacles]
    assert MujocoInterface("empty", extra_obstacles=many)._lidar._caster is not None


def _with(path: Path, extra: str) -> Path:
    """A scene of 12 static boxes around the start, the floor, and ``extra`` MJCF."""
    upright: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0)
    ring: list[Box] = [
        (2.0 * math.cos(k / 2), 2.0 * math.sin(k / 2), 0.25, 0.1, 0.2, 0.25, upright)
        for k in range(12)
    ]
    _scene(path, ring, 6.0)
    path.write_text(path.read_text().replace("</worldbody>", extra + "</worldbody>"))
    return path


def test_moving_geoms_are_cast_by_mujoco_and_merged(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A box on a slide joint is not static: MuJoCo casts it (flg_static=0), the caster
    the rest, and the nearer return wins, as in one mj_multiRay."""
    scene = _with(
        tmp_path / "w.xml",
        '<body name="door" pos="1.0 0.3 0.25"><joint type="slide" axis="1 0 0"/>'
        '<geom name="door" type="box" size="0.05 0.4 0.25" group="0"/></body>',
    )
    fast, ref = _pair(scene, monkeypatch)
    assert fast._lidar._cast_moving
    door = int(mujoco.mj_name2id(fast._model, mujoco.mjtObj.mjOBJ_GEOM, "door"))
    for x in (0.0, 0.5, 1.5):
        for world in (fast, ref):
            _pose(world, x, 0.0, 0.05, 0.0, 0.0, 0.0)
        _same_scan(fast, ref)
        assert door in set(fast.scan_hit_geoms().tolist())


@pytest.mark.parametrize(
    "extra",
    [
        '<geom name="ball" type="sphere" size="0.2" pos="1 1 0.2" group="0"/>',
        '<body name="target" mocap="true" pos="1 1 0.2">'
        '<geom type="box" size="0.1 0.1 0.1" group="0"/></body>',
    ],
)
def test_worlds_the_caster_does_not_model_stay_with_mujoco(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, extra: str
) -> None:
    """A static geom of another type, or a mocap body (its 'static' geoms move): MuJoCo
    casts everything, as before."""
    monkeypatch.setattr(lidar, "MIN_STATIC_BOXES", 0)
    world = MujocoInterface(_with(tmp_path / "w.xml", extra))
    assert world._lidar._caster is None
