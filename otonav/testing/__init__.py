"""Testing tools for otonav users.

- The pytest plugin (the ``otonav`` pytest entry point): ``@pytest.mark.sim`` runs an
  async test on a virtual-time loop.
- :func:`running_stack`: the robot stack up for the body of an ``async with``.
- :func:`replay`: re-simulate an actor against a recording; its divergences.
"""

from otonav.testing._replay import ReplayCrashError, replay
from otonav.testing._stack import running_stack

__all__ = ("ReplayCrashError", "replay", "running_stack")
