"""Layer 0: the runners assemble the stack through one session object (issue 16, item 8).

Five modules used to build world, writer, recorder and system each in its own way and
tear them down in four different orders. They now hand their world and actors to
``otonav.stack._session.StackSession``; this test keeps it so.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

RUNNERS = [
    "otonav/scenario/_run.py",
    "otonav/scenario/_assembly.py",
    "otonav/scenario/_judged.py",
    "otonav/scenario/_realtime.py",
    "otonav/testing/_stack.py",
    "otonav/engine/_live.py",
    "otonav/bench/_harness.py",
]
#: What only the session may make or do: it owns recording, time mode and teardown.
SESSION_ONLY = {"System", "RecordingWriter", "Recorder", "RealTimeClock", "attach_rosout"}
SESSION_ONLY_METHODS = {"attach_source", "finish"}


def _violations(path: Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        if isinstance(func, ast.Name) and func.id in SESSION_ONLY:
            found.append(f"line {node.lineno}: {func.id}(...)")
        elif isinstance(func, ast.Attribute) and func.attr in SESSION_ONLY_METHODS:
            found.append(f"line {node.lineno}: .{func.attr}(...)")
    return found


@pytest.mark.parametrize("module", RUNNERS)
def test_runner_leaves_assembly_and_teardown_to_the_session(module: str) -> None:
    found = _violations(ROOT / module)
    assert not found, (
        f"{module} assembles or tears down the stack itself ({'; '.join(found)}); hand the "
        "world and actors to otonav.stack._session.StackSession instead"
    )


def test_the_session_is_where_they_happen() -> None:
    """The check looks at the right things: the session itself does all of them."""
    found = " ".join(_violations(ROOT / "otonav/stack/_session.py"))
    for name in ("System", "RecordingWriter", "Recorder", "attach_rosout"):
        assert f"{name}(" in found
    for method in SESSION_ONLY_METHODS:
        assert f".{method}(" in found
