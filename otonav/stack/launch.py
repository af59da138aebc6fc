"""Launch as data: the stack config's ``actors`` list made into actors.

Each entry names a class (``package.module:Class`` importable from ``sys.path``, or
``path/to/file.py:Class``; a relative file is resolved against the config file when it
is loaded), its parameters and its remaps, as a ROS 2 launch file names a node's
executable, ``parameters`` and ``remappings``. An entry whose name is a built-in actor's
(``nav``, ``safety``, ``base``, ``bridge``) replaces it in place; any other is added.

A launchable actor declares its parameters as a pydantic model in a class attribute
``Params`` and takes them as ``params``::

    class Wander(Actor):
        class Params(BaseModel):
            speed: float = 0.2

        cmd = Output("/cmd_vel_nav", Twist)

        def __init__(self, params: Params, *, name=None, remap=None) -> None:
            super().__init__(name, remap=remap)
            self.params = params

An actor with no ``Params`` is built as ``Class(name=..., remap=...)`` and takes no
parameters. Bad parameters are one line naming ``actors.NAME.KEY``.
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import inspect
import re
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from otonav.runtime import Actor
from otonav.stack.config import ActorConfig, StackConfig
from otonav.stack.files import ConfigFileError, shown

__all__ = [
    "actor_class",
    "actor_params",
    "add_actors",
    "check_actors",
    "launch",
    "make_actor",
    "params_model",
]


def _import_file(path: Path, key: str) -> Any:
    """A module from a ``.py`` file, under a name derived from its path (importing the
    same file twice gives the same module)."""
    resolved = path.resolve()
    digest = hashlib.sha1(str(resolved).encode()).hexdigest()[:10]
    name = f"otonav_user_{resolved.stem}_{digest}"
    if name in sys.modules:
        return sys.modules[name]
    if not resolved.is_file():
        raise ConfigFileError(f"{key}: no file {path}")
    spec = importlib.util.spec_from_file_location(name, resolved)
    if spec is None or spec.loader is None:
        raise ConfigFileError(f"{key}: {path} is not a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        del sys.modules[name]
        raise ConfigFileError(
            f"{key}: importing {path} failed: {type(exc).__name__}: {exc}"
        ) from None
    return module


def actor_class(spec: str, key: str) -> type[Actor]:
    """The actor class ``spec`` names (``module:Class`` or ``file.py:Class``);
    :class:`ConfigFileError` naming ``key`` if it cannot be imported or is no actor."""
    where, sep, attr = spec.rpartition(":")
    if not sep or not where or not attr:
        raise ConfigFileError(
            f"{key}: {spec!r} is not module:Class (e.g. my_pkg.nodes:Wander or nodes.py:Wander)"
        )
    if where.endswith(".py"):
        module = _import_file(Path(where), key)
    else:
        try:
            module = importlib.import_module(where)
        except ImportError as exc:
            raise ConfigFileError(
                f"{key}: cannot import {where!r} ({exc}); is it on sys.path (PYTHONPATH)?"
            ) from None
        except Exception as exc:
            raise ConfigFileError(
                f"{key}: importing {where!r} failed: {type(exc).__name__}: {exc}"
            ) from None
    target = getattr(module, attr, None)
    if target is None:
        found = sorted(
            n
            for n, v in vars(module).items()
            if isinstance(v, type) and issubclass(v, Actor) and v.__module__ == module.__name__
        )
        raise ConfigFileError(
            f"{key}: {where!r} has no {attr!r} (actor classes there: {', '.join(found) or 'none'})"
        )
    if not (isinstance(target, type) and issubclass(target, Actor)):
        raise ConfigFileError(f"{key}: {spec} is not an otonav.runtime.Actor subclass")
    return target


def params_model(cls: type[Actor]) -> type[BaseModel] | None:
    """The class's declared parameter model (``Params``), if any."""
    model = getattr(cls, "Params", None)
    if isinstance(model, type) and issubclass(model, BaseModel):
        return model
    return None


def actor_params(cls: type[Actor], params: Mapping[str, Any], key: str) -> BaseModel | None:
    """``params`` validated against ``cls.Params`` (one line naming ``key.FIELD``)."""
    model = params_model(cls)
    if model is None:
        if params:
            raise ConfigFileError(
                f"{key}.params: {cls.__name__} declares no parameters (no Params model) "
                f"but was given {', '.join(sorted(params))}"
            )
        return None
    try:
        return model.model_validate(dict(params))
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join([key, *(str(part) for part in first["loc"])])
        message = first["msg"]
        if first["type"] == "extra_forbidden":
            known = ", ".join(model.model_fields) or "none"
            message = f"unknown parameter of {cls.__name__} (its parameters: {known})"
            return_value = ""
        else:
            return_value = f" (got {shown(first.get('input'))})"
        more = f"; and {exc.error_count() - 1} more" if exc.error_count() > 1 else ""
        raise ConfigFileError(f"{where}: {message}{return_value}{more}") from None


def make_actor(entry: ActorConfig) -> Actor:
    """The actor of one ``actors`` entry, its parameters validated."""
    key = f"actors.{entry.name}"
    cls = actor_class(entry.class_, f"{key}.class")
    params = actor_params(cls, entry.params, key)
    kwargs: dict[str, Any] = {"name": entry.name, "remap": dict(entry.remap)}
    if params is not None:
        kwargs["params"] = params
    try:
        inspect.signature(cls).bind(**kwargs)
    except TypeError as exc:
        how = "params, name and remap" if params is not None else "name and remap"
        raise ConfigFileError(
            f"{key}.class: {cls.__name__} must accept {how} as keywords ({exc})"
        ) from None
    actor = cls(**kwargs)
    if params is not None:
        actor._otonav_params = params.model_dump(mode="json")
    return actor


def add_actors(stack: StackConfig, specs: Sequence[str], *, source: str = "--actor") -> StackConfig:
    """``stack`` with one ``actors`` entry per ``module:Class`` (named by the class,
    in snake_case: ``my_nodes:Wander`` is ``wander``)."""
    entries = list(stack.actors)
    for spec in specs:
        attr = spec.rpartition(":")[2]
        if not attr.isidentifier():
            raise ConfigFileError(
                f"{source} {spec!r}: expected module:Class (e.g. my_pkg.nodes:Wander)"
            )
        name = re.sub(r"(?<!^)(?=[A-Z])", "_", attr).lower()
        if any(entry.name == name for entry in entries):
            raise ConfigFileError(
                f"{source} {spec}: an actor named {name!r} is already launched; name it in "
                "the config's actors list instead"
            )
        where = spec.rpartition(":")[0]
        if where.endswith(".py"):  # a file: found from any worker's directory
            spec = f"{Path(where).resolve()}:{attr}"
        entries.append(ActorConfig(name=name, class_=spec))
    return stack.model_copy(update={"actors": tuple(entries)})


def check_actors(entries: Sequence[ActorConfig]) -> None:
    """Import every entry's class and validate its parameters (what :func:`launch`
    would refuse), before anything runs."""
    for entry in entries:
        key = f"actors.{entry.name}"
        actor_params(actor_class(entry.class_, f"{key}.class"), entry.params, key)


def launch(builtin: Sequence[Actor], entries: Sequence[ActorConfig]) -> list[Actor]:
    """``builtin`` with each entry's actor in place of the built-in of its name, or
    after them (in the entries' order)."""
    actors = list(builtin)
    index = {actor.name: i for i, actor in enumerate(actors)}
    for entry in entries:
        actor = make_actor(entry)
        if entry.name in index:
            actors[index[entry.name]] = actor
        else:
            actors.append(actor)
    return actors
