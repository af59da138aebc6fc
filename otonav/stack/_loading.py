"""A stack config file as a launch file: loaded, validated, and its relative paths
(``robot.model``, an actor's ``path/file.py:Class``, ``module:Class`` next to the file,
``params_file``) taken from the file's folder, as a ROS 2 launch file finds what it
names relative to its package."""

from __future__ import annotations

from pathlib import Path

from otonav.hal._description import BUILTIN_ROBOTS
from otonav.stack._config import StackConfig
from otonav.stack._files import load_model
from otonav.stack._launch import module_spec

__all__ = ["load_stack_file", "resolve_paths"]


def load_stack_file(path: Path | str) -> StackConfig:
    """The stack config in ``path`` (YAML), its relative paths resolved against the
    file's folder; :class:`~otonav.stack._files.ConfigFileError` on any problem."""
    path = Path(path)
    return resolve_paths(load_model(path, StackConfig), path.parent)


def resolve_paths(stack: StackConfig, folder: Path) -> StackConfig:
    """``stack`` with its relative file paths (``robot.model``, an actor's
    ``path/file.py:Class``) made relative to ``folder`` (the config file's)."""
    updates: dict[str, object] = {}
    model = stack.robot.model
    if model not in BUILTIN_ROBOTS and not Path(model).is_absolute():
        updates["robot"] = stack.robot.model_copy(update={"model": str(folder / model)})
    actors = []
    for entry in stack.actors:
        if entry.params_file is not None and not Path(entry.params_file).is_absolute():
            entry = entry.model_copy(update={"params_file": str(folder / entry.params_file)})
        spec = entry.class_
        if spec is not None:
            where, sep, name = spec.rpartition(":")
            if sep and where.endswith(".py") and not Path(where).is_absolute():
                entry = entry.model_copy(update={"class_": f"{folder / where}:{name}"})
            else:
                entry = entry.model_copy(update={"class_": module_spec(spec, folder)})
        actors.append(entry)
    if tuple(actors) != stack.actors:
        updates["actors"] = tuple(actors)
    return stack.model_copy(update=updates) if updates else stack
