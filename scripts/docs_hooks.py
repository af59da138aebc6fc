"""The docs site's build hook (``hooks:`` in mkdocs.yml): reference text made from the code.

A page asks for generated text with a line of its own::

    <!-- generated: NAME -->

and :func:`on_page_markdown` puts the text there while the site builds, so it cannot drift
from the code: the CLI reference comes from the argparse parsers, the config keys (default,
unit, bounds, meaning) from the pydantic models and their attribute docstrings, the exit
codes from the CLI's own epilog, and the sample outputs (``run``, ``info``, ``replay``,
``graph``, ``scenarios``) from one real run made in a temporary directory during the build
(~5 s), with the figures that change from run to run (wall time, real-time factor, CPU)
masked. An unknown NAME fails the build. ``tests/static/test_docs.py`` calls the same
functions, so a generator that breaks is red in the gate before the site is built.
"""

from __future__ import annotations

import argparse
import ast
import functools
import inspect
import os
import re
import subprocess
import sys
import tempfile
import textwrap
import types
import typing
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, Literal, NamedTuple

import annotated_types
from pydantic import BaseModel
from pydantic.functional_validators import AfterValidator
from pydantic_core import PydanticUndefined

MARKER = re.compile(r"^<!-- generated: ([a-z0-9:_-]+) -->$", flags=re.MULTILINE)
DASH = "\N{EN DASH}"
COLUMNS = "110"
"""Terminal width the samples and the CLI help are formatted for."""

# ---------------------------------------------------------------------------------- CLI


def _parser_tree() -> dict[str, argparse.ArgumentParser]:
    os.environ["COLUMNS"] = COLUMNS  # argparse wraps help to the terminal width
    from otonav.cli import build_parser

    parser = build_parser()
    tree = {"otonav": parser}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                tree[f"otonav {name}"] = sub
    return tree


def cli_reference() -> str:
    """Every command's ``--help``, as argparse prints it."""
    parts = []
    for name, parser in _parser_tree().items():
        parts.append(f"## `{name}`\n\n```text\n$ {name} --help\n{parser.format_help()}```\n")
    return "\n".join(parts)


def exit_codes() -> str:
    """The exit-code table, from the epilog ``otonav --help`` prints."""
    from otonav.cli import EPILOG

    section = EPILOG.split("exit codes:\n", 1)[1]
    rows = ["| code | meaning |", "|---|---|"]
    entries: list[list[str]] = []
    for line in section.splitlines():
        match = re.match(r"^\s{1,8}(\S+)\s{2,}(.*)$", line)
        if match:
            entries.append([match.group(1), match.group(2)])
        elif entries and line.startswith(" " * 9) and line.strip():
            entries[-1][1] += " " + line.strip()  # a meaning that goes on
    rows += [f"| `{code}` | {meaning} |" for code, meaning in entries]
    if len(rows) < 4:
        raise ValueError("exit codes: the CLI epilog lists none (format changed?)")
    return "\n".join(rows) + "\n"


# ------------------------------------------------------------------------------- config


class Row(NamedTuple):
    key: str
    type: str
    default: str
    unit: str
    bounds: str
    meaning: str


UNITS = r"s of sim time|turns/s\^2|turns/s|m/s²|m/s\^2|m/s|rad/s²|rad/s|rad|Hz|s|m"
_LEADING_UNIT = re.compile(rf"^({UNITS})(?=[,:;.) ]|$)")
_INNER_UNIT = re.compile(rf"(?:,|^[^.]*?,) ({UNITS})(?=[:,.]| of)")


