"""Robot descriptions: built-in robots, models written the ways people write them
(meshes in mm, mirrored joints, geared, motor and position actuators, URDF, no
sensors), the values derived from them, and one-line errors naming the robot key."""

from __future__ import annotations

import math
import shutil
import struct
import zipfile
from dataclasses import replace
from pathlib import Path

import anyio
import numpy as np
import pytest

from otonav.actors import Bridge, topics
from otonav.hal import BoxObstacle, WheelSetpoint
from otonav.hal import _description as description
from otonav.hal._description import Mount, RobotDescription, builtin_robot
from otonav.hal.mujoco import MujocoInterface, SceneError, scene_path
from otonav.msgs import JointState, WheelCommand
from otonav.runtime import System, virtual_loop_factory
from otonav.scenario._verdict import lidar_over_obstacles

PATHFINDER = Path(__file__).resolve().parents[2] / "examples" / "my_robot"


def pathfinder(model: Path = PATHFINDER / "pathfinder.xml", **changes: object) -> RobotDescription:
    values: dict[str, object] = {
        "model": str(model),
        "label": model.name,
        "base": "chassis_link",
        "left_wheel": "left_wheel_hinge",
        "right_wheel": "right_wheel_hinge",
    }
    values.update(changes)
    return RobotDescription(**values)  # type: ignore[arg-type]


def urdf(**changes: object) -> RobotDescription:
    values: dict[str, object] = {
        "model": str(PATHFINDER / "pathfinder.urdf"),
        "label": "pathfinder.urdf",
        "base": "base_link",
        "left_wheel": "left_wheel_joint",
        "right_wheel": "right_wheel_joint",
        "lidar": Mount(body="laser_link", pos=(0.0, 0.0, 0.0)),
    }
    values.update(changes)
    return RobotDescription(**values)  # type: ignore[arg-type]


def variant(tmp_path: Path, old: str, new: str) -> RobotDescription:
    """The MJCF test robot with one edit, next to a copy of its meshes."""
    shutil.copytree(PATHFINDER / "meshes", tmp_path / "meshes", dirs_exist_ok=True)
    text = (PATHFINDER / "pathfinder.xml").read_text()
    assert old in text
    path = tmp_path / "edited.xml"
    path.write_text(text.replace(old, new))
    return pathfinder(path)


def old_scene(tmp_path: Path, scene: str) -> Path:
    """A built-in scene as scenes were written before: including robot.xml."""
    assets = Path(MujocoInterface("empty")._label).parent
    shutil.copy(assets / "robot.xml", tmp_path / "robot.xml")
    text = (assets / f"{scene}.xml").read_text()
    attached = '<compiler angle="radian"/>\n  <option timestep="0.002" integrator="implicitfast"/>'
    assert attached in text
    path = tmp_path / "old.xml"
    path.write_text(text.replace(attached, '<include file="robot.xml"/>'))
    return path


def drive(world: MujocoInterface, speed: float = 3.0, seconds: float = 1.0) -> None:
    world.write(WheelSetpoint(speed, speed))
    world.advance(round(seconds / world.tick))


def test_burger_has_the_turtlebot3_burgers_published_dimensions() -> None:
    world = MujocoInterface("empty", robot=builtin_robot("burger"))
    g = world.geometry
    assert g.wheel_radius == pytest.approx(0.033)
    assert g.wheel_separation == pytest.approx(0.160)
    xs = [x for x, _ in g.footprint]
    ys = [y for _, y in g.footprint]
    assert max(xs) - min(xs) == pytest.approx(0.138, abs=0.005)
    assert max(ys) - min(ys) == pytest.approx(0.178, abs=0.005)
    assert g.base_height + g.laser_offset_z == pytest.approx(0.172, abs=0.002)
    assert builtin_robot("burger").max_v == 0.22


def test_a_mesh_wheel_gives_its_radius_and_the_joints_their_separation() -> None:
    world = MujocoInterface("empty", robot=pathfinder())
    g = world.geometry
    assert g.wheel_radius == pytest.approx(0.0762, abs=1e-5)  # the mesh's 76.2 mm, scaled
    assert g.wheel_separation == pytest.approx(0.30)
    sources = world.geometry_sources()
    assert "mesh geom 'left_tyre'" in sources["wheel_radius"]
    assert "free joint added" in sources["base"]
    assert "otonav's default" in sources["lidar"]  # the model has no sensor of its own


