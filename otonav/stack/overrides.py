"""``--set key.path=value`` overrides, applied to a config model and validated."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from otonav.stack import safe_yaml
from otonav.stack.files import ConfigFileError, describe_validation_error, to_json

_M = TypeVar("_M", bound=BaseModel)


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
        for i, part in enumerate(parts[:-1]):
            child = node.get(part)
            if not isinstance(child, dict):
                where = ".".join(parts[: i + 1])
                raise ConfigFileError(
                    f"{source} {key}: '{where}' is not a section; valid sections: "
                    f"{', '.join(k for k, v in node.items() if isinstance(v, dict))}"
                )
            node = child
        if parts[-1] not in node:
            raise ConfigFileError(
                f"{source} {key}: unknown key '{parts[-1]}'; valid keys here: {', '.join(node)}"
            )
        if isinstance(node[parts[-1]], dict):
            raise ConfigFileError(
                f"{source} {key}: is a section; set its keys one by one, e.g. "
                f"{key}.{next(iter(node[parts[-1]]), 'key')}=VALUE"
            )
        node[parts[-1]] = value
    try:
        return type(model).model_validate_json(to_json(data, source))
    except ValidationError as exc:
        raise ConfigFileError(describe_validation_error(source, exc)) from None
