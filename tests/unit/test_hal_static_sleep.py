"""Static geoms placed once (ADR 0062): MuJoCo's sleeping skips them in ``mj_kinematics``,
and the physics, the sensors and every scan stay bit for bit what they were."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from otonav.bench._clutter import clutter_scenario
from otonav.hal import WheelSetpoint
from otonav.hal.mujoco import MujocoInterface
from otonav.hal.mujoco import _lidar as lidar
from otonav.hal.mujoco import _static_sleep as static_sleep
from otonav.hal.mujoco._lib import mujoco


def _clutter(
    n: int, monkeypatch: pytest.MonkeyPatch, *, anchor: bool, caster: bool, **kw: object
) -> MujocoInterface:
    monkeypatch.setattr(static_sleep, "MIN_STATIC_GEOMS", 100 if anchor else 10**9)
    monkeypatch.setattr(lidar, "MIN_STATIC_BOXES", 400 if caster else 10**9)
    boxes = [b.to_obstacle() for b in clutter_scenario(n).obstacles]
    return MujocoInterface("empty", extra_obstacles=boxes, **kw)  # type: ignore[arg-type]


def _drive(
    worlds: tuple[MujocoInterface, MujocoInterface], steps: int, scan_every: int = 5
) -> None:
    """Both worlds driven by the same commands; after every step the ground truth, and
    every ``scan_every`` steps the wheels, the IMU and the whole scan, must be equal."""
    a, b = worlds
    for k in range(steps):
        t = 0.002 * k
        cmd = WheelSetpoint(left=6.0 + 4.0 * math.sin(t), right=6.0 + 4.0 * math.cos(0.7 * t))
        for w in worlds:
            w.write(cmd)
            w.advance(1)
        assert a.ground_truth() == b.ground_truth(), k
        if k % scan_every == 0:
            assert a.read_wheels() == b.read_wheels()
            assert a.read_imu() == b.read_imu()
            sa, sb = a.read_scan(), b.read_scan()
            assert np.array_equal(sa.ranges, sb.ranges), k
            assert np.array_equal(a.scan_hit_geoms(), b.scan_hit_geoms()), k
            assert np.array_equal(a._lidar._dist, b._lidar._dist), k  # every float64


@pytest.mark.parametrize("start", [(-3.0, 0.0, 0.0), (-3.0, 1.3, 0.3)])
def test_the_1000_box_course_is_what_it_was_bit_for_bit(
    start: tuple[float, float, float], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The clutter bench's 1000-box world, anchored (static geoms placed once, the numpy
    caster), against the world as it was before ADR 0057 (every geom placed every step,
    mj_multiRay casting everything): the same ground truth after every step, the same
    wheels, IMU and scans. From (-3, 1.3) the robot drives into the boxes (contacts)."""
    fast = _clutter(1000, monkeypatch, anchor=True, caster=True, start=start)
    ref = _clutter(1000, monkeypatch, anchor=False, caster=False, start=start)
    assert fast._model.nbody == ref._model.nbody + 1
    assert fast._lidar._caster is not None
    assert ref._lidar._caster is None
    _drive((fast, ref), 2500)
    if start[1] > 0:  # it did meet the boxes: box contacts, the same in both
        m: Any = fast._model
        boxes = {g for g in range(m.ngeom) if fast.geom_name(g).startswith("obstacle")}
        touched = []
        for world in (fast, ref):
            d: Any = world._data
            touched.append({int(g) for c in d.contact[: d.ncon] for g in (c.geom1, c.geom2)})
        assert touched[0] & boxes
        assert touched[0] == touched[1]


def test_static_geoms_are_no_longer_placed_each_step(monkeypatch: pytest.MonkeyPatch) -> None:
    """The point of the anchor: mj_kinematics leaves the static geoms' poses alone (a
    pose overwritten stays overwritten) and still places the robot's."""
    for anchor in (True, False):
        world = _clutter(300, monkeypatch, anchor=anchor, caster=False)
        m, d = world._model, world._data
        box = next(g for g in range(m.ngeom) if world.geom_name(g).startswith("obstacle"))
        wheel = next(g for g in range(m.ngeom) if int(m.geom_bodyid[g]) != 0)
        kept = d.geom_xpos[box].copy()
        d.geom_xpos[box] = (9.0, 9.0, 9.0)
        d.geom_xpos[wheel] = (9.0, 9.0, 9.0)
        mujoco.mj_kinematics(m, d)
        assert tuple(d.geom_xpos[wheel]) != (9.0, 9.0, 9.0)
        if anchor:
            assert tuple(d.geom_xpos[box]) == (9.0, 9.0, 9.0)
            d.geom_xpos[box] = kept
        else:
            assert np.array_equal(d.geom_xpos[box], kept)


