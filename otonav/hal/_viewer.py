"""The MuJoCo viewer's window, without MuJoCo: is there a display for it, and the handle
of an open one. (``otonav.hal.mujoco`` launches it; nothing here imports MuJoCo.)

``mujoco.viewer.launch_passive`` with no usable display does not raise: GLFW fails to
initialise in the viewer's thread and the whole process exits with code 1 after
"could not initialize GLFW". So before launching, :func:`check_display` looks for a
display in the environment and then initialises GLFW in a short-lived child process
(the same ``glfw`` package and environment the viewer uses): if that fails, the viewer
would have killed us, and :class:`NoDisplayError` says so in one line instead.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from typing import Any, Final

from otonav.errors import UsageError

__all__ = [
    "NO_DISPLAY_FIX",
    "NoDisplayError",
    "ViewerHandle",
    "check_display",
    "launch_viewer",
]

NO_DISPLAY_FIX: Final = "run without --gui, or under xvfb-run"
# The tracking camera: m from the robot, degrees looking down, heading (MuJoCo's).
_DISTANCE, _ELEVATION, _AZIMUTH = 4.0, -40.0, 135.0
_VIEWER_THREAD: Final = "_launch_internal"  # target of launch_passive's thread

# Initialise GLFW as the viewer would; on failure print GLFW's last error, exit 3.
_PROBE: Final = """
import sys, warnings
warnings.simplefilter("ignore")
import glfw
errors = []
glfw.set_error_callback(lambda code, text: errors.append(text))
if glfw.init():
    glfw.terminate()
    sys.exit(0)
last = errors[-1] if errors else b"glfw.init() failed"
sys.stderr.write(last.decode("utf-8", "replace") if isinstance(last, bytes) else str(last))
sys.exit(3)
"""


class NoDisplayError(UsageError, RuntimeError):
    """No display the viewer can open; the message is one line: what and the fix."""


def _display_name() -> str | None:
    for var in ("DISPLAY", "WAYLAND_DISPLAY"):
        value = os.environ.get(var, "")
        if value:
            return f"{var}={value}"
    return None


def check_display(timeout: float = 10.0) -> None:
    """Raise :class:`NoDisplayError` unless GLFW can open the display in the environment.

    Costs one short child process (about 0.1 s).
    """
    name = _display_name()
    if name is None:
        raise NoDisplayError(
            f"no display for the viewer: neither DISPLAY nor WAYLAND_DISPLAY is set; "
            f"{NO_DISPLAY_FIX}"
        )
    try:
        probe = subprocess.run(
            [sys.executable, "-c", _PROBE],
            capture_output=True,
            text=True,
            timeout=timeout,
            check=False,
        )
    except subprocess.TimeoutExpired:
        raise NoDisplayError(
            f"no display for the viewer: opening {name} did not answer within {timeout:g} s; "
            f"{NO_DISPLAY_FIX}"
        ) from None
    if probe.returncode != 0:
        lines = [line.strip() for line in probe.stderr.splitlines() if line.strip()]
        why = lines[-1] if lines else f"GLFW probe exited with code {probe.returncode}"
        raise NoDisplayError(
            f"no display for the viewer: cannot open {name} ({why}); {NO_DISPLAY_FIX}"
        )


class ViewerHandle:
    """MuJoCo's passive viewer on a live world (``MujocoInterface.open_viewer``).

    Single-threaded use from the thread that steps the world: :meth:`sync` after the
    world advanced (at most ~60 Hz wall: each sync copies the state for drawing),
    :meth:`is_running` to notice the user closed the window, :meth:`close` when done
    (also as a context manager). ``start_time_s`` is how long the window took to open.
    """

    def __init__(
        self,
        sync_world: Callable[[], None],
        handle: Any,
        threads: Sequence[threading.Thread],
        start_time_s: float,
    ) -> None:
        self._sync_world = sync_world
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
        self._sync_world()  # poses of the last step, as reading does (no physics change)
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


def launch_viewer(
    viewer: Any,
    model: Any,
    data: Any,
    *,
    sync_world: Callable[[], None],
    tracking: tuple[int, int] | None,
) -> ViewerHandle:
    """Open ``viewer.launch_passive`` (the ``mujoco.viewer`` module, handed in by
    ``otonav.hal.mujoco``: this module never imports MuJoCo) on ``model``/``data`` with
    no side panels. ``tracking``: (MuJoCo's tracking camera type, the body to follow),
    seen from behind-left and above, ~4 m away; None: MuJoCo's default free camera."""
    started = time.perf_counter()
    before = set(threading.enumerate())
    handle = viewer.launch_passive(model, data, show_left_ui=False, show_right_ui=False)
    if tracking is not None:
        with handle.lock():
            handle.cam.type, handle.cam.trackbodyid = tracking
            handle.cam.distance, handle.cam.elevation = _DISTANCE, _ELEVATION
            handle.cam.azimuth = _AZIMUTH
    elapsed = time.perf_counter() - started
    new = [t for t in threading.enumerate() if t not in before]
    threads = [t for t in new if _VIEWER_THREAD in t.name] or new
    return ViewerHandle(sync_world, handle, threads, elapsed)
