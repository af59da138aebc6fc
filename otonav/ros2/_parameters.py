"""The actors' parameters as ROS 2 parameter services, through rclpy (docs/adr/0065).

ROS 2's parameter services (``list_parameters``, ``describe_parameters``,
``get_parameters``, ``set_parameters``, ...) are request/reply over DDS, and a Fast DDS
client (ROS 2's default rmw) matches a reply to its request by an identity that travels
in the RTPS inline QoS, which a plain Cyclone participant can neither read nor write. So
the services are served by rclpy itself, in this process, when it is importable (a
sourced ROS 2, or its wheels from PyPI): one rclpy node per actor, named as the actor,
with the actor's parameters declared as :class:`~otonav.stack._live_parameters.
ActorParameters` lists them (``params.dwa.max_v`` on ``/nav``). The runtime-safe ones are
settable; the others are declared read-only. A set is validated and applied on the run's
loop (as the Foxglove panel's are): a refused value is an unsuccessful
``SetParametersResult`` with the reason, and rclpy publishes the change on
``/parameter_events``. Without rclpy nothing here is imported.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import importlib.util
import threading
from collections.abc import Callable, Iterable
from typing import Any

from otonav.runtime import Actor
from otonav.stack._live_parameters import ActorParameters, ParameterError

__all__ = ("ParameterNodes", "rclpy_available")

_APPLY_TIMEOUT = 5.0
"""Wall seconds a set waits for the run's loop (a run that has ended never answers)."""


def rclpy_available() -> bool:
    """Whether rclpy can be imported here (without importing it)."""
    return importlib.util.find_spec("rclpy") is not None


class ParameterNodes:
    """rclpy nodes serving the parameters of ``actors`` on DDS domain ``domain_id``,
    applying sets on ``loop``; an rclpy executor spins them in a thread of its own."""

    def __init__(
        self,
        actors: Iterable[Actor],
        *,
        domain_id: int,
        loop: asyncio.AbstractEventLoop,
        node_name: Any,
        on_change: Callable[[str, str, Any], None] | None = None,
        on_refused: Callable[[str], None] | None = None,
    ) -> None:
        import rclpy
        from rcl_interfaces.msg import ParameterDescriptor
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node

        self._loop = loop
        self._on_change = on_change
        """Called on the loop with (actor, key, new value) after each set it took."""
        self._on_refused = on_refused
        """Called on the loop with why, after each set it refused."""
        self._table = ActorParameters(actors)
        self._context = Context()
        rclpy.init(context=self._context, domain_id=domain_id)
        self._executor = SingleThreadedExecutor(context=self._context)
        self.nodes: dict[str, Any] = {}
        grouped: dict[str, list[tuple[str, Any]]] = {}
        for name, value in self._table.values().items():
            actor, _, key = name.partition(".")
            grouped.setdefault(actor, []).append((key, value))
        for actor, entries in grouped.items():
            node = Node(node_name(actor), context=self._context)
            for key, value in entries:
                settable = self._table.settable(f"{actor}.{key}")
                descriptor = ParameterDescriptor(
                    name=key,
                    read_only=not settable,
                    description="settable while the robot runs"
                    if settable
                    else "read while the actor was built: read-only",
                )
                node.declare_parameter(key, value, descriptor)
            node.add_on_set_parameters_callback(self._on_set_for(actor))
            self._executor.add_node(node)
            self.nodes[actor] = node
        self._thread = threading.Thread(
            target=self._spin, name="otonav-ros2-parameters", daemon=True
        )
        self._thread.start()

    def _spin(self) -> None:
        from rclpy.executors import ExternalShutdownException

        with contextlib.suppress(ExternalShutdownException):
            self._executor.spin()

    def _on_set_for(self, actor: str) -> Any:
        from rcl_interfaces.msg import SetParametersResult

        def on_set(parameters: list[Any]) -> Any:
            for parameter in parameters:
                name = f"{actor}.{parameter.name}"
                problem = self._apply(name, parameter.value)
                if problem is not None:
                    return SetParametersResult(successful=False, reason=problem)
            return SetParametersResult(successful=True)

        return on_set

    def _apply(self, name: str, value: Any) -> str | None:
        """Set ``name`` on the run's loop; None, or why it was refused."""

        async def apply() -> str | None:
            try:
                _old, new = self._table.set(name, value)
            except ParameterError as exc:
                if self._on_refused is not None:
                    self._on_refused(str(exc))
                return str(exc)
            if self._on_change is not None:
                actor, _, key = name.partition(".")
                self._on_change(actor, key, new)
            return None

        try:
            future = asyncio.run_coroutine_threadsafe(apply(), self._loop)
        except RuntimeError:  # the loop has closed: the run is over
            return f"parameter {name!r}: the run has ended"
        try:
            return future.result(timeout=_APPLY_TIMEOUT)
        except (concurrent.futures.TimeoutError, concurrent.futures.CancelledError):
            future.cancel()
            return f"parameter {name!r}: the run did not take it (has it ended?)"

    def close(self) -> None:
        """Stop serving: the nodes leave the graph (idempotent)."""
        if not self._context.ok():
            return
        self._executor.shutdown(timeout_sec=2.0)
        for node in self.nodes.values():
            node.destroy_node()
        self._context.try_shutdown()
        self._thread.join(timeout=2.0)
