"""AST mutation testing of the pure navigation math against the unit layer (issue 24).

    python scripts/mutation.py [MODULE ...] [--list] [--timeout S] [--show-survivors]
                               [--ids ID,...] [--tests FILE ...]

Each mutant changes one node of one module's syntax tree:

* arithmetic: ``+ <-> -``, ``* <-> /``, ``** -> *``, ``// -> /``, ``% -> //``;
* comparisons: ``< <-> <=``, ``> <-> >=``, ``== <-> !=``, ``is <-> is not``,
  ``in <-> not in``;
* boolean ``and <-> or``, ``not x -> x``, unary ``-x -> x``;
* numbers: ``0 -> 1``, ``1 -> 0``, any other ``c -> c + 1``; ``True <-> False``;
* ``min <-> max`` calls.

Docstrings and ``__all__`` are not mutated (their strings are not numbers);
neither are type annotations (they do not run).

A mutant is *killed* when its module's unit tests (the table ``TARGETS``) fail on
it or run out of ``--timeout`` seconds (a mutated loop that never ends). Each
mutant runs in a child forked from a parent that has imported numpy, pytest and
hypothesis once; the child compiles the mutated source into ``sys.modules`` before
anything imports the module, then runs pytest in-process with ``-x`` (the first
failure kills). Prints the kill rate per module and in total; exit 0 (a report, not
a gate: ``make mutation``).

Every mutant has a stable id: 8 hex digits of a hash of its module, the function or
class it is in, the mutated expression's source, the change and its rank among
identical ones there (line numbers move when code is added above; the id does not).
``--list`` prints them; ``--ids`` runs only those mutants; ``--tests`` replaces the
module's test files (``TARGETS``) for one run.

Equivalent mutants (same behaviour as the original for every input) are listed, each
with the one-line reason a reviewer accepted, in ``scripts/mutation_equivalent.txt``.
They are never dropped silently: the raw rate counts them as survivors, they are
printed on their own lines with their reason, and a second rate is printed over the
mutants not listed. A listed mutant that is killed, or whose id no longer exists, is
reported as a stale entry.

Why not mutmut or cosmic-ray (both on PyPI): mutmut 3 copies the tree into
``mutants/`` and trampolines every function, which numpy-vectorised code and
slotted dataclasses resist; cosmic-ray starts the test command once per mutant (~1.5
s of imports each here). A fork per mutant after the imports costs ~0.1 s (ADR 0054).
"""

from __future__ import annotations

import argparse
import ast
import hashlib
import os
import signal
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from types import CodeType

ROOT = Path(__file__).resolve().parent.parent

TARGETS: dict[str, tuple[str, ...]] = {
    "otonav.nav._safety": (
        "tests/unit/test_safety_limit.py",
        "tests/unit/test_safety_reference.py",
        "tests/unit/test_safety_properties.py",
    ),
    "otonav.nav._dwa": (
        "tests/unit/test_nav_planning.py",
        "tests/unit/test_dwa_reference.py",
        "tests/unit/test_dwa_documented.py",
    ),
    "otonav.nav._global_path": (
        "tests/unit/test_nav_planning.py",
        "tests/unit/test_nav_indoor.py",
        "tests/unit/test_nav_search.py",
        "tests/unit/test_astar_contract.py",
    ),
    "otonav.nav._plan_grid": (
        "tests/unit/test_nav_indoor.py",
        "tests/unit/test_nav_search.py",
        "tests/unit/test_plan_grid_contract.py",
    ),
    "otonav.nav._recovery": (
        "tests/unit/test_nav_planning.py",
        "tests/unit/test_nav_indoor.py",
        "tests/unit/test_recovery_reference.py",
    ),
    "otonav.nav._scan_match": (
        "tests/unit/test_scan_match.py",
        "tests/unit/test_scan_match_reference.py",
        "tests/unit/test_scan_match_documented.py",
        "tests/unit/test_localizer.py",
    ),
    "otonav.nav._scan_map": (
        "tests/unit/test_scan_match.py",
        "tests/unit/test_scan_map_reference.py",
        "tests/unit/test_localizer.py",
    ),
}
"""Module -> the unit test files that pin it (files that do not exist are skipped)."""

