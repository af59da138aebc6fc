"""Every static geom the robot can touch is judged (issue 42): boxes whatever their
name, upright cylinders, capsules and spheres as disks; a mesh or a tilted cylinder is
named as unjudged, and a run among them fails: a clearance never measured is no pass."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from otonav.hal import BoxObstacle, RoundObstacle
from otonav.hal.mujoco import MujocoInterface
from otonav.scenario import run_scenario
from otonav.scenario._config import GoalSpec, ScenarioConfig
from otonav.stack import StackConfig

pytestmark = pytest.mark.unit

SCENE = """<mujoco>
  <asset>
    <mesh name="rock" vertex="0 0 0  0.2 0 0  0 0.2 0  0 0 0.2"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <geom name="pillar" type="cylinder" pos="2 1 0.5" size="0.1 0.5"/>
    <geom name="ball" type="sphere" pos="-2 1 0.3" size="0.3"/>
    <geom name="post" type="capsule" pos="0 -2 0.5" size="0.05 0.4"/>
    <geom name="crate" type="box" pos="3 -3 0.2" size="0.2 0.3 0.2"/>
    <geom name="ghost" type="cylinder" pos="4 4 0.5" size="0.1 0.5" contype="0"
          conaffinity="0"/>
    <body name="shelf" pos="-3 -3 0">
      <geom name="shelf_leg" type="cylinder" pos="0.5 0 0.5" size="0.05 0.5"/>
    </body>
    {extra}
  </worldbody>
</mujoco>
"""
TILTED = '<geom name="log" type="cylinder" pos="-3 3 0.1" size="0.1 0.5" euler="1.5708 0 0"/>'
EGG = '<geom name="egg" type="ellipsoid" pos="4 -4 0.2" size="0.1 0.2 0.3"/>'
MESH = '<geom name="boulder" type="mesh" mesh="rock" pos="3 3 0"/>'


def _scene(tmp_path: Path, extra: str = "") -> Path:
    path = tmp_path / "shapes.xml"
    path.write_text(SCENE.replace("{extra}", extra))
    return path


def test_every_static_shape_is_seen(tmp_path: Path) -> None:
    world = MujocoInterface(_scene(tmp_path))
    try:
        assert world.obstacles() == (BoxObstacle(3.0, -3.0, 0.2, 0.3, 0.0),)
        rounds = sorted(world.round_obstacles(), key=lambda r: (r.x, r.y))
        expected = [(-2.5, -3.0, 0.05), (-2.0, 1.0, 0.3), (0.0, -2.0, 0.05), (2.0, 1.0, 0.1)]
        for r, (x, y, radius) in zip(rounds, expected, strict=True):
            assert (r.x, r.y, r.radius) == pytest.approx((x, y, radius), abs=1e-9)
        assert all(isinstance(r, RoundObstacle) for r in rounds)
        assert world.unjudged_geoms() == ()
    finally:
        world.close()


def test_tilted_cylinders_and_ellipsoids_are_named_unjudged(tmp_path: Path) -> None:
    world = MujocoInterface(_scene(tmp_path, TILTED + EGG))
    try:
        assert world.unjudged_geoms() == ("log (CYLINDER)", "egg (ELLIPSOID)")
    finally:
        world.close()


def test_a_mesh_is_judged_by_its_footprint(tmp_path: Path) -> None:
    """The tetrahedron (0,0,0) (0.2,0,0) (0,0.2,0) (0,0,0.2) at (3, 3): its floor
    footprint is the triangle (3,3) (3.2,3) (3,3.2), wherever MuJoCo puts the mesh frame."""
    world = MujocoInterface(_scene(tmp_path, MESH))
    try:
        (hull,) = world.polygon_obstacles()
        corners = [c for point in sorted(hull.points) for c in point]
        assert corners == pytest.approx([3.0, 3.0, 3.0, 3.2, 3.2, 3.0])
        assert hull.distance_to(3.05, 3.05) == 0.0
        assert hull.distance_to(2.0, 3.0) == pytest.approx(1.0)
        assert hull.distance_to(3.2, 3.2) == pytest.approx(math.sqrt(0.02))  # 0.2 / sqrt 2
        assert world.unjudged_geoms() == ()
    finally:
        world.close()


def test_a_run_whose_clearance_was_not_measured_fails(tmp_path: Path) -> None:
    scenario = ScenarioConfig(
        name="unjudged", scene=str(_scene(tmp_path, EGG)), goal=GoalSpec(x=1.0, y=0.0)
    )
    verdict = run_scenario(scenario, StackConfig(), record=False, plot=False)
    assert verdict.reached  # the robot did arrive ...
    assert not verdict.passed  # ... but nobody measured how close it came to the egg
    assert "clearance not measured" in verdict.reason
    assert "egg (ELLIPSOID)" in verdict.reason


def test_a_cylinder_s_clearance_is_measured(tmp_path: Path) -> None:
    scenario = ScenarioConfig(
        name="cylinders", scene=str(_scene(tmp_path)), goal=GoalSpec(x=1.0, y=0.0)
    )
    verdict = run_scenario(scenario, StackConfig(), record=False, plot=False)
    assert verdict.passed, verdict.reason
    # The pillar (r 0.1 at (2, 1)) is the nearest near the goal: hypot(1, 1) - 0.1 =
    # 1.314 m from it; the post (r 0.05 at (0, -2)) 1.95 m from the start.
    assert 1.3 < verdict.min_clearance_m < 1.95


def test_the_plot_draws_disks_and_mesh_footprints_with_the_boxes() -> None:
    """Issue 42: a scene of cylinders drew no obstacle. One artist still draws them all."""
    from otonav.hal import PolygonObstacle
    from otonav.scenario._plot import draw_trajectory

    shapes = (
        BoxObstacle(1.0, 0.5, 0.2, 0.3, 0.0),
        RoundObstacle(-1.0, 2.0, 0.075),
        PolygonObstacle(((3.0, 3.0), (3.2, 3.0), (3.0, 3.2))),
    )
    trajectory = [(0.0, 0.0, 0.0), (1.0, 0.0, 1.0)]
    fig = draw_trajectory(trajectory, shapes, (0.0, 3.0), 0.15, None, "shapes")
    (ax,) = fig.axes
    (patch,) = [p for p in ax.patches if p.get_label() == "obstacles, walls"]
    vertices = [(float(vx), float(vy)) for vx, vy in np.asarray(patch.get_path().vertices)]
    # The disk's rightmost and top points, and the triangle's corners, are outlined.
    for x, y in ((-0.925, 2.0), (-1.0, 2.075), (3.2, 3.0), (3.0, 3.2)):
        assert min(math.hypot(vx - x, vy - y) for vx, vy in vertices) < 1e-9, (x, y)