def test_a_mirrored_geared_wheel_joint_still_drives_forward() -> None:
    world = MujocoInterface("empty", robot=pathfinder())
    drive(world)
    truth = world.ground_truth()
    assert truth.vx_world == pytest.approx(3.0 * 0.0762, rel=0.05)  # 3 rad/s x r, forward
    assert truth.x > 0.15
    assert abs(truth.y) < 0.01
    assert abs(truth.yaw) < 0.01
    wheels = world.read_wheels()
    assert wheels.left_velocity == pytest.approx(3.0, rel=0.05)
    assert wheels.right_velocity == pytest.approx(3.0, rel=0.05)
    assert wheels.left_position > 0
    assert wheels.right_position > 0


def test_a_urdf_with_package_meshes_and_no_actuators_drives() -> None:
    world = MujocoInterface("empty", robot=urdf())
    sources = world.geometry_sources()
    assert sources["left_wheel_actuator"].startswith("none in the model")
    assert "frictionless" in sources["casters"]  # URDF spheres would drag otherwise
    assert world.geometry.laser_offset_x == pytest.approx(0.05)
    assert world.geometry.laser_offset_z == pytest.approx(0.12)
    drive(world)
    assert world.ground_truth().vx_world == pytest.approx(3.0 * 0.0762, rel=0.05)


@pytest.mark.parametrize("lidar", [None, Mount(pos=(0.0, 0.0, 0.05))], ids=["on-top", "inside"])
def test_the_lidar_does_not_see_the_robot_itself(lidar: Mount | None) -> None:
    """Inside its housing too (0.05 m up is inside the deck's collision box), as vendor
    models mount it: every geom of the robot is out of the rays, whichever body's."""
    world = MujocoInterface("empty", robot=pathfinder(lidar=lidar))
    ranges = world.read_scan().ranges
    finite = ranges[np.isfinite(ranges)]
    assert finite.size > 0  # the arena's walls
    assert float(finite.min()) > 4.0  # nothing of the robot (its deck reaches 0.24 m)


@pytest.mark.parametrize(
    ("actuator", "kind"),
    [
        ('<motor name="left_drive" joint="left_wheel_hinge" ctrlrange="-1 1"/>', "motor"),
        ('<position name="left_drive" joint="left_wheel_hinge" kp="20"/>', "position"),
    ],
)
def test_motor_and_position_actuators_are_driven_as_velocity_loops(
    tmp_path: Path, actuator: str, kind: str
) -> None:
    old = '<velocity name="left_drive" joint="left_wheel_hinge" kv="4" gear="2" forcerange="-1 1"/>'
    world = MujocoInterface("empty", robot=variant(tmp_path, old, actuator))
    assert world.geometry_sources()["left_wheel_actuator"].startswith(kind)
    drive(world)
    assert world.read_wheels().left_velocity == pytest.approx(3.0, rel=0.05)
    assert abs(world.ground_truth().yaw) < 0.05  # both wheels at the same speed


def test_a_models_own_rangefinder_places_the_lidar(tmp_path: Path) -> None:
    robot = variant(
        tmp_path,
        '<body name="left_wheel_link"',
        '<site name="scanner" pos="0.08 0 0.1" zaxis="1 0 0"/>\n      <body name="left_wheel_link"',
    )
    text = (
        Path(robot.model)
        .read_text()
        .replace(
            "</actuator>",
            '</actuator>\n  <sensor><rangefinder name="front" site="scanner"/></sensor>',
        )
    )
    Path(robot.model).write_text(text)
    world = MujocoInterface("empty", robot=robot)  # its ray faces forward: the scan is cast
    # from the same point in the base's axes
    assert "rangefinder 'front'" in world.geometry_sources()["lidar"]
    assert world.geometry.laser_offset_x == pytest.approx(0.08)


