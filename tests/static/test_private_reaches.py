"""Layer 0: no module but ``otonav/runtime/_asyncio_compat.py`` touches a private name of
asyncio or anyio (issue 31, item 6; ADR 0055).

Private names change between CPython and anyio releases without notice; the one module
allowed to use them pins each with a test (tests/unit/runtime/test_asyncio_compat.py).
An AST walk of every module outside tests/ (otonav, examples, benchmarks, scripts) finds:

1. imports of a private module or name (``import anyio._backends._asyncio``,
   ``from asyncio.base_events import _MIN_...``);
2. a private attribute reached from an asyncio/anyio module or from anything imported
   from one (``base_events._MIN_SCHEDULED_TIMER_HANDLES``, ``asyncio.Task._step``);
3. a string naming a private module (``importlib.import_module("anyio._backends...")``);
4. in a class derived from an asyncio/anyio class, ``self._x`` or ``def _x`` where the
   library defines ``_x`` (``_run_once``, ``self._ready``);
5. anywhere, ``obj._x`` where asyncio/anyio define ``_x`` on their objects and the module
   does not define an ``_x`` of its own (``loop._scheduled``, ``handle._when``).
"""

from __future__ import annotations

import ast
import contextlib
import importlib
import importlib.util
import inspect
import re
from functools import cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LIBS = ("asyncio", "anyio")
COMPAT = "otonav/runtime/_asyncio_compat.py"
NOT_THE_LIBRARYS = {
    # (module, name): rule 5 matches by name; these objects are another library's.
    ("otonav/record/_fastwriter.py", "_buffer"): "mcap's Writer, whose chunk buffer it is",
}
PRIVATE_MODULE_STRING = re.compile(r"(asyncio|anyio)(\.\w+)*\._[A-Za-z]\w*(\.\w+)*")


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _is_lib(module: str) -> bool:
    return module.split(".")[0] in LIBS


def _defined_names(tree: ast.AST) -> set[str]:
    """Private names a source defines: ``self._x = ...``, ``def _x``, class-level
    ``_x = ...``, ``__slots__`` entries."""
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            names.add(node.name)
        elif isinstance(node, ast.ClassDef):
            for item in node.body:
                if not isinstance(item, ast.Assign | ast.AnnAssign):
                    continue
                targets = item.targets if isinstance(item, ast.Assign) else [item.target]
                for target in targets:
                    if isinstance(target, ast.Name):
                        names.add(target.id)
                        if target.id == "__slots__" and item.value is not None:
                            names.update(
                                c.value
                                for c in ast.walk(item.value)
                                if isinstance(c, ast.Constant) and isinstance(c.value, str)
                            )
    return {n for n in names if _private(n)}


@cache
def library_private_names() -> frozenset[str]:
    """Every private name asyncio and anyio define on their classes and objects."""
    names: set[str] = set()
    for lib in LIBS:
        spec = importlib.util.find_spec(lib)
        assert spec is not None
        assert spec.submodule_search_locations is not None
        for location in spec.submodule_search_locations:
            for path in Path(location).rglob("*.py"):
                names |= _defined_names(ast.parse(path.read_text(encoding="utf-8")))
    return frozenset(names)


def _lib_bindings(tree: ast.AST) -> set[str]:
    """Local names bound to an asyncio/anyio module or to something imported from one."""
    bound: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if _is_lib(alias.name):
                    bound.add(alias.asname or alias.name.split(".")[0])
        elif isinstance(node, ast.ImportFrom) and node.module and _is_lib(node.module):
            bound.update(alias.asname or alias.name for alias in node.names)
    return bound


def _root(node: ast.expr) -> str | None:
    while isinstance(node, ast.Attribute):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


def _derives_from_lib(cls: ast.ClassDef, bound: set[str], runtime: object | None) -> bool:
    if any(_root(base) in bound for base in cls.bases):
        return True
    if isinstance(runtime, type):
        return any(_is_lib(k.__module__) for k in inspect.getmro(runtime)[1:])
    return False


