"""What the entry points share above the stack: the optional parts a stack config asks
for (its ``foxglove`` and ``ros2`` sections), wired in one place for the CLI, the
embedding and the pytest helper (:func:`open_extras`)."""

from otonav.engine.extras import Extras, ExtrasError, open_extras

__all__ = ("Extras", "ExtrasError", "open_extras")