def test_a_turned_sensor_site_is_refused(tmp_path: Path) -> None:
    robot = variant(
        tmp_path,
        '<body name="left_wheel_link"',
        '<site name="scanner" pos="0.08 0 0.1" euler="0 0 180"/>\n'
        '      <body name="left_wheel_link"',
    )
    with pytest.raises(SceneError, match=r"^robot\.lidar: site 'scanner' is turned against"):
        MujocoInterface("empty", robot=replace(robot, lidar=Mount(site="scanner")))


def test_given_values_override_derived_ones() -> None:
    world = MujocoInterface("empty", robot=pathfinder(wheel_radius=0.08, wheel_separation=0.31))
    assert world.geometry.wheel_radius == 0.08
    assert world.geometry.wheel_separation == 0.31
    assert world.geometry_sources()["wheel_radius"] == "robot.wheel_radius (given)"


@pytest.mark.parametrize(
    ("robot", "message"),
    [
        (
            pathfinder(left_wheel="wheel_l"),
            r"^robot\.left_wheel: no joint 'wheel_l' in pathfinder\.xml "
            r"\(hinge joints: left_wheel_hinge, right_wheel_hinge\)$",
        ),
        (
            pathfinder(base="base_footprint"),
            r"^robot\.base: no body 'base_footprint' in pathfinder\.xml \(bodies: "
            r"chassis_link, left_wheel_link, right_wheel_link\)$",
        ),
        (
            pathfinder(lidar=Mount(site="laser")),
            r"^robot\.lidar: no site 'laser' in pathfinder\.xml \(sites: none named\)$",
        ),
        (
            pathfinder(left_wheel="right_wheel_hinge", right_wheel="left_wheel_hinge"),
            r"^robot\.left_wheel: joint 'right_wheel_hinge' is at y = -0\.150 m, not left of "
            r"'left_wheel_hinge' .*: swap robot\.left_wheel and robot\.right_wheel$",
        ),
        (
            pathfinder(right_wheel="left_wheel_hinge"),
            r"^robot\.right_wheel: names the same joint as robot\.left_wheel "
            r"\('left_wheel_hinge'\); name the right wheel's joint$",
        ),
        (
            pathfinder(model=PATHFINDER / "nope.xml"),
            r"^robot\.model: 'nope\.xml' is neither a built-in robot \(otonav, burger\) nor an "
            r"existing MJCF or URDF file$",
        ),
        (
            pathfinder(lidar=Mount(pos=(0.0, 0.05, 0.2))),
            r"^robot\.lidar: the lidar is 0\.050 m off the robot's centre line",
        ),
    ],
)
def test_bad_robot_descriptions_are_one_line_naming_the_key(
    robot: RobotDescription, message: str
) -> None:
    with pytest.raises(SceneError, match=message) as caught:
        MujocoInterface("empty", robot=robot)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        (
            '<geom name="left_tyre" class="pf_tyre"/>',
            '<geom name="left_tyre" class="pf_tyre" contype="0" conaffinity="0"/>',
            r"^robot\.left_wheel: joint 'left_wheel_hinge' moves body 'left_wheel_link', "
            r"which has no collision geom",
        ),
        (
            'pos="0 0.15 0" euler="-90 0 0"',
            'pos="0 0.15 0"',
            r"^robot\.left_wheel: joint 'left_wheel_hinge' turns about an axis that is not "
            r"the robot's left-right",
        ),
        (
            "</actuator>",
            '  <motor name="extra" joint="left_wheel_hinge"/>\n  </actuator>',
            r"^robot\.left_wheel: joint 'left_wheel_hinge' has 2 actuators "
            r"\(left_drive, extra\); give it one$",
        ),
    ],
    ids=["no-collision-geom", "wrong-axis", "two-actuators"],
)
def test_a_wheel_the_robot_cannot_drive_is_refused(
    tmp_path: Path, old: str, new: str, message: str
) -> None:
    with pytest.raises(SceneError, match=message):
        MujocoInterface("empty", robot=variant(tmp_path, old, new))