def private_reaches(source: str, module: object | None = None, path: str = "") -> list[str]:
    """What ``source`` touches of asyncio's and anyio's private names, one line each.
    ``module``: the imported module, to see classes derived through otonav's own."""
    tree = ast.parse(source)
    bound = _lib_bindings(tree)
    # `import os` then `os._exit(...)`: another module's own name, not the library's
    other_modules = {
        alias.asname or alias.name.split(".")[0]
        for node in ast.walk(tree)
        if isinstance(node, ast.Import)
        for alias in node.names
        if not _is_lib(alias.name)
    }
    lib_names = library_private_names()
    own = _defined_names(tree)
    found: list[str] = []

    def say(node: ast.AST, what: str) -> None:
        found.append(f"line {getattr(node, 'lineno', '?')}: {what}")

    derived: set[int] = set()  # ids of attribute nodes inside lib-derived classes
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if _is_lib(alias.name) and any(_private(p) for p in alias.name.split(".")):
                    say(node, f"import {alias.name}")
        elif isinstance(node, ast.ImportFrom) and node.module and _is_lib(node.module):
            if any(_private(p) for p in node.module.split(".")):
                say(node, f"from {node.module} import ...")
            for alias in node.names:
                if _private(alias.name):
                    say(node, f"from {node.module} import {alias.name}")
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            if PRIVATE_MODULE_STRING.fullmatch(node.value):
                say(node, f"the private module {node.value!r}")
        elif isinstance(node, ast.ClassDef):
            runtime = getattr(module, node.name, None) if module is not None else None
            if not _derives_from_lib(node, bound, runtime):
                continue
            for inner in ast.walk(node):
                if isinstance(inner, ast.FunctionDef | ast.AsyncFunctionDef):
                    if inner.name in lib_names:
                        say(inner, f"{node.name} overrides the library's {inner.name}")
                elif (
                    isinstance(inner, ast.Attribute)
                    and isinstance(inner.value, ast.Name)
                    and inner.value.id in ("self", "cls", "this")
                    and inner.attr in lib_names
                ):
                    derived.add(id(inner))
                    say(inner, f"{node.name}: self.{inner.attr} is the library's")
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id in ("getattr", "hasattr", "setattr")
            and len(node.args) >= 2
            and isinstance(node.args[1], ast.Constant)
            and isinstance(node.args[1].value, str)
            and _private(node.args[1].value)
        ):
            # getattr(obj, "_x"): the same reach, spelled as a string
            target = node.args[0]
            if _root(target) in bound or (
                node.args[1].value in lib_names and node.args[1].value not in own
            ):
                say(node, f"{ast.unparse(node)}: a private name of asyncio/anyio")
    for node in ast.walk(tree):
        if not isinstance(node, ast.Attribute) or not _private(node.attr) or id(node) in derived:
            continue
        root = _root(node.value)
        if root in bound:
            say(node, f"{ast.unparse(node)}: a private name of {root}")
        elif (
            node.attr in lib_names
            and node.attr not in own
            and root not in other_modules
            # self._x: inherited from otonav's own base (a lib-derived class: rule 4)
            and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))
            and (path, node.attr) not in NOT_THE_LIBRARYS
        ):
            say(node, f"{ast.unparse(node)}: {node.attr} is a private name of asyncio/anyio")
    return sorted(set(found))


SCANNED = ("otonav", "examples", "benchmarks", "scripts")
"""Everything but tests/ (the compat module's own tests reach in on purpose)."""


def _modules() -> list[str]:
    return sorted(
        p.relative_to(ROOT).as_posix()
        for top in SCANNED
        for p in (ROOT / top).rglob("*.py")
        if p.relative_to(ROOT).as_posix() != COMPAT
    )


@pytest.mark.parametrize("path", _modules())
def test_no_module_touches_a_private_name_of_asyncio_or_anyio(path: str) -> None:
    name = path.removesuffix(".py").removesuffix("/__init__").replace("/", ".")
    module: object | None = None
    if path.startswith("otonav/") and not name.endswith("__main__"):  # __main__ runs the CLI
        # an optional extra that is not installed: the AST alone
        with contextlib.suppress(ImportError):
            module = importlib.import_module(name)
    found = private_reaches((ROOT / path).read_text(encoding="utf-8"), module, path)
    assert not found, (
        f"{path} touches private names of asyncio/anyio ({'; '.join(found)}): put the "
        f"reach in {COMPAT}, behind a public function or method, with a test in "
        "tests/unit/runtime/test_asyncio_compat.py that fails when the library changes it"
    )


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("import anyio._backends._asyncio", "import anyio._backends._asyncio"),
        ("from asyncio.base_events import _MIN_SCHEDULED_TIMER_HANDLES as m", "import _MIN"),
        (
            "from asyncio import base_events\nx = base_events._MIN_SCHEDULED_TIMER_HANDLES",
            "private name of base_events",
        ),
        ("import asyncio\nasyncio.tasks._PyTask", "private name of asyncio"),
        ("import importlib\nimportlib.import_module('anyio._backends._asyncio')", "private"),
        (
            "import asyncio\nclass L(asyncio.SelectorEventLoop):\n"
            "    def _run_once(self):\n        pass",
            "overrides the library's _run_once",
        ),
        (
            "import asyncio\nclass L(asyncio.SelectorEventLoop):\n"
            "    def go(self):\n        return self._ready",
            "self._ready is the library's",
        ),
        ("def f(loop):\n    return loop._scheduled[0]._when", "_when is a private name"),
        ("def f(s):\n    return len(s._queue) >= s._depth", "_queue is a private name"),
        ("class F:\n    def f(self):\n        return self._loop._ready", "_ready is a private"),
        (
            "from asyncio import base_events\ngetattr(base_events, '_MIN_SCHEDULED_TIMER_HANDLES')",
            "a private name of asyncio/anyio",
        ),
    ],
)
def test_the_walk_finds_each_kind_of_reach(source: str, expected: str) -> None:
    found = private_reaches(source)
    assert any(expected in line for line in found), found


def test_the_walk_leaves_public_use_and_own_privates_alone() -> None:
    source = (
        "import asyncio\nimport anyio\nfrom anyio.abc import TaskGroup\n"
        "class Q:\n    def __init__(self):\n        self._queue = []\n"
        "    def n(self):\n        return len(self._queue)\n"
        "async def f(tg: TaskGroup):\n    await anyio.sleep(0)\n"
        "    asyncio.get_running_loop().call_soon(print)\n    return asyncio.Handle.__slots__\n"
    )
    assert private_reaches(source) == []


def test_another_modules_private_looking_name_is_its_own() -> None:
    # os._exit is os's documented function, though asyncio defines an _exit too
    assert private_reaches("import os\nos._exit(0)\n") == []
    assert private_reaches("import asyncio\nasyncio.events._exit\n") != []


def test_the_compat_module_is_where_the_reaches_are() -> None:
    """The check sees the real ones: the compat module is full of them."""
    found = " ".join(private_reaches((ROOT / COMPAT).read_text(encoding="utf-8")))
    for name in ("_run_once", "'_MIN_SCHEDULED_TIMER_HANDLES'", "anyio._backends"):
        assert name in found
