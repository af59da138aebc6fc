"""Launch as data: the stack config's ``actors`` list made into actors.

Each entry names a class (``package.module:Class`` importable from ``sys.path``, the
current directory or the config file's, or ``path/to/file.py:Class``; a relative file
is resolved against the config file when it is loaded), its parameters (inline, and a
ROS 2 ``params_file``) and its remaps, as a ROS 2 launch file names a node's
executable, ``parameters`` and ``remappings``. An entry whose name is a built-in actor's
(``nav``, ``safety``, ``base``, ``bridge``) replaces it in place, or, with no
``class``, remaps the built-in's topics; any other is added (ADR 0071).

A launchable actor declares its parameters as a pydantic model in a class attribute
``Params``; ``Actor.__init__`` takes them and keeps them as ``self.params``::

    class Wander(Actor):
        class Params(BaseModel):
            speed: float = 0.2

        cmd = Output("/cmd_vel_nav", Twist)

        async def run(self) -> None:
            ...  # self.params.speed

An actor with an ``__init__`` of its own takes ``params``, ``name`` and ``remap`` as
keywords and passes them on. Bad parameters are one line naming ``actors.NAME.KEY`` (or
the parameter file's key path).
"""

from __future__ import annotations

import hashlib
import importlib
import importlib.util
import inspect
import re
import sys
import traceback
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from otonav.runtime import Actor
from otonav.stack._config import ActorConfig, StackConfig
from otonav.stack._files import ConfigFileError, read_yaml, shown