def test_a_urdf_whose_meshes_are_missing_names_the_model(tmp_path: Path) -> None:
    shutil.copy(PATHFINDER / "pathfinder.urdf", tmp_path / "pathfinder.urdf")
    robot = urdf(model=str(tmp_path / "pathfinder.urdf"))
    with pytest.raises(SceneError, match=r"^robot\.model: pathfinder\.urdf does not compile: "
                       r".*chassis\.stl"):  # fmt: skip
        MujocoInterface("empty", robot=robot)


def test_the_default_robot_attached_moves_as_the_old_included_one(tmp_path: Path) -> None:
    """A scene that includes robot.xml (as scenes did) and the built-in scene with the
    robot attached are the same world, step for step."""
    old_world = MujocoInterface(old_scene(tmp_path, "obstacles"))
    new_world = MujocoInterface("obstacles")
    for world in (old_world, new_world):
        world.write(WheelSetpoint(4.0, 6.0))
        world.advance(1500)
    assert old_world.ground_truth() == new_world.ground_truth()
    assert old_world.read_wheels() == new_world.read_wheels()
    assert np.array_equal(old_world.read_scan().ranges, new_world.read_scan().ranges)
    assert math.isfinite(new_world.ground_truth().x)


def test_an_old_scene_with_our_robot_in_it_refuses_another_robot(tmp_path: Path) -> None:
    scene = old_scene(tmp_path, "empty")
    MujocoInterface(scene)  # its own robot: used as it is
    with pytest.raises(SceneError, match=r"old\.xml includes otonav's robot \(body 'chassis'\); "
                       r"remove its <include"):  # fmt: skip
        MujocoInterface(scene, robot=builtin_robot("burger"))


TB3 = Path(__file__).resolve().parents[2] / "examples" / "robots" / "turtlebot3_burger.xml"


def turtlebot3(**changes: object) -> RobotDescription:
    """ROBOTIS's Burger as vendors write it (examples/robots): base_footprint above
    base_link, a box caster on its own fixed link, the lidar inside its housing."""
    values: dict[str, object] = {
        "model": str(TB3),
        "label": TB3.name,
        "base": "base_footprint",
        "left_wheel": "wheel_left_joint",
        "right_wheel": "wheel_right_joint",
        "lidar": Mount(body="base_scan", pos=(0.0, 0.0, 0.0)),
    }
    values.update(changes)
    return RobotDescription(**values)  # type: ignore[arg-type]


@pytest.mark.parametrize("base", ["base_footprint", "base_link"])
def test_a_vendor_model_runs_as_written_whichever_base_frame_is_named(base: str) -> None:
    world = MujocoInterface("empty", robot=turtlebot3(base=base))
    sources = world.geometry_sources()
    assert sources["base"] == "body 'base_footprint', free joint added by otonav"
    assert sources["casters"] == (
        "made frictionless by otonav: #3 of body 'caster_back_link' (condim 3, priority 0)"
    )
    height = {"base_footprint": 0.0, "base_link": 0.010}[base]
    assert world.geometry.base_height == pytest.approx(height, abs=1e-3)
    assert world.geometry.laser_offset_z == pytest.approx(0.182 - height, abs=1e-3)
    ranges = world.read_scan().ranges
    assert float(ranges[np.isfinite(ranges)].min()) > 4.0  # the housing is not seen
    drive(world, speed=0.19 / 0.033, seconds=2.0)
    truth = world.ground_truth()
    assert truth.x > 0.25  # weak servos: ~0.16 of 0.19 m/s asked, but it rolls
    assert abs(truth.pitch) < 0.02


def test_a_condim_1_caster_without_priority_is_made_frictionless(tmp_path: Path) -> None:
    assets = Path(MujocoInterface("empty")._label).parent
    text = (assets / "robots" / "burger.xml").read_text()
    old = 'condim="1" priority="1"'
    assert old in text
    path = tmp_path / "burger.xml"
    path.write_text(text.replace(old, 'condim="1"'))
    robot = replace(builtin_robot("burger"), model=str(path), label=path.name)
    world = MujocoInterface("empty", robot=robot)
    assert world.geometry_sources()["casters"] == (
        "made frictionless by otonav: 'caster' (condim 1, priority 0)"
    )
    drive(world, speed=0.2 / 0.033, seconds=2.0)
    assert world.ground_truth().x > 0.3