EQUIVALENT = ROOT / "scripts" / "mutation_equivalent.txt"
"""Reviewed equivalent mutants: ``module id reason`` per line, ``#`` comments."""

_DESELECT = "not imports_nothing_more"
"""Tests that start a subprocess (the mutant is not in it): skipped."""

_BINOP = {
    ast.Add: ast.Sub,
    ast.Sub: ast.Add,
    ast.Mult: ast.Div,
    ast.Div: ast.Mult,
    ast.Pow: ast.Mult,
    ast.FloorDiv: ast.Div,
    ast.Mod: ast.FloorDiv,
}
_CMPOP = {
    ast.Lt: ast.LtE,
    ast.LtE: ast.Lt,
    ast.Gt: ast.GtE,
    ast.GtE: ast.Gt,
    ast.Eq: ast.NotEq,
    ast.NotEq: ast.Eq,
    ast.Is: ast.IsNot,
    ast.IsNot: ast.Is,
    ast.In: ast.NotIn,
    ast.NotIn: ast.In,
}


@dataclass(frozen=True, slots=True)
class Mutant:
    module: str
    index: int
    line: int
    what: str
    id: str
    """Stable id (module docstring)."""
    where: str
    """The enclosing function or class (dotted), and the mutated expression's source."""
    context: str = ""
    """The expression around a short one (a number's, a comparison's), for reading."""


def _skipped(tree: ast.Module) -> set[int]:
    """ids of nodes not to mutate: annotations, docstrings, ``__all__``."""
    skip: set[int] = set()
    for node in ast.walk(tree):
        annotations: list[ast.AST | None] = []
        if isinstance(node, ast.AnnAssign):
            annotations.append(node.annotation)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            annotations.append(node.returns)
            args = node.args
            for arg in (*args.posonlyargs, *args.args, *args.kwonlyargs, args.vararg, args.kwarg):
                if arg is not None:
                    annotations.append(arg.annotation)
        elif isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id in ("__all__",) for t in node.targets
        ):
            annotations.append(node)
        for a in annotations:
            if a is not None:
                skip.update(id(n) for n in ast.walk(a))
    return skip


def _sites(tree: ast.Module) -> Iterator[tuple[ast.AST, str, int]]:
    """(node, description, variant) for every mutation of ``tree``, in a fixed order."""
    skip = _skipped(tree)
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.BinOp) and type(node.op) in _BINOP:
            yield node, f"{type(node.op).__name__} -> {_BINOP[type(node.op)].__name__}", 0
        elif isinstance(node, ast.Compare):
            for k, op in enumerate(node.ops):
                if type(op) in _CMPOP:
                    yield node, f"{type(op).__name__} -> {_CMPOP[type(op)].__name__}", k
        elif isinstance(node, ast.BoolOp):
            yield (
                node,
                f"{type(node.op).__name__} -> {'Or' if isinstance(node.op, ast.And) else 'And'}",
                0,
            )
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.Not, ast.USub)):
            yield node, f"drop {type(node.op).__name__}", 0
        elif isinstance(node, ast.Constant):
            if isinstance(node.value, bool):
                yield node, f"{node.value} -> {not node.value}", 0
            elif isinstance(node.value, (int, float)):
                yield node, f"{node.value!r} -> {_number(node.value)!r}", 0
        elif (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id in ("min", "max")
        ):
            yield node, f"{node.func.id} -> {'max' if node.func.id == 'min' else 'min'}", 0


def _number(value: float) -> float:
    if value == 0:
        return type(value)(1)
    if value == 1:
        return type(value)(0)
    return value + 1


def _apply(node: ast.AST, variant: int) -> None:
    if isinstance(node, ast.BinOp):
        node.op = _BINOP[type(node.op)]()
    elif isinstance(node, ast.Compare):
        ops = list(node.ops)
        ops[variant] = _CMPOP[type(ops[variant])]()
        node.ops = ops
    elif isinstance(node, ast.BoolOp):
        node.op = ast.Or() if isinstance(node.op, ast.And) else ast.And()
    elif isinstance(node, ast.Constant):
        value = node.value
        if isinstance(value, bool):
            node.value = not value
        elif isinstance(value, (int, float)):
            node.value = _number(value)
    elif isinstance(node, ast.Call):
        assert isinstance(node.func, ast.Name)
        node.func.id = "max" if node.func.id == "min" else "min"


