"""Scenes: the built-in MJCF worlds and user files, parsed and compiled, each failure a
:class:`SceneError` naming the file."""

from __future__ import annotations

import math
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Final

from otonav.errors import UsageError
from otonav.hal._description import assets_dir
from otonav.hal._types import BoxObstacle
from otonav.hal.mujoco._lib import mujoco

__all__ = ["SceneError", "compile_scene", "scene_names", "scene_path"]

_ROBOT_FRAGMENT: Final = "robot.xml"
_OBSTACLE_HEIGHT: Final = 0.5  # m, height of boxes added through extra_obstacles


def _one_line(exc: BaseException) -> str:
    """MuJoCo's messages span lines (``Element 'geom', line 1``): one line for users."""
    return " ".join(str(exc).split())


class SceneError(UsageError):
    """An MJCF scene that cannot be found, parsed, compiled or used as an otonav world."""


# -- scenes ----------------------------------------------------------------------------


def scene_names() -> tuple[str, ...]:
    """Names of the built-in scenes (the MJCF files shipped in ``otonav/hal/assets``)."""
    names = (
        entry.name.removesuffix(".xml")
        for entry in assets_dir().iterdir()
        if entry.name.endswith(".xml") and entry.name != _ROBOT_FRAGMENT
    )
    return tuple(sorted(names))


@contextmanager
def scene_path(scene: str | os.PathLike[str]) -> Iterator[Path]:
    """Context manager yielding a real filesystem path for a scene name or MJCF path
    (a built-in scene's from :func:`~otonav.hal._description.assets_dir`, a real folder
    even when the package is zipped)."""
    if isinstance(scene, str) and scene in scene_names():
        yield assets_dir() / f"{scene}.xml"
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
