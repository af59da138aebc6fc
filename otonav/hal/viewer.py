"""Is there a display for the MuJoCo viewer? (No MuJoCo here: this is a plain check.)

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
from typing import Final

from otonav.errors import UsageError

__all__ = ["NO_DISPLAY_FIX", "NoDisplayError", "check_display"]

NO_DISPLAY_FIX: Final = "run without --gui, or under xvfb-run"

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