def _drop_unary(tree: ast.Module, target: ast.UnaryOp) -> None:
    class Drop(ast.NodeTransformer):
        def visit_UnaryOp(self, node: ast.UnaryOp) -> ast.AST:
            self.generic_visit(node)
            return node.operand if node is target else node

    Drop().visit(tree)


def _scopes(tree: ast.Module) -> tuple[dict[int, str], dict[int, ast.AST]]:
    """id(node) -> the dotted name of the innermost function or class holding it, and
    id(node) -> its parent node."""
    scope: dict[int, str] = {}
    parent: dict[int, ast.AST] = {}

    def walk(node: ast.AST, name: str) -> None:
        for child in ast.iter_child_nodes(node):
            inner = name
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                inner = f"{name}.{child.name}" if name else child.name
            scope[id(child)] = inner
            parent[id(child)] = node
            walk(child, inner)

    walk(tree, "")
    return scope, parent


def mutants(module: str) -> tuple[str, list[Mutant]]:
    path = ROOT / (module.replace(".", "/") + ".py")
    source = path.read_text()
    tree = ast.parse(source)
    scope, parent = _scopes(tree)
    seen: dict[str, int] = {}
    found = []
    for i, (node, what, variant) in enumerate(_sites(tree)):
        text = ast.unparse(node)
        where = f"{scope.get(id(node)) or '<module>'}: {text}"
        key = f"{module}|{where}|{what}|{variant}"
        rank = seen.get(key, 0)
        seen[key] = rank + 1
        digest = hashlib.sha256(f"{key}|{rank}".encode()).hexdigest()[:8]
        around = parent.get(id(node))
        context = ""
        if len(text) < 16 and around is not None and not isinstance(around, ast.stmt):
            context = ast.unparse(around)
        elif len(text) < 16 and isinstance(around, (ast.Assign, ast.AnnAssign, ast.Return)):
            context = ast.unparse(around).splitlines()[0]
        line = getattr(node, "lineno", 0)
        found.append(Mutant(module, i, line, what, digest, where, context))
    return source, found


