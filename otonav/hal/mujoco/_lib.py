"""The one module that imports :mod:`mujoco` (ADR 0056); the package's other modules
take the module object from here, so the MUJOCO_GL choice below is made once, before
anything of MuJoCo's loads."""

from __future__ import annotations

import os
from typing import Any, Final

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

__all__ = ["mujoco", "viewer_module"]


def viewer_module() -> Any:
    """``mujoco.viewer``, imported on first use: it loads GLFW (only when a window opens)."""
    import mujoco.viewer

    return mujoco.viewer