def _attribute_docs(model: type[BaseModel]) -> dict[str, str]:
    """``name: type = ...`` followed by a string literal: the attribute's docstring."""
    docs: dict[str, str] = {}
    for cls in reversed(model.__mro__):
        if not (isinstance(cls, type) and issubclass(cls, BaseModel)) or cls is BaseModel:
            continue
        try:
            tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
        except (OSError, TypeError):
            continue
        body = tree.body[0].body if isinstance(tree.body[0], ast.ClassDef) else []
        for node, after in zip(body, [*body[1:], None], strict=True):
            if (
                isinstance(node, ast.AnnAssign)
                and isinstance(node.target, ast.Name)
                and isinstance(after, ast.Expr)
                and isinstance(after.value, ast.Constant)
                and isinstance(after.value.value, str)
            ):
                docs[node.target.id] = inspect.cleandoc(after.value.value)
    return docs


def _alias_docs(model: type[BaseModel]) -> dict[str, str]:
    """Module-level type aliases with a docstring (``Coordinate = Annotated[...]`` then
    ``\"\"\"m, a position\"\"\"``), by the field names annotated with them."""
    module = sys.modules[model.__module__]
    docs: dict[str, str] = {}
    by_alias: dict[str, str] = {}
    try:
        body = ast.parse(inspect.getsource(module)).body
    except (OSError, TypeError):
        return docs
    for node, after in zip(body, [*body[1:], None], strict=True):
        if (
            isinstance(node, ast.Assign | ast.AnnAssign)
            and isinstance(after, ast.Expr)
            and isinstance(after.value, ast.Constant)
            and isinstance(after.value.value, str)
        ):
            target = node.targets[0] if isinstance(node, ast.Assign) else node.target
            if isinstance(target, ast.Name):
                by_alias[target.id] = inspect.cleandoc(after.value.value)
    for cls in reversed(model.__mro__):
        for field, annotation in vars(cls).get("__annotations__", {}).items():
            if isinstance(annotation, str) and annotation in by_alias:
                docs[field] = by_alias[annotation]
    return docs


def _submodel(annotation: Any) -> type[BaseModel] | None:
    for arg in [annotation, *typing.get_args(annotation)]:
        if isinstance(arg, type) and issubclass(arg, BaseModel):
            return arg
    return None


def _is_list_of_models(annotation: Any) -> type[BaseModel] | None:
    if typing.get_origin(annotation) is tuple:
        args = typing.get_args(annotation)
        if len(args) == 2 and args[1] is Ellipsis:
            return _submodel(args[0])
    return None


def _type_name(annotation: Any) -> str:
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is Literal:
        return " \\| ".join(f"`{a}`" for a in args)
    if origin in (types.UnionType, typing.Union):
        named = [_type_name(a) for a in args if a is not type(None)]
        return " \\| ".join(named) + (" \\| null" if type(None) in args else "")
    if origin is typing.Annotated:
        return _type_name(args[0])
    if origin is tuple:
        if len(args) == 2 and args[1] is Ellipsis:
            return f"list of {_type_name(args[0])}"
        return "[" + ", ".join(_type_name(a) for a in args) + "]"
    if origin is dict:
        return "mapping"
    if isinstance(annotation, type):
        if issubclass(annotation, BaseModel):
            return "mapping"
        return annotation.__name__
    return str(annotation).replace("typing.", "")


def _number(value: Any) -> str:
    return str(value) if isinstance(value, int) else f"{value:g}"


def _bounds(metadata: list[Any], annotation: Any) -> str:
    low = high = ""
    lengths: list[str] = []
    for item in [*metadata, *_annotated_metadata(annotation)]:
        if isinstance(item, annotated_types.Gt):
            low = f"({_number(item.gt)}"
        elif isinstance(item, annotated_types.Ge):
            low = f"[{_number(item.ge)}"
        elif isinstance(item, annotated_types.Lt):
            high = f"{_number(item.lt)})"
        elif isinstance(item, annotated_types.Le):
            high = f"{_number(item.le)}]"
        elif isinstance(item, annotated_types.MinLen):
            lengths.append(f"length ≥ {item.min_length}")
        elif isinstance(item, annotated_types.MaxLen):
            lengths.append(f"length ≤ {item.max_length}")
        elif isinstance(item, AfterValidator):
            closure = inspect.getclosurevars(item.func).nonlocals
            if {"lo", "hi"} <= closure.keys():
                low = ("(" if closure.get("open_low") else "[") + _number(closure["lo"])
                high = _number(closure["hi"]) + "]"
    if low or high:
        return f"{low or '(-∞'}, {high or '∞)'}"
    if len(lengths) == 2:
        return "length " + DASH.join(text.split()[-1] for text in lengths)
    return ", ".join(lengths)


