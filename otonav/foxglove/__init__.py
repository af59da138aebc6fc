"""The Foxglove live view: every topic served over the Foxglove WebSocket protocol.

:class:`LiveView` is the actor, :class:`FoxgloveServer` the server it feeds, and
:class:`LiveViewOptions` its settings (``otonav run --foxglove``; the ``websockets``
package comes with the ``otonav[foxglove]`` extra, imported only when a server starts).
"""

from otonav.foxglove.view import FoxgloveServer, LiveView, LiveViewError, LiveViewOptions

__all__ = ("FoxgloveServer", "LiveView", "LiveViewError", "LiveViewOptions")
