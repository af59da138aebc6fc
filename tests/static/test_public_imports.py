"""What users copy imports otonav through its public surface only (ADR 0056): every
``otonav`` import in ``examples/`` and in the docs' and README's Python blocks names a
public package and only what its ``__all__`` exports (or ``otonav.errors`` /
``otonav.limits``), never an implementation module. ``tests/`` and ``benchmarks/`` may
reach into internals: they test and measure them. And no module of the package cites
working notes that are not in the repository."""

from __future__ import annotations

import ast
import importlib
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import docs_hooks  # noqa: E402

PUBLIC_MODULES = ("otonav.errors", "otonav.limits")
"""Top-level modules that are public as they are (no package around them)."""

SOURCES: dict[str, str] = {
    **{
        str(path.relative_to(ROOT)): path.read_text()
        for path in sorted((ROOT / "examples").rglob("*.py"))
    },
    **{
        f"{path.relative_to(ROOT)} block {i}": body
        for i, (path, body) in enumerate(docs_hooks.code_blocks("python"))
        if not docs_hooks.included_file(body)  # an included file is one of examples/
    },
}


def _parse(text: str) -> ast.AST:
    flags = ast.PyCF_ONLY_AST | ast.PyCF_ALLOW_TOP_LEVEL_AWAIT  # notebook-style cells
    tree: ast.AST = compile(text, "<source>", "exec", flags=flags)
    return tree


def reaches(text: str) -> list[str]:
    """The ``otonav`` imports in ``text`` that go past the public surface."""
    found = []
    for node in ast.walk(_parse(text)):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            targets = [(node.module, [a.name for a in node.names])]
        elif isinstance(node, ast.Import):
            targets = [(a.name, []) for a in node.names]
        else:
            continue
        for module, names in targets:
            if module == "otonav" or module.startswith("otonav."):
                problem = _problem(module, names)
                if problem:
                    found.append(f"line {node.lineno}: {problem}")
    return found


def _problem(module: str, names: list[str]) -> str | None:
    if any(part.startswith("_") for part in module.split(".")):
        return f"{module} is private"
    imported = importlib.import_module(module)
    if module in PUBLIC_MODULES:
        private = [n for n in names if n.startswith("_")]
        return f"{module}: {private} are private" if private else None
    if not hasattr(imported, "__path__"):
        return f"{module} is an implementation module: import from its package"
    unexported = [n for n in names if n not in getattr(imported, "__all__", ())]
    return f"{module} does not export {unexported}" if unexported else None


@pytest.mark.parametrize("source", sorted(SOURCES))
def test_examples_and_docs_import_only_the_public_api(source: str) -> None:
    found = reaches(SOURCES[source])
    assert not found, f"{source} reaches past otonav's public API: {found}"


@pytest.mark.parametrize(
    ("code", "expected"),
    [
        ("from otonav.nav import Navigation", []),
        ("from otonav.errors import UsageError", []),
        ("from otonav.nav.navigate import Navigation", ["implementation module"]),
        ("import otonav.runtime.mailbox", ["implementation module"]),
        ("from otonav.stack import files", ["does not export"]),
        ("from otonav.hal.mujoco._lib import mujoco", ["private"]),
        ("async for x in y:\n    from otonav.record.writer import X", ["implementation"]),
    ],
)
def test_the_check_tells_a_reach_from_a_public_import(code: str, expected: list[str]) -> None:
    found = reaches(code)
    assert len(found) == len(expected)
    assert all(e in f for e, f in zip(expected, found, strict=True))


def test_no_module_cites_notes_outside_the_repository() -> None:
    """Working notes (``notes/*.md``) are not shipped: the code cites ADRs and docs."""
    citing = [
        str(path.relative_to(ROOT))
        for path in sorted((ROOT / "otonav").rglob("*"))
        if path.suffix in (".py", ".xml", ".yaml", ".toml", ".md")
        and "notes/" in path.read_text(errors="replace")
    ]
    assert not citing, f"cite an ADR or a docs page instead of notes/: {citing}"