def test_only_worlds_with_many_static_geoms_are_anchored() -> None:
    """From MIN_STATIC_GEOMS static geoms on (the empty scene has 5: floor and walls)."""
    n = static_sleep.MIN_STATIC_GEOMS - 5
    few = [b.to_obstacle() for b in clutter_scenario(n - 1).obstacles]
    many = [b.to_obstacle() for b in clutter_scenario(n).obstacles]
    for boxes, expect in ((few, False), (many, True)):
        world = MujocoInterface("empty", extra_obstacles=boxes)
        m = world._model
        found = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, static_sleep.ANCHOR) >= 0
        assert found is expect
        assert bool(m.opt.enableflags & mujoco.mjtEnableBit.mjENBL_SLEEP) is expect


def _scene_with_a_loose_box(path: Path, flags: str = "") -> Path:
    """150 static boxes in a ring, and a free box resting on the floor near the robot
    (its own tree: with sleeping on and its policy left alone it would fall asleep)."""
    ring = "".join(
        f'<geom name="obstacle_{k}" type="box" size="0.05 0.05 0.25" group="0" '
        f'pos="{3.0 * math.cos(k / 24)!r} {3.0 * math.sin(k / 24)!r} 0.25"/>'
        for k in range(150)
    )
    path.write_text(
        f'<mujoco><option timestep="0.002" integrator="implicitfast">{flags}</option>'
        '<worldbody><geom name="floor" type="plane" size="6 6 0.1" group="0"/>'
        + ring
        + '<body name="loose" pos="1.5 0.6 0.1"><freejoint/>'
        '<geom type="box" size="0.1 0.1 0.1" group="0" mass="0.5"/></body>'
        "</worldbody></mujoco>"
    )
    return path


def test_other_trees_never_sleep(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A scene's own free body keeps moving as it did (sleeping is on for the anchor
    only): the robot drives into it, and both trees stay awake to the end."""
    scene = _scene_with_a_loose_box(tmp_path / "loose.xml")
    monkeypatch.setattr(static_sleep, "MIN_STATIC_GEOMS", 100)
    fast = MujocoInterface(scene, start=(0.0, 0.0, 0.4))
    monkeypatch.setattr(static_sleep, "MIN_STATIC_GEOMS", 10**9)
    ref = MujocoInterface(scene, start=(0.0, 0.0, 0.4))
    _drive((fast, ref), 1500, scan_every=25)
    m, d, dr = fast._model, fast._data, ref._data
    nq, nv = ref._model.nq, ref._model.nv
    assert np.array_equal(d.qpos[:nq], dr.qpos[:nq])
    assert np.array_equal(d.qvel[:nv], dr.qvel[:nv])
    anchor = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, static_sleep.ANCHOR)
    awake = [int(a) for a in d.tree_awake]
    anchor_tree = int(m.body_treeid[anchor])
    assert awake[anchor_tree] == 0
    assert all(a == 1 for t, a in enumerate(awake) if t != anchor_tree)
    assert len(awake) == 3  # robot, loose box, anchor


def test_a_scene_that_sleeps_itself_is_left_alone(tmp_path: Path) -> None:
    scene = _scene_with_a_loose_box(tmp_path / "sleeps.xml", '<flag sleep="enable"/>')
    world = MujocoInterface(scene)
    m = world._model
    assert mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, static_sleep.ANCHOR) < 0
    assert m.opt.enableflags & mujoco.mjtEnableBit.mjENBL_SLEEP


def test_the_static_geom_count(tmp_path: Path) -> None:
    """World-body geoms, and those of jointless bodies under it; not a moving body's, nor
    a mocap body's, nor what hangs under them."""
    spec = mujoco.MjSpec.from_string(
        "<mujoco><worldbody><geom type='plane' size='1 1 1'/>"
        "<body><geom size='.1'/><geom size='.1'/><body><geom size='.1'/></body>"
        "<body><joint/><geom size='.1'/><body><geom size='.1'/></body></body></body>"
        "<body mocap='true'><geom size='.1'/><body><geom size='.1'/></body></body>"
        "</worldbody></mujoco>"
    )
    assert static_sleep.static_geom_count(spec) == 4
