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
  Settable only where a config key sets it (:data:`otonav.params.CONFIG_KEYS`, which
  ``stack.build`` builds them from): a new value passes that key's bounds, exactly as
  ``--set KEY=VALUE`` does (issue 41: a client set
  ``safety.params.scales`` to 1e8, which ``--set`` caps at 100, and the safety layer
  ran out of memory), then the dataclass's own check: a change builds a new dataclass
  with ``dataclasses.replace`` (each one on the way). A refused value leaves the old one.

Called on the loop's thread only (the live view hands requests over from the server's).
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Iterable
from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, TypeAdapter, ValidationError

from otonav.params import CONFIG_KEYS
from otonav.runtime import Actor
from otonav.stack._config import StackConfig

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
        return self._config_key(name) is not None

    def _config_key(self, name: str) -> str | None:
        """The config key bounding runtime-safe parameter ``name``; None: read-only."""
        actor, _, rest = name.partition(".")
        kind, _, path = rest.partition(".")
        params = getattr(self._actors.get(actor), "params", None)
        if kind != "params" or not path:
            return None
        live: frozenset[str] | None = getattr(self._actors[actor], "live_parameters", None)
        if live is not None and not any(
            path == entry or (entry.endswith(".") and path.startswith(entry)) for entry in live
        ):
            return None
        *parents, field = path.split(".")
        for parent in parents:
            params = getattr(params, parent, None)
        value = getattr(params, field, None) if dataclasses.is_dataclass(params) else None
        if value is None or not _numeric(value):
            return None
        return CONFIG_KEYS.get(type(params), {}).get(field)

    def set(self, name: str, value: Any) -> tuple[Any, Any]:
        """Set ``name`` to ``value``; returns ``(old, new)``. Raises :class:`ParameterError`."""
        current = self.values()
        if name not in current:
            raise ParameterError(f"parameter {name!r}: no such parameter")
        key = self._config_key(name)
        if key is None:
            raise ParameterError(
                f"parameter {name!r}: read-only while the robot runs (runtime-safe: the "
                "numeric ACTOR.params.FIELD ones a config key sets)"
            )
        old = current[name]
        if not _numeric(value):
            raise ParameterError(f"parameter {name!r}: {_short(value)} is not a number")
        if isinstance(old, int) and isinstance(value, float) and value.is_integer():
            value = int(value)  # JSON and ROS 2 clients may send 6.0 for 6
        try:
            new = _validator(key).validate_python(value)
        except ValidationError as exc:
            why = exc.errors()[0]["msg"]
            raise ParameterError(
                f"parameter {name!r}: {_short(value)} refused: {why} (the bound of {key}, "
                f"as --set {key}=... has it)"
            ) from None
        actor_name, _, path = name.partition(".params.")
        actor = self._actors[actor_name]
        try:
            actor.params = _replaced(actor.params, path.split("."), new)  # type: ignore[attr-defined]
        except (ValueError, TypeError) as exc:
            raise ParameterError(f"parameter {name!r}: {new!r} refused: {exc}") from None
        return old, new


@functools.cache  # built once per key: a set runs on the stack's thread
def _validator(key: str) -> TypeAdapter[Any]:
    """What validates config key ``key`` (``section.field``): its type and bounds, strict
    and finite, as the config's models validate it."""
    *sections, field = key.split(".")
    model: type[BaseModel] = StackConfig
    for section in sections:
        model = model.model_fields[section].annotation  # type: ignore[assignment]
    info = model.model_fields[field]
    return TypeAdapter(
        Annotated[info.annotation, info],  # type: ignore[arg-type]
        config=ConfigDict(strict=True, allow_inf_nan=False),
    )


def _short(value: Any) -> str:
    """``value`` quoted in one short line (a client may send 10**400 or a deep list)."""
    if isinstance(value, bool | float | str):
        text = repr(value)
    elif isinstance(value, int):
        text = str(value) if abs(value) < 10**30 else f"an integer of {len(str(abs(value)))} digits"
    else:
        text = f"a {type(value).__name__}"
    return text if len(text) <= 60 else text[:59] + "…"


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
