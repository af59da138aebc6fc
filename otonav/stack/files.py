"""Reading configuration files: YAML (safe loading only) validated by the pydantic models."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TypeVar

import yaml
from pydantic import BaseModel, ValidationError

_M = TypeVar("_M", bound=BaseModel)


class ConfigFileError(ValueError):
    """A configuration file that cannot be used: one line naming the file, the key path
    and what would be valid."""


def describe_validation_error(source: str, error: ValidationError) -> str:
    """One line: ``file: key.path: what is wrong (got value); other.key: ...``."""
    problems = []
    for item in error.errors():
        path = ".".join(str(part) for part in item["loc"]) or "(top level)"
        message = item["msg"]
        if item["type"] == "extra_forbidden":
            message = "unknown key (check the spelling; the README lists the valid keys)"
        got = item.get("input")
        shown = "" if item["type"] in ("extra_forbidden", "missing") else f" (got {got!r})"
        problems.append(f"{path}: {message}{shown}")
    return f"{source}: " + "; ".join(problems)


def to_json(data: object, source: str) -> str:
    """YAML data as JSON for strict validation; a value JSON cannot hold (a YAML date,
    a binary) is a configuration error naming where it is."""
    try:
        return json.dumps(data)
    except (TypeError, ValueError) as exc:
        raise ConfigFileError(
            f"{source}: a value is not a number, string, list or mapping ({exc}); "
            "quote it if it is meant as text"
        ) from None


def load_model(path: Path, model: type[_M]) -> _M:
    """Load ``path`` (YAML) as ``model``; raise :class:`ConfigFileError` on any problem."""
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise ConfigFileError(f"{path}: no such file") from None
    except OSError as exc:
        raise ConfigFileError(f"{path}: cannot read ({exc.strerror})") from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise ConfigFileError(f"{path}: invalid YAML{where}: {problem}") from None
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ConfigFileError(
            f"{path}: expected a mapping of keys at the top level, got {type(data).__name__}"
        )
    try:
        # JSON mode: with strict models, YAML lists become tuples and mappings models,
        # while "yes" or "3" stay refused where a number is expected.
        return model.model_validate_json(to_json(data, str(path)))
    except ValidationError as exc:
        raise ConfigFileError(describe_validation_error(str(path), exc)) from None
