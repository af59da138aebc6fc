"""Layer 0: no module reaches into pydantic's internals (issue 36; ADR 0086). A message
built without validation gets its state through ``BaseModel.__setstate__`` (the pickle
protocol) in ``otonav/msgs/_base.py`` and the CDR decoder it generates; nothing reads or
writes BaseModel's slots (``m.__pydantic_fields_set__``, ``BaseModel.__dict__[...]``)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
HOOKS = {"__pydantic_init_subclass__"}  # pydantic's documented class hook


def _reaches(path: Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if (
            isinstance(node, ast.Attribute)
            and node.attr.startswith("__pydantic_")
            and node.attr not in HOOKS
        ):
            found.append(f"{path.relative_to(ROOT)}:{node.lineno}: .{node.attr}")
        elif (
            isinstance(node, ast.Attribute)
            and node.attr == "__dict__"
            and isinstance(node.value, ast.Name)
            and node.value.id == "BaseModel"
        ):
            found.append(f"{path.relative_to(ROOT)}:{node.lineno}: BaseModel.__dict__")
        elif isinstance(node, ast.Call) and any(
            isinstance(a, ast.Constant) and str(a.value).startswith("__pydantic_")
            for a in node.args
        ):  # getattr(m, "__pydantic_extra__"), object.__getattribute__(m, "__pydantic_...")
            found.append(f"{path.relative_to(ROOT)}:{node.lineno}: a pydantic slot by name")
    return found


@pytest.mark.parametrize("package", ["otonav", "benchmarks", "examples"])
def test_no_module_reaches_into_pydantic(package: str) -> None:
    exempt = {ROOT / "benchmarks" / "message_bench.py"}  # measures the old way, on purpose
    found = [
        line
        for path in sorted((ROOT / package).rglob("*.py"))
        if path not in exempt
        for line in _reaches(path)
    ]
    assert not found, "\n".join(found)