def urdf_variant(tmp_path: Path, name: str, old: str, new: str) -> RobotDescription:
    shutil.copytree(PATHFINDER / "meshes", tmp_path / "meshes", dirs_exist_ok=True)
    text = (PATHFINDER / "pathfinder.urdf").read_text()
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new))
    return urdf(model=str(path), label=name)


def test_a_urdf_using_xacro_is_refused_with_the_command_that_expands_it(tmp_path: Path) -> None:
    """MuJoCo reads a xacro file without its macros (issue 41 case 14: the caster gone)."""
    robot = urdf_variant(
        tmp_path,
        "pathfinder.urdf.xacro",
        '<robot name="pathfinder">',
        '<robot name="pathfinder" xmlns:xacro="http://ros.org/wiki/xacro">\n'
        '  <xacro:include filename="caster.xacro"/>',
    )
    with pytest.raises(SceneError) as caught:
        MujocoInterface("empty", robot=robot)
    assert str(caught.value) == (
        "robot.model: pathfinder.urdf.xacro uses xacro (<xacro:include>), which otonav does "
        "not expand: expand it first (xacro pathfinder.urdf.xacro > pathfinder.urdf) and name "
        "the result"
    )


def test_a_plain_urdf_that_declares_the_xacro_namespace_is_read(tmp_path: Path) -> None:
    """ROBOTIS's expanded turtlebot3_burger.urdf declares xmlns:xacro and keeps a
    commented-out include: no xacro left in it, so it loads."""
    robot = urdf_variant(
        tmp_path,
        "expanded.urdf",
        '<robot name="pathfinder">',
        '<robot name="pathfinder" xmlns:xacro="http://ros.org/wiki/xacro">\n'
        '  <!-- <xacro:include filename="caster.xacro"/> -->',
    )
    assert MujocoInterface("empty", robot=robot).geometry.wheel_radius > 0.07


def test_the_robot_identified_in_sim_time_reaches_what_its_servos_allow() -> None:
    """ADR 0066: kv 0.1 servos with 0.1 N m of friction loss fall short of the asked
    speed by a constant, their deadband; otonav's own servos reach it. The world is not
    touched."""
    weak = MujocoInterface("obstacles", robot=turtlebot3())
    before = weak.ground_truth()
    reach = weak.reach(0.22, 2.84)
    assert 0.15 < reach.v < 0.2  # ~85 % of 0.22
    assert reach.omega < 0.8 * 2.84
    assert reach.accel > 0.5
    assert reach.deadband == pytest.approx(1.0, abs=0.15)  # frictionloss / kv, rad/s
    assert weak.ground_truth() == before
    assert weak.ticks == 0
    assert weak.geometry_sources()["reach"].startswith("identified in 8.75 s of sim: 0.187 of")
    strong = MujocoInterface("empty", robot=builtin_robot("burger")).reach(0.22, 2.84)
    assert strong.v == pytest.approx(0.22, rel=0.02)
    assert strong.omega == pytest.approx(2.84, rel=0.05)
    assert strong.deadband < 0.05


@pytest.mark.parametrize(
    ("model", "base", "lidar"),
    [
        ("skeleton.xml", "base_link", None),
        ("skeleton.urdf", "base_footprint", Mount(body="laser", pos=(0.0, 0.0, 0.0))),
    ],
)
def test_the_docs_skeletons_drive_as_written(model: str, base: str, lidar: Mount | None) -> None:
    """docs/how-to/own-robot.md's skeletons: names only, everything else otonav's."""
    path = TB3.parent / model
    robot = RobotDescription(
        model=str(path),
        label=model,
        base=base,
        left_wheel="left_wheel_joint",
        right_wheel="right_wheel_joint",
        lidar=lidar,
    )
    world = MujocoInterface("empty", robot=robot)
    assert world.geometry.wheel_radius == pytest.approx(0.05)
    assert world.geometry.wheel_separation == pytest.approx(0.26)
    assert "frictionless" in world.geometry_sources()["casters"]
    drive(world, speed=4.0, seconds=2.0)
    truth = world.ground_truth()
    assert truth.x > 0.3
    assert abs(truth.pitch) < 0.03


