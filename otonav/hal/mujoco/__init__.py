"""The world simulated by MuJoCo: :class:`MujocoInterface`, the scenes it loads, the
robot description it builds the robot from.

This package holds every line of otonav that touches MuJoCo, and only its ``_lib``
module imports :mod:`mujoco` (an import-linter contract; ADR 0056). Its modules:

- ``scene``: built-in scenes and MJCF files, parsed and compiled (:class:`SceneError`);
- ``prepare``: the robot's description put into the scene's ``MjSpec``;
- ``derive``: the robot's geometry read from the compiled world;
- ``world``: :class:`MujocoInterface`, the HAL over the compiled world;
- ``lidar``: its lidar, and the static geoms the numpy caster takes (ADR 0057);
- ``shapes``: its static geoms as the judge measures them;
- ``static_sleep``: static geoms placed once, not at every step (ADR 0062).

The viewer's window (:class:`~otonav.hal._viewer.ViewerHandle`, the display check) lives
in :mod:`otonav.hal._viewer`, which does not import MuJoCo.
"""

from otonav.hal._viewer import NoDisplayError, ViewerHandle
from otonav.hal.mujoco._scene import SceneError, compile_scene, scene_names, scene_path
from otonav.hal.mujoco._world import MujocoInterface

__all__ = (
    "MujocoInterface",
    "NoDisplayError",
    "SceneError",
    "ViewerHandle",
    "compile_scene",
    "scene_names",
    "scene_path",
)
