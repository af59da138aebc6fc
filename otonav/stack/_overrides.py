"""``--set key.path=value`` overrides, applied to a config model and validated."""

from __future__ import annotations

import types
import typing
from collections.abc import Sequence
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from otonav.stack import _safe_yaml as safe_yaml
from otonav.stack._files import ConfigFileError, describe_validation_error, to_json

_M = TypeVar("_M", bound=BaseModel)


def _section(model: type[BaseModel] | None, name: str) -> type[BaseModel] | None:
    """The model of section ``name`` of ``model`` (an optional section's too), or None."""
    field = model.model_fields.get(name) if model is not None else None
    if field is None:
        return None
    kinds = [field.annotation]
    if isinstance(field.annotation, types.UnionType) or typing.get_origin(field.annotation) is (
        typing.Union
    ):
        kinds = list(typing.get_args(field.annotation))
    for kind in kinds:
        if isinstance(kind, type) and issubclass(kind, BaseModel):
            return kind
    return None


def _actor_path(data: dict[str, Any], parts: list[str], source: str, key: str) -> list[str]:
    """``actors.NAME.KEY`` (a parameter of the launched actor NAME) as a path into the
    dumped config: the ``actors`` list becomes a mapping by name for the walk below."""
    if parts[0] != "actors" or "actors" not in data:
        return parts
    entries = data["actors"]
    names = list(entries) if isinstance(entries, dict) else [entry["name"] for entry in entries]
    if len(parts) < 3 or parts[1] not in names:
        raise ConfigFileError(
            f"{source} {key}: expected actors.NAME.PARAM with NAME one of the launched "
            f"actors ({', '.join(names) or 'none: add one with --actor or the actors list'})"
        )
    if isinstance(entries, list):
        data["actors"] = {entry["name"]: entry for entry in entries}
    entry = data["actors"][parts[1]]
    if parts[2] in ("params", "remap", "class", "name") and len(parts) > 3:
        return parts
    if parts[2] in ("class", "name"):
        return parts
    entry.setdefault("params", {}).setdefault(parts[2], None)  # validated by the Params model
    return ["actors", parts[1], "params", *parts[2:]]


def apply_overrides(model: _M, assignments: Sequence[str], *, source: str = "--set") -> _M:
    """Return ``model`` with each ``a.b.c=value`` applied (values parsed as YAML scalars)."""
    data: dict[str, Any] = model.model_dump(mode="json")
    for assignment in assignments:
        key, sep, raw = assignment.partition("=")
        if not sep or not key.strip():
            raise ConfigFileError(
                f"{source} {assignment!r}: expected key.path=value, e.g. nav.kp_lin=0.5"
            )
        try:
            value = safe_yaml.load(raw)
        except safe_yaml.YamlLimitError as exc:
            raise ConfigFileError(f"{source} {key.strip()}: {exc}") from None
        except yaml.YAMLError:
            value = raw
        node = data
        parts = key.strip().split(".")
        parts = _actor_path(data, parts, source, key)
        section: type[BaseModel] | None = type(model)
        for i, part in enumerate(parts[:-1]):
            parent, section = section, _section(section, part)
            child = node.get(part)
            if child is None and section is not None:  # an optional section left out
                child = node[part] = {}
            if not isinstance(child, dict):
                where = ".".join(parts[: i + 1])
                sections = [k for k in node if isinstance(node[k], dict) or _section(parent, k)]
                raise ConfigFileError(
                    f"{source} {key}: '{where}' is not a section; valid sections: "
                    f"{', '.join(sections)}"
                )
            node = child
        fields = list(section.model_fields) if section is not None else []
        known = [*node, *(name for name in fields if name not in node)]
        if parts[-1] not in known:
            raise ConfigFileError(
                f"{source} {key}: unknown key '{parts[-1]}'; valid keys here: {', '.join(known)}"
            )
        if isinstance(node.get(parts[-1]), dict):
            raise ConfigFileError(
                f"{source} {key}: is a section; set its keys one by one, e.g. "
                f"{key}.{next(iter(node[parts[-1]]), 'key')}=VALUE"
            )
        node[parts[-1]] = value
    if isinstance(data.get("actors"), dict):
        data["actors"] = list(data["actors"].values())
    try:
        return type(model).model_validate_json(to_json(data, source))
    except ValidationError as exc:
        raise ConfigFileError(describe_validation_error(source, exc)) from None