def _annotated_metadata(annotation: Any) -> list[Any]:
    """Constraints carried by the type itself (``PositiveFloat``, ``Annotated[...]``),
    also inside ``X | None``."""
    found: list[Any] = []
    if typing.get_origin(annotation) is typing.Annotated:
        found.extend(annotation.__metadata__)
        for sub in typing.get_args(annotation)[1:]:
            if hasattr(sub, "metadata"):  # a pydantic FieldInfo inside Annotated
                found.extend(sub.metadata)
    for arg in typing.get_args(annotation):
        if typing.get_origin(arg) is typing.Annotated:
            found.extend(_annotated_metadata(arg))
    return found


def _unit(name: str, doc: str, metadata: list[Any], annotation: Any) -> str:
    for item in [*metadata, *_annotated_metadata(annotation)]:
        if isinstance(item, AfterValidator):
            unit = str(inspect.getclosurevars(item.func).nonlocals.get("unit", "")).strip()
            if unit:
                return unit
    first = doc.split(". ")[0]
    for pattern in (_LEADING_UNIT, _INNER_UNIT):
        match = pattern.search(first)
        if match:
            return match.group(1).replace("^2", "²")
    for suffix, unit in (("_hz", "Hz"), ("_s", "s"), ("_m", "m")):
        if name.endswith(suffix):
            return unit
    return ""


def _show(value: Any) -> str:
    if value is None:
        return DASH
    if isinstance(value, BaseModel):
        return "`" + ", ".join(f"{k}: {v}" for k, v in value.model_dump().items()) + "`"
    if isinstance(value, bool):
        return f"`{str(value).lower()}`"
    if isinstance(value, float):
        return f"`{value:.6g}`"
    if isinstance(value, tuple | list | dict) and not value:
        return "`[]`" if not isinstance(value, dict) else "`{}`"
    return f"`{value}`"


def _prose(doc: str) -> str:
    """A docstring as one table cell: one line, Markdown code spans, pipes escaped."""
    text = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", " ".join(doc.split()))
    return text.replace("``", "`").replace("|", "\\|")


def config_rows(
    model: type[BaseModel], instance: BaseModel | None, prefix: str = ""
) -> Iterator[Row]:
    """One row per leaf key of ``model``, defaults read from ``instance`` (a section's
    default can differ from its class's, e.g. ``hal.can.left.sign``)."""
    docs = _attribute_docs(model)
    aliases = _alias_docs(model)
    for name, info in model.model_fields.items():
        key = prefix + (info.alias or name)
        value = getattr(instance, name) if instance is not None else None
        if instance is None:
            if info.default_factory is not None:
                value = info.default_factory()  # type: ignore[call-arg]
            elif info.default is not PydanticUndefined:
                value = info.default
        doc = docs.get(name, "")
        alias_doc = aliases.get(name, "")
        listed = _is_list_of_models(info.annotation)
        if listed is not None:
            fields = ", ".join(f.alias or n for n, f in listed.model_fields.items())
            yield Row(key, f"list of {{{fields}}}", _show(value), "", "", _prose(doc))
            yield from config_rows(listed, None, f"{key}[].")
            continue
        sub = _submodel(info.annotation)
        if sub is not None and typing.get_origin(info.annotation) is not dict:
            if value is None:
                yield Row(key, _type_name(info.annotation), DASH, "", "", _prose(doc))
            yield from config_rows(sub, value if isinstance(value, BaseModel) else None, f"{key}.")
            continue
        required = instance is None and info.is_required()
        yield Row(
            key=key,
            type=_type_name(info.annotation),
            default="required" if required else _show(value),
            unit=_unit(name, doc or alias_doc, list(info.metadata), info.annotation),
            bounds=_bounds(list(info.metadata), info.annotation),
            meaning=_prose(doc or alias_doc),
        )


