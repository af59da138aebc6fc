"""What users copy imports otonav through its public surface only (ADR 0056): every
``otonav`` import in ``examples/`` and in the docs' and README's Python blocks names a
public package and only what its ``__all__`` exports (or ``otonav.errors`` /
``otonav.limits``), never an implementation module. ``tests/`` and ``benchmarks/`` may
reach into internals: they test and measure them. And no module of the package cites
working notes that are not in the repository."""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import docs_hooks  # noqa: E402

PUBLIC_MODULES = ("otonav.errors", "otonav.limits", "otonav.params")
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
        ("from otonav.nav._navigate import Navigation", ["private"]),
        ("import otonav.runtime._mailbox", ["private"]),
        ("from otonav.stack import files", ["does not export"]),
        ("from otonav.hal.mujoco._lib import mujoco", ["private"]),
        ("async for x in y:\n    from otonav.record._writer import X", ["private"]),
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


def _walk() -> list[tuple[str, bool]]:
    """Every module of otonav, and whether it is a package."""
    import otonav

    return [(info.name, info.ispkg) for info in pkgutil.walk_packages(otonav.__path__, "otonav.")]


def stray_modules(walked: list[tuple[str, bool]]) -> list[str]:
    """The modules of ``walked`` that are neither a package nor one of PUBLIC_MODULES."""
    return [
        name
        for name, package in walked
        if not package
        and name not in PUBLIC_MODULES
        and not any(part.startswith("_") for part in name.split("."))
    ]


def test_a_module_named_without_an_underscore_is_public() -> None:
    """Issue 36: implementation modules carry private names (``_loop.py``), as trio's and
    httpx's do, so what a user can import without an underscore is the public API: a
    package (with its ``__all__``) or one of PUBLIC_MODULES."""
    stray = stray_modules(_walk())
    assert not stray, f"give these modules a private name (_module.py): {stray}"


def test_the_walk_finds_a_stray_public_module(tmp_path: Path) -> None:
    """The check can fail: a module file without an underscore next to a private one."""
    package = tmp_path / "pkg"
    package.mkdir()
    for name in ("__init__.py", "_private.py", "stray.py"):
        (package / name).write_text("")
    walked = [(i.name, i.ispkg) for i in pkgutil.walk_packages([str(package)], "pkg.")]
    assert stray_modules(walked) == ["pkg.stray"]


PACKAGES = [
    "otonav",
    *(name for name, package in _walk() if package and "._" not in name),
]


@pytest.mark.parametrize("package", PACKAGES)
def test_the_export_walk(package: str) -> None:
    """Every name a public package exports resolves, is public, and (a class or a
    function) is documented: what mkdocstrings renders as the API reference is the
    ``__all__`` of these packages."""
    module = importlib.import_module(package)
    exported = getattr(module, "__all__", None)
    assert exported is not None, f"{package} has no __all__"
    problems = []
    for name in exported:
        if name.startswith("_") and not (name.startswith("__") and name.endswith("__")):
            problems.append(f"{name} is private")
            continue
        try:
            value = getattr(module, name)
        except (AttributeError, ImportError) as exc:
            problems.append(f"{name} does not resolve: {exc}")
            continue
        documented = inspect.isclass(value) or inspect.isfunction(value)
        if documented and not (value.__doc__ or "").strip():
            problems.append(f"{name} has no docstring")
    assert not problems, f"{package}: {problems}"