@pytest.mark.parametrize(("height", "warned"), [(0.3, False), (0.6, True)])
def test_a_lidar_over_the_tallest_obstacle_is_warned_of(height: float, warned: bool) -> None:
    """The courses' boxes are 0.5 m tall: a lidar at 0.6 m sees none of them."""
    world = MujocoInterface(
        "empty",
        robot=pathfinder(lidar=Mount(pos=(0.0, 0.0, height))),
        extra_obstacles=[BoxObstacle(2.0, 0.0, 0.2, 0.2)],
    )
    assert world.tallest_obstacle() == pytest.approx(0.5)
    warnings = lidar_over_obstacles(world)
    assert bool(warnings) == warned
    if warned:
        assert warnings[0].startswith("warning: the lidar is 0.")
        assert warnings[0].endswith(
            "over the tallest obstacle (0.50 m): it sees none of them; mount it lower (robot.lidar)"
        )


def test_a_wheel_cylinder_turned_in_radians_under_degrees_is_refused(tmp_path: Path) -> None:
    """MJCF angles are degrees by default: euler="1.5708 0 0" leaves the wheel a flat
    disk the robot sits on (it never moves): one line naming the key and the fix."""
    text = (TB3.parent / "skeleton.xml").read_text()
    assert 'euler="90 0 0"' in text
    path = tmp_path / "radians.xml"
    path.write_text(text.replace('euler="90 0 0"', 'euler="1.5708 0 0"'))
    robot = RobotDescription(
        model=str(path),
        label=path.name,
        base="base_link",
        left_wheel="left_wheel_joint",
        right_wheel="right_wheel_joint",
    )
    with pytest.raises(SceneError) as caught:
        MujocoInterface("empty", robot=robot)
    assert str(caught.value) == (
        "robot.left_wheel: the wheel's geom of body 'left_wheel' is a cylinder whose axis is "
        "not the joint's axle, so it cannot roll: turn it (MJCF angles are degrees unless "
        '<compiler angle="radian"/>)'
    )