def config_table(model: type[BaseModel], instance: BaseModel | None) -> str:
    lines = [
        "| key | type | default | unit | bounds | meaning |",
        "|---|---|---|---|---|---|",
    ]
    for row in config_rows(model, instance):
        lines.append("| " + " | ".join([f"`{row.key}`", *row[1:]]) + " |")
    return "\n".join(lines) + "\n"


def stack_config_reference() -> str:
    """One table per top-level section, headed by the section's class docstring."""
    from otonav.stack import StackConfig

    parts = []
    defaults = StackConfig()
    for name, info in StackConfig.model_fields.items():
        sub = _submodel(info.annotation)
        listed = _is_list_of_models(info.annotation)
        model = listed or sub
        if model is None:
            raise ValueError(f"StackConfig.{name}: a top-level key that is no section")
        rows = config_table(model, None if listed else getattr(defaults, name))
        prefix = f"{name}[]." if listed else f"{name}."
        rows = re.sub(r"^\| `", f"| `{prefix}", rows, flags=re.MULTILINE)
        rows = rows.replace(f"| `{prefix}key` |", "| key |")
        parts.append(f"## `{name}`\n\n{_prose(model.__doc__ or '')}\n\n{rows}")
    return "\n".join(parts)


def scenario_reference() -> str:
    from otonav.scenario import ScenarioConfig

    return config_table(ScenarioConfig, ScenarioConfig())


def sweep_reference() -> str:
    from otonav.sweep._spec import SweepSpec

    return config_table(SweepSpec, None)


# --------------------------------------------------------------------------------- ADRs

DOCS = Path(__file__).resolve().parent.parent / "docs"


def adr_index() -> str:
    """Every ``docs/adr/NNNN-*.md`` with its title (its first heading), linked."""
    rows = ["| # | decision |", "|---|---|"]
    for path in sorted((DOCS / "adr").glob("[0-9][0-9][0-9][0-9]-*.md")):
        heading = next(
            (line for line in path.read_text().splitlines() if line.startswith("# ")), ""
        )
        title = re.sub(r"^#\s*(ADR\s*)?0*\d+\s*[:.—-]?\s*", "", heading).strip() or path.stem
        rows.append(f"| [{path.name[:4]}](../adr/{path.name}) | {title} |")
    return "\n".join(rows) + "\n"


# ------------------------------------------------------------------------------ samples

SAMPLES: dict[str, tuple[list[str], int]] = {
    "run": (["run"], 0),
    "info": (["info", "out/recording.mcap"], 0),
    "replay": (["replay", "out/recording.mcap", "--node", "nav", "--set", "nav.kp_ang=3.0"], 1),
    "graph": (["graph"], 0),
    "scenarios": (["scenarios"], 0),
}
"""Commands whose output the pages show, with the exit code each must give."""

VOLATILE: list[tuple[re.Pattern[str], str]] = [
    # the verdict table: wall time and real-time factor
    (re.compile(r"(│ wall time\s+│\s+)(\S+ s)"), "wall"),
    (re.compile(r"(│ real-time factor\s+│\s+)(\S+x)"), "rtf"),
    # replay: "in 0.186 s (72x; CPU 0.088 s)"
    (re.compile(r"( in )([0-9.]+ s \([0-9.]+x; CPU [0-9.]+ s\))"), "replay"),
]
"""Figures that depend on the machine's speed and load: masked with … (same width)."""


def mask(text: str) -> str:
    for pattern, _what in VOLATILE:
        text = pattern.sub(lambda m: m.group(1) + "…".rjust(len(m.group(2))), text)
    return text


