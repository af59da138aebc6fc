"""Testing tools for otonav users.

- The pytest plugin (the ``otonav`` pytest entry point): ``@pytest.mark.sim`` runs an
  async test on a virtual-time loop.
- :func:`running_stack`: the robot stack up for the body of an ``async with``.
"""

from otonav.testing.stack import RunningStack, running_stack

__all__ = ("RunningStack", "running_stack")