def _tyre_stl(path: Path, radius_mm: float, width_mm: float, sides: int = 48) -> None:
    """A binary STL of a round tyre (a prism about z), in millimetres."""
    ring = [
        (
            radius_mm * math.cos(2 * math.pi * k / sides),
            radius_mm * math.sin(2 * math.pi * k / sides),
        )
        for k in range(sides)
    ]
    h = width_mm / 2
    triangles = []
    for k in range(sides):
        (x0, y0), (x1, y1) = ring[k], ring[(k + 1) % sides]
        triangles += [
            ((0, 0, -h), (x1, y1, -h), (x0, y0, -h)),
            ((0, 0, h), (x0, y0, h), (x1, y1, h)),
            ((x0, y0, -h), (x1, y1, -h), (x1, y1, h)),
            ((x0, y0, -h), (x1, y1, h), (x0, y0, h)),
        ]
    with path.open("wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(triangles)))
        for triangle in triangles:
            f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            for vertex in triangle:
                f.write(struct.pack("<3f", *vertex))
            f.write(b"\0\0")


def test_a_mesh_tyre_turned_about_its_axle_rests_on_the_floor_with_its_caster(
    tmp_path: Path,
) -> None:
    """A mesh's bounding box turns with the mesh (ROBOTIS's tyres: their principal
    axes): its corners reached 14 mm under the floor, lifted the robot and hid the
    caster. The mesh's own vertices bound it."""
    _tyre_stl(tmp_path / "tyre.stl", 50.0, 30.0)
    text = (TB3.parent / "skeleton.xml").read_text()
    text = text.replace(
        '<mujoco model="skeleton">',
        '<mujoco model="skeleton">\n  <asset><mesh name="tyre" file="tyre.stl" '
        'scale="0.001 0.001 0.001"/></asset>',
    )
    old = '<geom type="cylinder" size="0.05 0.015" euler="90 0 0" mass="0.2"/>'
    assert text.count(old) == 2
    text = text.replace(old, '<geom type="mesh" mesh="tyre" euler="90 0 45" mass="0.2"/>')
    (tmp_path / "meshed.xml").write_text(text)
    robot = RobotDescription(
        model=str(tmp_path / "meshed.xml"),
        label="meshed.xml",
        base="base_link",
        left_wheel="left_wheel_joint",
        right_wheel="right_wheel_joint",
    )
    world = MujocoInterface("empty", robot=robot)
    assert world.geometry.wheel_radius == pytest.approx(0.05, abs=1e-4)
    assert world.geometry.base_height == pytest.approx(0.05, abs=1e-3)  # not lifted
    assert "frictionless" in world.geometry_sources()["casters"]


def test_the_speed_asked_is_capped_by_the_wheels_control_range() -> None:
    """ROBOTIS's servos take at most 6.67 rad/s: asked 0.4 m/s, the robot is asked
    0.22, and what it reaches is judged against that (ADR 0066)."""
    world = MujocoInterface("empty", robot=turtlebot3())
    reach = world.reach(0.4, 3.0)
    assert reach.asked_v == pytest.approx(6.67 * 0.033)
    assert reach.asked_omega == pytest.approx(6.67 * 0.033 / 0.08)
    assert 0.8 < reach.v / reach.asked_v < 0.9
    assert world.geometry_sources()["reach"].endswith("(the wheels' control range: 6.67 rad/s)")


def test_joint_states_report_a_mirrored_joint_in_its_own_sign() -> None:
    """Pathfinder's right hinge turns about -y: rolling forward it turns negative, and
    robot_state_publisher (and MuJoCo's qpos) expect that sign on /joint_states."""
    world = MujocoInterface("empty", robot=pathfinder())
    assert world.geometry.wheel_signs == (1.0, -1.0)
    right_dof = world._wheel_qvel[1]
    states: list[JointState] = []

    async def main() -> None:
        async with System([Bridge(world)]) as system:
            sub = system.subscribe(topics.JOINT_STATES, JointState, topics.SENSOR_QOS)
            wheels = system.publisher(topics.WHEEL_CMD, WheelCommand, topics.COMMAND_QOS)
            await wheels.publish(WheelCommand(left=3.0, right=3.0))
            with anyio.move_on_after(1.0):
                async for message in sub:
                    states.append(message)

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(world, wall_ceiling=30)})
    assert world.ground_truth().x > 0.1  # it rolled forward
    last = states[-1]
    assert last.velocity[0] == pytest.approx(3.0, rel=0.05)
    assert last.velocity[1] == pytest.approx(-3.0, rel=0.05)
    assert last.position[0] > 1.0
    assert last.position[1] < -1.0
    assert math.copysign(1.0, world._data.qvel[right_dof]) == -1.0  # the model's own sign


def test_a_zipped_package_copies_the_whole_assets_tree_for_its_scenes_and_robots(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Installed as a zip, the assets are no real files: MuJoCo gets a copy of the whole
    tree, so the Burger in ``robots/`` loads as it does from a folder."""
    shipped = description.assets_dir()
    archive = tmp_path / "otonav.zip"
    with zipfile.ZipFile(archive, "w") as z:
        for file in shipped.rglob("*"):
            if file.is_file():
                z.write(file, f"otonav/hal/assets/{file.relative_to(shipped).as_posix()}")
    monkeypatch.setattr(
        description, "_shipped", lambda: zipfile.Path(archive, "otonav/hal/assets/")
    )
    monkeypatch.setattr(description, "_copy", [])
    with scene_path("obstacles") as path:
        assert not path.is_relative_to(shipped)
        copied = path.parent / "robots" / "burger.xml"
        assert copied.read_bytes() == (shipped / "robots" / "burger.xml").read_bytes()
    burger = builtin_robot("burger")
    assert Path(burger.model) == copied
    world = MujocoInterface("obstacles", robot=burger)
    assert world.geometry.wheel_radius == pytest.approx(0.033)
    assert world.geometry.wheel_joints == ("wheel_left_joint", "wheel_right_joint")
