"""Lifecycle events and actor statuses are enums that are also strings: code that
compares with ``"crashed"`` keeps working, and what is written out (/rosout, logs, the
graph) is the same text as before."""

from __future__ import annotations

import json

import anyio
import pytest

from otonav.runtime import (
    Actor,
    ActorStatus,
    EventKind,
    System,
    SystemEvent,
    virtual_loop_factory,
)

pytestmark = pytest.mark.unit


class _Brief(Actor):
    async def run(self) -> None:
        await self.clock.sleep(0.1)


def test_event_kinds_are_an_enum_that_compares_and_prints_as_before() -> None:
    system = System([_Brief("brief")])

    async def main() -> None:
        async with system:
            await system.wait_finished()

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    kinds = [e.kind for e in system.events]
    assert kinds == [EventKind.STARTED, EventKind.FINISHED, EventKind.STOPPED]
    assert all(type(k) is EventKind for k in kinds)
    # Still strings, with the same text everywhere they are written.
    assert kinds == ["started", "finished", "stopped"]
    assert [f"{k}" for k in kinds] == ["started", "finished", "stopped"]
    assert [str(k) for k in kinds] == ["started", "finished", "stopped"]
    assert json.dumps(kinds) == '["started", "finished", "stopped"]'
    assert {"stopped": 1}[system.events[-1].kind] == 1  # hashes as its text
    status: str = system.graph().actors[0].status
    assert type(status) is ActorStatus
    assert status == "finished"


def test_every_kind_and_status_is_lower_case_text() -> None:
    assert {k.value for k in EventKind} == {
        "started",
        "finished",
        "crashed",
        "restarted",
        "stopped",
    }
    assert {s.value for s in ActorStatus} == {
        "created",
        "running",
        "finished",
        "crashed",
        "stopped",
    }
    assert SystemEvent(0.0, "a", EventKind.CRASHED).kind == "crashed"
