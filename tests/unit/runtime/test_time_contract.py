"""One time contract (ADR 0055): the actors' ``Clock`` with its two implementations, one
catch-up cap written once, and the names it replaced kept working with a warning."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from otonav.runtime import (
    MAX_STEP_BATCH,
    Clock,
    JumpSource,
    RealTimeClock,
    VirtualClock,
    VirtualTimeLoop,
)

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parents[3]


def test_both_modes_implement_the_one_clock_contract() -> None:
    loop = VirtualTimeLoop()
    try:
        assert isinstance(VirtualClock(loop), Clock)
    finally:
        loop.close()
    assert isinstance(RealTimeClock(JumpSource(0.002)), Clock)


def test_a_real_time_clock_caps_one_advance_at_max_step_batch_by_default() -> None:
    clock = RealTimeClock(JumpSource(0.002))
    assert clock.max_batch_ticks == round(MAX_STEP_BATCH / 0.002) == 25
    assert RealTimeClock(JumpSource(0.002), max_step_batch=None).max_batch_ticks is None


def _batch_literals(source: str, where: str) -> list[str]:
    """``max_step_batch`` given a number (a keyword, a default, a field) in ``source``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.keyword) and node.arg == "max_step_batch":
            values = [node.value]
        elif isinstance(node, ast.arguments):
            args = [*node.posonlyargs, *node.args]
            pairs = list(zip(args[len(args) - len(node.defaults) :], node.defaults, strict=True))
            pairs += [(a, d) for a, d in zip(node.kwonlyargs, node.kw_defaults, strict=True) if d]
            values = [d for a, d in pairs if a.arg == "max_step_batch"]
        elif (
            isinstance(node, ast.AnnAssign)
            and isinstance(node.target, ast.Name)
            and node.target.id == "max_step_batch"
            and node.value is not None
        ):
            values = [node.value]
        else:
            continue
        found += [
            f"{where}:{v.lineno}"
            for v in values
            if isinstance(v, ast.Constant) and isinstance(v.value, int | float)
        ]
    return found


def test_the_catch_up_cap_is_written_once() -> None:
    """Four modules wrote max_step_batch=0.05 (issue 31): every default is the constant."""
    found = [
        hit
        for top in ("otonav", "examples", "benchmarks")
        for path in sorted((ROOT / top).rglob("*.py"))
        for hit in _batch_literals(path.read_text(encoding="utf-8"), str(path.relative_to(ROOT)))
    ]
    assert not found, f"max_step_batch given as a number, not MAX_STEP_BATCH: {found}"


def test_the_cap_check_sees_each_way_of_writing_a_literal() -> None:
    source = "\n".join(
        [
            "def f(max_step_batch: float = 0.05): ...",
            "def g(*, max_step_batch=0.05): ...",
            "RealTimeClock(s, max_step_batch=0.05)",
            "class R:",
            "    max_step_batch: float = 0.05",
            "def h(max_step_batch=MAX_STEP_BATCH): ...",
        ]
    )
    assert len(_batch_literals(source, "sample")) == 4