def equivalent_list(path: Path = EQUIVALENT) -> dict[tuple[str, str], str]:
    """(module, id) -> reason, from the reviewed list (module docstring)."""
    listed: dict[tuple[str, str], str] = {}
    if not path.exists():
        return listed
    for number, raw in enumerate(path.read_text().splitlines(), 1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        parts = line.split(None, 2)
        if len(parts) < 3:
            raise SystemExit(f"{path}:{number}: want 'module id reason', got {raw!r}")
        listed[(parts[0], parts[1])] = parts[2]
    return listed


def _short(text: str, width: int = 70) -> str:
    return text if len(text) <= width else text[: width - 3] + "..."


def _show(m: Mutant) -> str:
    around = f" (in {_short(m.context, 60)})" if m.context else ""
    return f"line {m.line}: {m.what} in {_short(m.where)}{around}"


def mutated_code(module: str, source: str, index: int) -> CodeType:
    tree = ast.parse(source)
    for i, (node, _what, variant) in enumerate(_sites(tree)):
        if i == index:
            if isinstance(node, ast.UnaryOp):
                _drop_unary(tree, node)
            else:
                _apply(node, variant)
            break
    ast.fix_missing_locations(tree)
    path = ROOT / (module.replace(".", "/") + ".py")
    return compile(tree, str(path), "exec")


def _run_child(module: str, code: CodeType, tests: list[str]) -> int:
    import importlib.util

    import pytest

    spec = importlib.util.find_spec(module)
    assert spec is not None
    assert spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[module] = mod
    exec(code, mod.__dict__)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    args = [*tests, "-x", "-q", "-p", "no:cacheprovider", "-k", _DESELECT]
    # (otonav is imported already, to hold the mutant: its plugin is not rewritten)
    args += ["-W", "ignore::pytest.PytestAssertRewriteWarning"]
    return int(pytest.main(args))


def run_mutant(module: str, code: CodeType, tests: list[str], timeout: float) -> str:
    """``killed``, ``timeout`` or ``survived``."""
    pid = os.fork()
    if pid == 0:  # child
        try:
            status = _run_child(module, code, tests)
        except BaseException:  # a mutant that breaks at import is killed
            status = 99
        os._exit(status)
    deadline = time.monotonic() + timeout
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            code_ = os.waitstatus_to_exitcode(status)
            return "survived" if code_ == 0 else "killed"
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return "timeout"
        time.sleep(0.02)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("modules", nargs="*", default=list(TARGETS))
    parser.add_argument("--list", action="store_true", help="list the mutants only")
    parser.add_argument("--timeout", type=float, default=60.0)
    parser.add_argument("--show-survivors", action="store_true")
    parser.add_argument("--ids", default="", help="comma-separated mutant ids: run only these")
    parser.add_argument("--tests", nargs="+", help="test files instead of the module's TARGETS")
    args = parser.parse_args()
    unknown = [m for m in args.modules if m not in TARGETS]
    if unknown:
        print(f"modules: {unknown} not valid ({', '.join(TARGETS)})", file=sys.stderr)
        return 2
    os.chdir(ROOT)
    import hypothesis  # (imported once, before the forks)
    import numpy  # noqa: F401
    import pytest  # noqa: F401

    # No example database (a failure found on one mutant must not be replayed on the
    # next) and no deadline (a slow shared machine is not a kill); derandomized, so a
    # run is repeatable. Tests' own @settings still override these defaults.
    hypothesis.settings.register_profile("mutation", database=None, deadline=None, derandomize=True)
    hypothesis.settings.load_profile("mutation")

    listed = equivalent_list()
    wanted = {i for i in args.ids.split(",") if i}
    total_killed = total = total_equivalent = 0
    started = time.monotonic()
    for module in args.modules:
        source, found = mutants(module)
        ids = {m.id for m in found}
        for mod, mid in sorted(listed):
            if mod == module and mid not in ids:
                print(f"  stale: {mod} {mid} is listed equivalent but no longer a mutant")
        if wanted:
            found = [m for m in found if m.id in wanted]
        tests = [t for t in (args.tests or TARGETS[module]) if (ROOT / t).exists()]
        if args.list:
            for m in found:
                mark = "  [equivalent]" if (module, m.id) in listed else ""
                print(f"{m.module} {m.id} {_show(m)}{mark}")
            continue
        path = ROOT / (module.replace(".", "/") + ".py")
        clean = run_mutant(module, compile(source, str(path), "exec"), tests, args.timeout)
        if clean != "survived":  # the unmutated module must pass, or nothing is measured
            print(f"{module}: its tests fail without a mutant ({clean})", file=sys.stderr)
            return 1
        survivors: list[Mutant] = []
        killed = 0
        for m in found:
            outcome = run_mutant(module, mutated_code(module, source, m.index), tests, args.timeout)
            if outcome == "survived":
                survivors.append(m)
            else:
                killed += 1
                if (module, m.id) in listed:
                    print(f"  stale: {module} {m.id} is listed equivalent but was killed")
        equivalent = [m for m in survivors if (module, m.id) in listed]
        rest = [m for m in survivors if (module, m.id) not in listed]
        total_killed += killed
        total += len(found)
        total_equivalent += len(equivalent)
        print(
            f"{module}: {killed}/{len(found)} mutants killed ({_pct(killed, len(found))}) "
            f"by {' '.join(tests)}; {len(equivalent)} survivors listed equivalent; "
            f"{killed}/{len(found) - len(equivalent)} of the rest killed "
            f"({_pct(killed, len(found) - len(equivalent))})"
        )
        if args.show_survivors:
            for m in equivalent:
                why = listed[(module, m.id)]
                print(f"  equivalent: {m.id} {_show(m)}\n      why: {why}")
            for m in rest:
                print(f"  survived:   {m.id} {_show(m)}")
        sys.stdout.flush()
    if total and not args.list:
        print(
            f"total: {total_killed}/{total} killed ({_pct(total_killed, total)}); "
            f"{total_equivalent} listed equivalent; {total_killed}/{total - total_equivalent} "
            f"of the rest ({_pct(total_killed, total - total_equivalent)}), "
            f"{time.monotonic() - started:.0f} s"
        )
    return 0


def _pct(part: int, whole: int) -> str:
    return f"{100.0 * part / whole:.1f} %" if whole else "-"


if __name__ == "__main__":
    sys.exit(main())
