"""What a recording says about its world: an MCAP metadata record, ``otonav.world``,
written by :class:`~otonav.stack._session.StackSession` when the recording opens (so a
cut-off file keeps it), holding every obstacle and wall box and the robot's geometry.
``otonav plot`` draws the boxes from the recording alone; ``otonav replay`` builds the
actors for the recorded robot without compiling its MJCF (ADR 0036)."""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import asdict

from otonav.hal import BoxObstacle, RobotGeometry, RobotHardwareInterface
from otonav.hal._types import Reach

WORLD_METADATA = "otonav.world"
"""The metadata record's name."""


def _boxes(boxes: tuple[BoxObstacle, ...]) -> str:
    return json.dumps([[b.x, b.y, b.half_x, b.half_y, b.yaw] for b in boxes])


def world_metadata(hal: RobotHardwareInterface) -> dict[str, str]:
    """The record for ``hal``'s world: ``obstacles`` and ``walls`` as JSON lists of
    ``[x, y, half_x, half_y, yaw]`` (m, m, m, m, rad; world frame), and ``robot``, the
    :class:`~otonav.hal.RobotGeometry` the actors were built for, as a JSON object of its
    fields (floats as Python writes them: each reads back as the same double)."""
    g = hal.geometry
    robot = {
        "wheel_radius": g.wheel_radius,
        "wheel_separation": g.wheel_separation,
        "laser_offset_x": g.laser_offset_x,
        "laser_offset_z": g.laser_offset_z,
        "base_height": g.base_height,
        "imu_offset": list(g.imu_offset),
        "footprint": [list(corner) for corner in g.footprint],
    }
    record = {
        "obstacles": _boxes(hal.obstacles()),
        "walls": _boxes(hal.walls()),
        "robot": json.dumps(robot),
    }
    identified = hal.identified()
    if identified is not None:  # what the actors were built for (ADR 0066)
        (v, omega), reach = identified
        record["reach"] = json.dumps({"request": [v, omega], **asdict(reach)})
    sources = hal.geometry_sources()
    if sources:  # where each value came from: derived from the model, or given
        record["robot_sources"] = json.dumps(sources, sort_keys=True)
    return record


def geometry_from_metadata(record: Mapping[str, str]) -> RobotGeometry | None:
    """The robot geometry of a :func:`world_metadata` record (None: a recording made
    before it was written, or one whose entry does not read as a geometry)."""
    text = record.get("robot")
    if text is None:
        return None
    try:
        robot = json.loads(text)
        x, y, z = (float(v) for v in robot["imu_offset"])
        return RobotGeometry(
            wheel_radius=float(robot["wheel_radius"]),
            wheel_separation=float(robot["wheel_separation"]),
            laser_offset_x=float(robot["laser_offset_x"]),
            laser_offset_z=float(robot["laser_offset_z"]),
            base_height=float(robot["base_height"]),
            imu_offset=(x, y, z),
            footprint=tuple((float(cx), float(cy)) for cx, cy in robot["footprint"]),
        )
    except (ValueError, TypeError, KeyError):
        return None


def reach_from_metadata(
    record: Mapping[str, str],
) -> tuple[tuple[float, float], Reach] | None:
    """The identification a :func:`world_metadata` record kept (None: none kept)."""
    text = record.get("reach")
    if text is None:
        return None
    try:
        values = json.loads(text)
        v, omega = (float(x) for x in values.pop("request"))
        return (v, omega), Reach(**{k: float(x) for k, x in values.items()})
    except (ValueError, TypeError, KeyError):
        return None


def boxes_from_metadata(record: Mapping[str, str]) -> tuple[BoxObstacle, ...]:
    """The obstacle and wall boxes of a :func:`world_metadata` record."""
    return tuple(
        BoxObstacle(float(x), float(y), float(hx), float(hy), float(yaw))
        for key in ("obstacles", "walls")
        for x, y, hx, hy, yaw in json.loads(record.get(key, "[]"))
    )
