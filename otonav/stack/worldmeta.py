"""What a recording says about its world: an MCAP metadata record, ``otonav.world``,
written by :class:`~otonav.stack.session.StackSession` when the recording opens (so a
cut-off file keeps it), holding every obstacle and wall box. ``otonav plot`` draws
them from the recording alone."""

from __future__ import annotations

import json
from collections.abc import Mapping

from otonav.hal import BoxObstacle, RobotHardwareInterface

WORLD_METADATA = "otonav.world"
"""The metadata record's name."""


def _boxes(boxes: tuple[BoxObstacle, ...]) -> str:
    return json.dumps([[b.x, b.y, b.half_x, b.half_y, b.yaw] for b in boxes])


def world_metadata(hal: RobotHardwareInterface) -> dict[str, str]:
    """The record for ``hal``'s world: ``obstacles`` and ``walls`` as JSON lists of
    ``[x, y, half_x, half_y, yaw]`` (m, m, m, m, rad; world frame)."""
    return {"obstacles": _boxes(hal.obstacles()), "walls": _boxes(hal.walls())}


def boxes_from_metadata(record: Mapping[str, str]) -> tuple[BoxObstacle, ...]:
    """The obstacle and wall boxes of a :func:`world_metadata` record."""
    return tuple(
        BoxObstacle(float(x), float(y), float(hx), float(hy), float(yaw))
        for key in ("obstacles", "walls")
        for x, y, hx, hy, yaw in json.loads(record.get(key, "[]"))
    )
