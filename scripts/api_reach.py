"""How far the repository's own code reaches past otonav's public API (ADR 0056).

    python scripts/api_reach.py [ROOT]

Counts the ``otonav`` import lines of ``tests/``, ``examples/``, ``benchmarks/`` and the
Python blocks of the README and the docs (ADRs aside) by area: all of them, those into an
implementation module (a module that is not a public package, nor ``otonav.errors`` or
``otonav.limits``), and of those, how many take only names the enclosing public package
exports (they could import from it). ``ROOT``'s own ``otonav`` is imported.
"""

from __future__ import annotations

import ast
import importlib
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

PUBLIC_MODULES = ("otonav.errors", "otonav.limits")
BLOCK = re.compile(r"```python\n(.*?)```", re.S)


def sources(root: Path) -> Iterator[tuple[str, str]]:
    for area in ("tests", "examples", "benchmarks"):
        for path in sorted((root / area).rglob("*.py")):
            yield area, path.read_text()
    for page in [root / "README.md", *sorted((root / "docs").rglob("*.md"))]:
        if "adr" not in page.parts:
            for block in BLOCK.findall(page.read_text()):
                yield "docs", block


def public_package(module: str) -> ModuleType | None:
    parts = module.split(".")
    while parts:
        found = importlib.import_module(".".join(parts))
        if hasattr(found, "__path__") and not any(p.startswith("_") for p in parts):
            return found
        parts.pop()
    return None


def imports(text: str) -> Iterator[tuple[str, list[str]]]:
    flags = ast.PyCF_ONLY_AST | ast.PyCF_ALLOW_TOP_LEVEL_AWAIT
    try:
        tree = compile(text, "<source>", "exec", flags=flags)
    except SyntaxError:
        return
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.module, [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, []


def main(root: Path) -> None:
    sys.path.insert(0, str(root))
    counts: dict[str, list[int]] = {}
    for area, text in sources(root):
        for module, names in imports(text):
            if module != "otonav" and not module.startswith("otonav."):
                continue
            row = counts.setdefault(area, [0, 0, 0])
            row[0] += 1
            if hasattr(importlib.import_module(module), "__path__") or module in PUBLIC_MODULES:
                continue
            row[1] += 1
            package = public_package(module)
            exported = getattr(package, "__all__", ())
            if names and all(n in exported for n in names):
                row[2] += 1
    for area, (total, reaching, could) in sorted(counts.items()):
        print(
            f"{area:10s} import lines {total:4d}, into implementation modules {reaching:4d} "
            f"(the package exports every name taken: {could})"
        )


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve())