@functools.cache
def _sample_outputs() -> dict[str, str]:
    env = {**os.environ, "COLUMNS": COLUMNS, "NO_COLOR": "1", "TERM": "dumb"}
    outputs: dict[str, str] = {}
    with tempfile.TemporaryDirectory(prefix="otonav-docs-") as tmp:
        for name, (args, expected) in SAMPLES.items():  # run first: the others read it
            done = subprocess.run(
                [sys.executable, "-m", "otonav", *args],
                cwd=tmp,
                env=env,
                capture_output=True,
                text=True,
                timeout=300,
                check=False,
            )
            if done.returncode != expected:
                raise RuntimeError(
                    f"docs sample 'otonav {' '.join(args)}' exited {done.returncode}, "
                    f"expected {expected}:\n{done.stdout}\n{done.stderr}"
                )
            body = "\n".join(line.rstrip() for line in done.stdout.splitlines())
            outputs[name] = f"```text\n$ otonav {' '.join(args)}\n{mask(body)}\n```\n"
        refresh_picture(Path(tmp) / "out" / "trajectory.png")
    return outputs


PICTURE = DOCS / "images" / "trajectory.png"
"""The README's and the front page's picture: the default run's plot, as it is drawn now."""


def refresh_picture(drawn: Path) -> bool:
    """Put the plot the build's own default run drew in place of :data:`PICTURE` when it
    differs (the README showed an older drawing, issue 39); True if it changed."""
    if PICTURE.exists() and PICTURE.read_bytes() == drawn.read_bytes():
        return False
    PICTURE.write_bytes(drawn.read_bytes())
    return True


def sample(name: str) -> str:
    return _sample_outputs()[name]


# ------------------------------------------------------------------------------- blocks

ROOT = DOCS.parent
FENCE = re.compile(r"^```\{?\.?(\w*)[^\n]*\n(.*?)^```$", flags=re.DOTALL | re.MULTILINE)
"""A fenced block: ```python, or ```{.python title="..."} (which ruff's formatter leaves be)."""
SNIPPET = re.compile(r'^--8<-- "([^"]+)"\s*$')


def doc_sources() -> list[Path]:
    """The Markdown the tests read: every page of the site (ADRs aside) and the README."""
    pages = [p for p in sorted(DOCS.rglob("*.md")) if "adr" not in p.relative_to(DOCS).parts]
    return [ROOT / "README.md", *pages]


def code_blocks(lang: str) -> list[tuple[Path, str]]:
    """Every fenced block of ``lang`` in :func:`doc_sources`, with its file."""
    return [
        (path, body)
        for path in doc_sources()
        for block_lang, body in FENCE.findall(path.read_text())
        if block_lang == lang
    ]


def included_file(body: str) -> Path | None:
    """The file a block includes whole (``--8<-- "path"``), or None."""
    match = SNIPPET.match(body.strip())
    return ROOT / match.group(1) if match else None


# --------------------------------------------------------------------------------- hook

GENERATORS: dict[str, Callable[[], str]] = {
    "cli": cli_reference,
    "exit-codes": exit_codes,
    "stack-config": stack_config_reference,
    "scenario-config": scenario_reference,
    "sweep-config": sweep_reference,
    "adr-index": adr_index,
    **{f"sample:{name}": functools.partial(sample, name) for name in SAMPLES},
}


def render(markdown: str, where: str = "page") -> str:
    """Replace every ``<!-- generated: NAME -->`` line; an unknown NAME is an error."""

    def one(match: re.Match[str]) -> str:
        name = match.group(1)
        if name not in GENERATORS:
            raise ValueError(
                f"{where}: unknown generated block {name!r}; known: {list(GENERATORS)}"
            )
        return GENERATORS[name]().rstrip("\n")

    return MARKER.sub(one, markdown)


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    return render(markdown, where=str(page.file.src_uri))


if __name__ == "__main__":  # python scripts/docs_hooks.py NAME: print one block
    print(render(f"<!-- generated: {sys.argv[1]} -->", where="command line"))
