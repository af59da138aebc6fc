"""Reading configuration files: YAML (safe loading, within size, depth and expansion
limits: ``otonav.stack._safe_yaml``) validated by the pydantic models."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TypeVar

import yaml
from pydantic import BaseModel, ValidationError

from otonav.errors import UsageError
from otonav.stack import _safe_yaml as safe_yaml

_M = TypeVar("_M", bound=BaseModel)


class ConfigFileError(UsageError):
    """A configuration file that cannot be used: one line naming the file, the key path
    and what would be valid."""


SHOWN_CHARS = 60
"""How much of a rejected value an error line quotes (a 10 MB name stays one short line)."""

SHOWN_PROBLEMS = 5
"""How many problems an error line lists before "and N more"."""


def shown(value: object) -> str:
    text = repr(value)
    if len(text) <= SHOWN_CHARS:
        return text
    return f"{text[: SHOWN_CHARS - 25]}... ({len(text):,} characters)"


def describe_validation_error(source: str, error: ValidationError) -> str:
    """One line: ``file: key.path: what is wrong (got value); other.key: ...``."""
    problems = []
    errors = error.errors()
    for item in errors[:SHOWN_PROBLEMS]:
        path = ".".join(str(part) for part in item["loc"])
        message = item["msg"]
        if item["type"] == "extra_forbidden":
            message = "unknown key (check the spelling; the README lists the valid keys)"
        elif item["type"] == "value_error":  # our own validators: the message says it all
            message = message.removeprefix("Value error, ")
        got = item.get("input")
        if item["type"] in ("extra_forbidden", "missing") or (
            item["type"] == "value_error" and not path
        ):
            quoted = ""  # a whole-model check quotes what it needs itself
        else:
            quoted = f" (got {shown(got)})"
        problems.append(f"{path}: {message}{quoted}" if path else message)
    if len(errors) > SHOWN_PROBLEMS:
        problems.append(f"and {len(errors) - SHOWN_PROBLEMS} more")
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


def parse_yaml(text: str | bytes, source: str) -> object:
    """One YAML document (bytes: must be UTF-8) within the limits of
    :mod:`otonav.stack._safe_yaml`; :class:`ConfigFileError` naming ``source`` otherwise."""
    try:
        return safe_yaml.load(safe_yaml.decode(text) if isinstance(text, bytes) else text)
    except safe_yaml.YamlLimitError as exc:
        raise ConfigFileError(f"{source}: {exc}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc)
        problem = " ".join(str(problem).split())
        raise ConfigFileError(f"{source}: invalid YAML{where}: {problem}") from None


def read_yaml(path: Path) -> object:
    """The YAML document in ``path``, read within the limits; :class:`ConfigFileError`
    naming the file otherwise."""
    try:
        with path.open("rb") as f:
            raw = f.read(safe_yaml.MAX_BYTES + 1)  # bounded, even for /dev/zero
    except FileNotFoundError:
        raise ConfigFileError(f"{path}: no such file") from None
    except OSError as exc:
        raise ConfigFileError(f"{path}: cannot read ({exc.strerror})") from None
    return parse_yaml(raw, str(path))


def load_model(path: Path, model: type[_M]) -> _M:
    """Load ``path`` (YAML) as ``model``; raise :class:`ConfigFileError` on any problem."""
    data = read_yaml(path)
    if data is None or data == {}:  # it silently ran the defaults (issue 27)
        raise ConfigFileError(
            f"{path}: empty (no keys); give at least one key (the README lists them), "
            "or leave the file out to use the defaults"
        )
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
