"""The stack config's optional sections as actors: the Foxglove live view (``foxglove``)
and the ROS 2 bridge (``ros2``), made, wired and closed in one place (issue 36).

``otonav run``, ``open_live_stack`` and ``running_stack`` each ask :func:`open_extras`
for them: the same config gives the same extras whichever way the stack starts. Each
part imports its optional dependency only when its section is enabled.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from otonav.errors import UsageError
from otonav.runtime import Actor, System
from otonav.stack import StackConfig
from otonav.stack._robot import robot_frames

if TYPE_CHECKING:
    from otonav.foxglove import FoxgloveServer, LiveView
    from otonav.ros2 import Ros2Bridge
    from otonav.stack._live_parameters import ActorParameters

__all__ = ("Extras", "ExtrasError", "open_extras")


class ExtrasError(UsageError):
    """A section cannot start (a port taken, a missing extra, a bad domain): one line
    naming the section and what would work."""


@dataclass(slots=True)
class Extras:
    """The actors the config's optional sections add, and what they need once the
    system is wired (:meth:`serve_parameters`) and when the run is over (:meth:`close`)."""

    view: LiveView | None = None
    ros2: Ros2Bridge | None = None
    _closed: bool = field(default=False, repr=False)

    @property
    def foxglove(self) -> FoxgloveServer | None:
        """The Foxglove server (``foxglove.enabled``), else None."""
        return None if self.view is None else self.view.server

    @property
    def actors(self) -> tuple[Actor, ...]:
        """The live view and the bridge, in that order (each only when enabled)."""
        return tuple(a for a in (self.view, self.ros2) if a is not None)

    def serve_parameters(self, system: System) -> ActorParameters | None:
        """Serve the parameters of ``system``'s actors to Foxglove clients and as ROS 2
        parameter services (each when enabled); the table Foxglove serves, else None."""
        actors: Iterable[Actor] = [system.actor(a.name) for a in system.graph().actors]
        table = None
        if self.view is not None:
            table = self.view.serve_parameters(actors)
        if self.ros2 is not None:
            self.ros2.serve_parameters(actors)
        return table

    def close(self) -> None:
        """Stop the server and leave the DDS domain (idempotent; each even if the other
        raised)."""
        if self._closed:
            return
        self._closed = True
        try:
            if self.view is not None:
                self.view.server.close()
        finally:
            if self.ros2 is not None:
                self.ros2.close()


def open_extras(config: StackConfig) -> Extras:
    """The extras ``config`` enables, started (the Foxglove server bound, the bridge on
    its DDS domain); :class:`ExtrasError` if one cannot start (what started is closed)."""
    extras = Extras()
    try:
        if config.foxglove.enabled:
            extras.view = _live_view(config)
        if config.ros2.enabled:
            from otonav.ros2 import Ros2Bridge, Ros2Error

            try:
                extras.ros2 = Ros2Bridge(config.ros2, base_frame=robot_frames(config.robot).base)
            except Ros2Error as exc:
                raise ExtrasError(str(exc)) from None
    except BaseException:
        extras.close()
        raise
    return extras


def _live_view(config: StackConfig) -> LiveView:
    from otonav.foxglove import LiveView, LiveViewError

    try:
        from otonav.foxglove import FoxgloveServer

        return LiveView(FoxgloveServer(config.foxglove))
    except LiveViewError as exc:
        raise ExtrasError(str(exc)) from None
