"""What every entry point shares above the stack.

- :func:`open_live_stack`: a stack held open on the running loop, in real time (a host
  service) or virtual time (a pytest test): subscribe, publish, goals, the graph; one
  teardown (:class:`LiveStack`). ``otonav.embed`` and ``otonav.testing.running_stack``
  are this function.
- :func:`open_extras`: the config's optional sections (``foxglove``, ``ros2``) as actors,
  wired in one place for the CLI, the embedding and pytest (:class:`Extras`).
"""

from otonav.engine._extras import Extras, ExtrasError, open_extras
from otonav.engine._live import HOST_QOS, LiveStack, LiveSubscription, open_live_stack

__all__ = (
    "HOST_QOS",
    "Extras",
    "ExtrasError",
    "LiveStack",
    "LiveSubscription",
    "open_extras",
    "open_live_stack",
)