__all__ = [
    "actor_class",
    "actor_params",
    "add_actors",
    "check_actors",
    "launch",
    "make_actor",
    "module_spec",
    "params_model",
    "remap_builtin",
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
        folder, slash, where = where.rpartition("/")
        if slash and folder not in sys.path:  # a module found in that folder (ADR 0071)
            sys.path.append(folder)
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


def module_spec(spec: str, folder: Path) -> str:
    """``spec`` (``module:Class``) as ``FOLDER/module:Class`` when its module is not
    importable from ``sys.path`` but lives in ``folder``, as ``python`` finds a module
    next to the script it runs; any other spec unchanged."""
    where, sep, attr = spec.rpartition(":")
    top = where.partition(".")[0]
    if not sep or where.endswith(".py") or "/" in where or not top.isidentifier():
        return spec
    try:
        if not ((folder / f"{top}.py").is_file() or (folder / top).is_dir()):
            return spec
    except OSError:  # a name no file system takes: not there
        return spec
    if importlib.util.find_spec(top) is not None:
        return spec
    return f"{folder.resolve()}/{where}:{attr}"


def _file_params(entry: ActorConfig, key: str) -> tuple[dict[str, Any], str]:
    """The parameters ``entry.params_file`` holds for ``entry.name`` (ROS 2's layout:
    ``NAME: {ros__parameters: {...}}``, ``/**`` for every node), and the key path prefix
    its errors name."""
    if entry.params_file is None:
        return {}, key
    path = Path(entry.params_file)
    data = read_yaml(path)
    if not isinstance(data, dict):
        raise ConfigFileError(f"{path}: expected NODE_NAME: {{ros__parameters: {{...}}}}")
    merged: dict[str, Any] = {}
    prefix = ""
    for node in ("/**", entry.name, f"/{entry.name}"):
        section = data.get(node)
        if section is None:
            continue
        if not isinstance(section, dict) or not isinstance(section.get("ros__parameters"), dict):
            raise ConfigFileError(
                f"{path}: {node}: expected a mapping with ros__parameters (ROS 2's layout: "
                f"{entry.name}: {{ros__parameters: {{KEY: VALUE}}}})"
            )
        merged.update(section["ros__parameters"])
        prefix = f"{node}.ros__parameters"
    if not prefix:
        raise ConfigFileError(
            f"{path}: no section for node {entry.name!r} (its sections: "
            f"{', '.join(map(str, data)) or 'none'}); name the node, or /** for every node"
        )
    return merged, f"{path}: {prefix}"


def actor_params(
    cls: type[Actor], params: Mapping[str, Any], key: str, *, entry: ActorConfig | None = None
) -> BaseModel | None:
    """``params`` validated against ``cls.Params`` (one line naming ``key.FIELD``); with
    ``entry``, its ``params_file``'s under them (an error there names the file's key)."""
    from_file, file_key = _file_params(entry, key) if entry is not None else ({}, key)
    model = params_model(cls)
    if model is None:
        if params or from_file:
            raise ConfigFileError(
                f"{key}.params: {cls.__name__} declares no parameters (no Params model) "
                f"but was given {', '.join(sorted({**from_file, **params}))}"
            )
        return None
    try:
        return model.model_validate({**from_file, **params})
    except ValidationError as exc:
        first = exc.errors()[0]
        top = str(first["loc"][0]) if first["loc"] else ""
        if top in from_file and top not in params:
            key = file_key
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
    if entry.class_ is None:
        raise ConfigFileError(f"{key}: no class, and no built-in actor of that name to remap")
    cls = actor_class(entry.class_, f"{key}.class")
    params = actor_params(cls, entry.params, key, entry=entry)
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
    try:
        actor = cls(**kwargs)
    except Exception as exc:  # the user's __init__: one line, where it raised (issue 41)
        frame = traceback.extract_tb(exc.__traceback__)[-1]
        raise ConfigFileError(
            f"{key}: {cls.__name__}(...) raised {type(exc).__name__}: {exc} "
            f"({Path(frame.filename).name}:{frame.lineno})"
        ) from None
    if params is not None:
        actor._otonav_params = params.model_dump(mode="json")
    return actor


def remap_builtin(actor: Actor, entry: ActorConfig) -> None:
    """Rename ``actor``'s topics as ``entry.remap`` says, from the names it has now
    (``otonav graph``'s) to new ones; a class-less entry may do nothing else."""
    key = f"actors.{entry.name}"
    if entry.params or entry.params_file:
        raise ConfigFileError(
            f"{key}.params: a built-in actor takes its parameters from the config's sections "
            "(nav.*, safety.*, base.*); give a class to replace it with your own"
        )
    now = {port.topic: actor.topic_of(port) for port in actor.ports()}
    unknown = sorted(set(entry.remap) - set(now.values()))
    if unknown:
        raise ConfigFileError(
            f"{key}.remap: {entry.name} has no topic {', '.join(unknown)} (its topics: "
            f"{', '.join(sorted(set(now.values())))})"
        )
    actor._otonav_remap = {port: entry.remap.get(topic, topic) for port, topic in now.items()}


def add_actors(stack: StackConfig, specs: Sequence[str], *, source: str = "--actor") -> StackConfig:
    """``stack`` with one ``actors`` entry per ``module:Class`` (named by the class,
    in snake_case: ``my_nodes:Wander`` is ``wander``)."""
    entries = list(stack.actors)
    for spec in specs:
        where, _sep, attr = spec.rpartition(":")
        if not where or not attr.isidentifier():
            raise ConfigFileError(
                f"{source} {spec!r}: expected module:Class (e.g. my_pkg.nodes:Wander)"
            )
        name = re.sub(r"(?<!^)(?=[A-Z])", "_", attr).lower()
        if any(entry.name == name for entry in entries):
            raise ConfigFileError(
                f"{source} {spec}: an actor named {name!r} is already launched; name it in "
                "the config's actors list instead"
            )
        if where.endswith(".py"):  # a file: found from any worker's directory
            spec = f"{Path(where).resolve()}:{attr}"
        try:
            entries.append(ActorConfig(name=name, class_=module_spec(spec, Path.cwd())))
        except ValidationError as exc:  # a name or path too long, ...: one line
            raise ConfigFileError(f"{source} {shown(spec)}: {exc.errors()[0]['msg']}") from None
    return stack.model_copy(update={"actors": tuple(entries)})


def check_actors(entries: Sequence[ActorConfig]) -> None:
    """Import every entry's class and validate its parameters (what :func:`launch`
    would refuse), before anything runs."""
    for entry in entries:
        key = f"actors.{entry.name}"
        if entry.class_ is not None:
            actor_params(actor_class(entry.class_, f"{key}.class"), entry.params, key, entry=entry)


def launch(builtin: Sequence[Actor], entries: Sequence[ActorConfig]) -> list[Actor]:
    """``builtin`` with each entry's actor in place of the built-in of its name, or
    after them (in the entries' order)."""
    actors = list(builtin)
    index = {actor.name: i for i, actor in enumerate(actors)}
    for entry in entries:
        if entry.class_ is None and entry.name in index:
            remap_builtin(actors[index[entry.name]], entry)
            continue
        actor = make_actor(entry)
        if entry.name in index:
            actors[index[entry.name]] = actor
        else:
            actors.append(actor)
    return actors
