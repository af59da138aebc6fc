"""The actors' parameters as the Foxglove ``parameters`` capability shows them
(docs/adr/0044): read every one, set the runtime-safe ones while the robot runs.

- ``ACTOR.KEY``: what a launched actor was started with (its validated ``Params``,
  :attr:`Actor.parameters`): read-only, since the actor built itself from them once.
- ``ACTOR.params.FIELD``: a numeric field of the frozen dataclass an actor keeps as
  ``params`` (the go-to-goal gains and limits, the safety layer's stopping model, the
  avoiding navigator's), or of a dataclass nested in it (``nav.params.dwa.max_v``). The
  actor reads it every step, so a new value takes effect at the next one: these are the
  runtime-safe ones. An actor whose ``params`` are partly read once (the navigator's map
  size) names the ones it reads every step in ``live_parameters`` (paths under
  ``params``, a trailing ``.`` for a whole nested dataclass); the others are read-only.
  A change builds a new dataclass with ``dataclasses.replace`` (each one on the way), so
  it is validated as the dataclass validates itself (the same check a ``--set`` goes
  through); a refused value leaves the old one.

Called on the loop's thread only (the live view hands requests over from the server's).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from typing import Any

from otonav.runtime import Actor

__all__ = ("ActorParameters", "ParameterError")

_SCALARS = (bool, int, float, str)


class ParameterError(ValueError):
    """A parameter that does not exist, is read-only, or refused its value: one line."""


class ActorParameters:
    """The parameters of ``actors``, by dotted name."""

    def __init__(self, actors: Iterable[Actor]) -> None:
        self._actors = {actor.name: actor for actor in actors}

    def values(self) -> dict[str, Any]:
        """Every parameter's value now, by name, in actor order."""
        out: dict[str, Any] = {}
        for name, actor in self._actors.items():
            for key, value in actor.parameters.items():
                if isinstance(value, _SCALARS):
                    out[f"{name}.{key}"] = value
            out.update(_flatten(f"{name}.params", getattr(actor, "params", None)))
        return out

    def settable(self, name: str) -> bool:
        actor, _, rest = name.partition(".")
        kind, _, path = rest.partition(".")
        params = getattr(self._actors.get(actor), "params", None)
        if kind != "params" or not path:
            return False
        value = _flatten("", params).get(f".{path}")
        live: frozenset[str] | None = getattr(self._actors[actor], "live_parameters", None)
        if live is not None and not any(
            path == entry or (entry.endswith(".") and path.startswith(entry)) for entry in live
        ):
            return False
        return value is not None and _numeric(value)

    def set(self, name: str, value: Any) -> tuple[Any, Any]:
        """Set ``name`` to ``value``; returns ``(old, new)``. Raises :class:`ParameterError`."""
        current = self.values()
        if name not in current:
            raise ParameterError(f"parameter {name!r}: no such parameter")
        if not self.settable(name):
            raise ParameterError(
                f"parameter {name!r}: read-only while the robot runs "
                "(runtime-safe: the numeric ACTOR.params.FIELD ones)"
            )
        old = current[name]
        if not _numeric(value) or not math.isfinite(value):
            raise ParameterError(f"parameter {name!r}: {value!r} is not a finite number")
        if isinstance(old, int) and not float(value).is_integer():
            raise ParameterError(f"parameter {name!r}: {value!r} must be a whole number")
        new = int(value) if isinstance(old, int) else float(value)
        actor_name, _, path = name.partition(".params.")
        actor = self._actors[actor_name]
        try:
            actor.params = _replaced(actor.params, path.split("."), new)  # type: ignore[attr-defined]
        except (ValueError, TypeError) as exc:
            raise ParameterError(f"parameter {name!r}: {new!r} refused: {exc}") from None
        return old, new


def _flatten(prefix: str, params: Any) -> dict[str, Any]:
    """Every scalar field of dataclass ``params`` and of the dataclasses nested in it, by
    dotted name under ``prefix``."""
    out: dict[str, Any] = {}
    if not dataclasses.is_dataclass(params) or isinstance(params, type):
        return out
    for f in dataclasses.fields(params):
        value = getattr(params, f.name)
        if isinstance(value, _SCALARS):
            out[f"{prefix}.{f.name}"] = value
        else:
            out.update(_flatten(f"{prefix}.{f.name}", value))
    return out


def _replaced(params: Any, path: list[str], value: Any) -> Any:
    """``params`` with the field at ``path`` set to ``value``, each dataclass on the way
    rebuilt with ``dataclasses.replace`` (so each validates itself)."""
    head, *rest = path
    inner = _replaced(getattr(params, head), rest, value) if rest else value
    return dataclasses.replace(params, **{head: inner})


def _numeric(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)
