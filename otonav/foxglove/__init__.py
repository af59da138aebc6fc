"""The Foxglove live view: every topic served over the Foxglove WebSocket protocol.

:class:`LiveView` is the actor and :class:`FoxgloveServer` the server it feeds, made
from the stack config's ``foxglove`` section (``otonav run --foxglove``; the
``websockets`` package comes with the ``otonav[foxglove]`` extra, imported only when the
server is: without it, ``FoxgloveServer`` raises :class:`LiveViewError`).
"""

from typing import TYPE_CHECKING

from otonav.foxglove._errors import LiveViewError
from otonav.foxglove._view import LiveView

if TYPE_CHECKING:
    from otonav.foxglove._protocol import FoxgloveServer

__all__ = ("FoxgloveServer", "LiveView", "LiveViewError")


def __getattr__(name: str) -> object:
    if name != "FoxgloveServer":
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    try:
        from otonav.foxglove._protocol import FoxgloveServer
    except ImportError:
        raise LiveViewError(
            "--foxglove needs the foxglove extra: pip install 'otonav[foxglove]'"
        ) from None
    return FoxgloveServer
