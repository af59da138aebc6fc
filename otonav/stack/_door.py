"""The one door for messages from outside the process (issue 41, docs/adr/0074).

A message a Foxglove client publishes or a DDS participant writes is checked here, after
it decoded as its topic's type and before any actor sees it, with the bounds the config
uses: every number finite (the config's ``allow_inf_nan=False``), a pose within the
world a scenario can describe (:func:`otonav.nav.goal_problem`, the bound of a scenario's
goal), a velocity command within the fastest base the config allows (``base.max_v`` <=
10 m/s, ``base.max_omega`` <= 50 rad/s; slower commands are clamped by the base as
ROS 2's controllers clamp them). A refused message is counted and logged on /rosout
with its source by :class:`Refusals`; the bridge that took it answers where its protocol
can (a Foxglove status). Live parameter sets pass the same bounds
(:mod:`otonav.stack._live_parameters`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from otonav.limits import MAX_BASE_OMEGA, MAX_BASE_V
from otonav.msgs import Message, PoseStamped, Twist, Vector3
from otonav.nav import goal_problem

__all__ = ("LOGGED_PER_SOURCE", "Refusals", "refusal")

LOGGED_PER_SOURCE = 10
"""Refusals logged on /rosout per source, one line each; later ones are counted only
(one line says so), so a client that floods cannot fill the recording with them."""


def refusal(message: Message) -> str | None:
    """Why ``message`` from outside may not reach an actor, or None."""
    problem = _not_finite(message)
    if problem is None and isinstance(message, PoseStamped):
        position = message.pose.position
        problem = goal_problem(position.x, position.y)
    if problem is None and isinstance(message, Twist):
        problem = _beyond(message.linear, "linear", MAX_BASE_V, "m/s") or _beyond(
            message.angular, "angular", MAX_BASE_OMEGA, "rad/s"
        )
    return problem


def _beyond(vector: Vector3, name: str, bound: float, unit: str) -> str | None:
    """A velocity command beyond what any base may be configured to (``base.max_v``,
    ``base.max_omega``): 1e308 m/s on /cmd_vel_nav overflowed the safety layer."""
    for axis in "xyz":
        value = getattr(vector, axis)
        if abs(value) > bound:
            return f"{name}.{axis} = {value!r}: beyond the fastest base ({bound:g} {unit})"
    return None


class Refusals:
    """Counts what the door refused, by source, and logs each refusal once through
    ``log(text)`` (the first :data:`LOGGED_PER_SOURCE` of a source)."""

    def __init__(self, log: Callable[[str], None]) -> None:
        self._log = log
        self.by_source: dict[str, int] = {}

    @property
    def count(self) -> int:
        """Messages refused in all."""
        return sum(self.by_source.values())

    def refuse(self, source: str, text: str, *, log: bool = True) -> None:
        """Count a refusal from ``source`` (e.g. ``foxglove client 3``); ``text`` says what
        and why, in one line (``log=False``: counted only, e.g. before /rosout is up)."""
        seen = self.by_source[source] = self.by_source.get(source, 0) + 1
        if not log:
            return
        if seen <= LOGGED_PER_SOURCE:
            self._log(f"refused from {source}: {text}")
        if seen == LOGGED_PER_SOURCE:
            self._log(f"{source}: further refusals are counted, not logged")


def _not_finite(message: Any, path: str = "") -> str | None:
    """The first field of ``message`` that is a NaN or an infinity, or None."""
    if isinstance(message, float):
        return None if math.isfinite(message) else f"{path or 'value'} is {message}"
    if isinstance(message, tuple | list):
        for i, item in enumerate(message):
            problem = _not_finite(item, f"{path}[{i}]")
            if problem is not None:
                return problem
        return None
    if isinstance(message, Message):
        for name in type(message).model_fields:
            problem = _not_finite(getattr(message, name), f"{path}.{name}" if path else name)
            if problem is not None:
                return problem
    return None
