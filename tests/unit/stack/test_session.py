"""One session object, one teardown: the order of ADR 0007 in every runner, the final
drain, and the loop's time source given back."""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from contextlib import AbstractAsyncContextManager
from pathlib import Path

import anyio
import pytest

from otonav.embed import open_live_stack
from otonav.hal._fake import FakeHardware
from otonav.msgs import Point, Pose, PoseStamped
from otonav.record._reader import read_messages
from otonav.runtime import (
    Actor,
    JumpSource,
    Output,
    RealTime,
    VirtualTimeLoop,
    virtual_loop_factory,
)
from otonav.stack import StackConfig
from otonav.stack._session import StackSession
from otonav.testing import running_stack

pytestmark = pytest.mark.unit

LAST_WORDS = "/last_words"

#: The robot driven straight through /cmd_vel: no planner, no safety layer, said in the
#: config (``navigator=False`` meant this until ADR 0055; it now keeps the safety layer).
BASE_ONLY = StackConfig.model_validate(
    {"nav": {"planner": "external"}, "safety": {"enabled": False}}
)


class LastWords(Actor):
    """Publishes one message from its on_stop, after some sim time."""

    out = Output(LAST_WORDS, PoseStamped)

    def __init__(self) -> None:
        super().__init__("last_words")

    async def run(self) -> None:
        await anyio.sleep_forever()

    async def on_stop(self) -> None:
        await self.clock.sleep(0.05)
        await self.out.publish(PoseStamped(pose=Pose(position=Point(x=1.0))))


Runner = Callable[[Path, Actor], AbstractAsyncContextManager[object]]


def _virtual(path: Path, actor: Actor) -> AbstractAsyncContextManager[object]:
    return running_stack(BASE_ONLY, record_to=path, extra_actors=[actor])


def _realtime(path: Path, actor: Actor) -> AbstractAsyncContextManager[object]:
    return running_stack(BASE_ONLY, record_to=path, extra_actors=[actor], time=RealTime(20))


def _live(path: Path, actor: Actor) -> AbstractAsyncContextManager[object]:
    return open_live_stack(BASE_ONLY, record_to=path, extra_actors=[actor], time=RealTime(20))


async def _run_stack(runner: Runner, path: Path) -> None:
    async with runner(path, LastWords()):
        await asyncio.sleep(0)  # up, then straight down: the teardown is what is tested


@pytest.mark.parametrize(
    ("runner", "loop"),
    [(_virtual, "virtual"), (_realtime, "stock"), (_live, "stock")],
    ids=["running_stack", "running_stack-realtime", "open_live_stack"],
)
def test_the_recording_ends_with_every_stop_in_reverse_start_order(
    runner: Runner, loop: str, tmp_path: Path
) -> None:
    """What actors publish while stopping, and the recorder's own "stopped" line, are in
    the file: a final drain after the system exits. (running_stack and open_live_stack
    finished the writer without it: the recorder's "stopped" line was lost.)"""
    path = tmp_path / "run.mcap"
    factory = virtual_loop_factory() if loop == "virtual" else None
    with asyncio.Runner(loop_factory=factory) as asyncio_runner:
        asyncio_runner.run(_run_stack(runner, path))
    recorded = list(read_messages(path, [LAST_WORDS, "/rosout"]))
    assert [t for t, _s, _m in recorded].count(LAST_WORDS) == 1
    stops = [m.name for t, _s, m in recorded if t == "/rosout" and m.msg == "stopped"]
    assert stops == ["last_words", "command_watch", "base", "bridge", "recorder"]
    # The last words came after the robot actors had begun stopping, before the recorder.
    topics = [t if t == LAST_WORDS else m.msg for t, _s, m in recorded]
    assert topics.index(LAST_WORDS) < len(topics) - 1


@pytest.mark.sim
async def test_running_stack_gives_the_loop_its_time_source_back() -> None:
    """After the stack, the loop runs on as before: a sleep does not step the closed
    world. (It raised from the loop's selector: the closed MuJoCo world stayed attached.)"""
    loop = asyncio.get_running_loop()
    assert isinstance(loop, VirtualTimeLoop)
    before = loop.source
    async with running_stack(BASE_ONLY) as stack:
        assert loop.source is stack.hal
        await stack.system.clock.sleep(0.1)
    assert loop.source is before
    start = loop.time()
    await anyio.sleep(1.5)
    assert loop.time() == pytest.approx(start + 1.5, abs=1e-6)


class _Witness(FakeHardware):
    """A world that notes what had happened by the time it was closed."""

    def __init__(self, session_of: list[StackSession], log: list[str]) -> None:
        super().__init__()
        self._session_of = session_of
        self._log = log

    def close(self) -> None:
        session = self._session_of[0]
        assert session.writer is not None
        self._log.append(f"world closed (writer finished: {session.writer.finished})")
        super().close()


def test_teardown_order_writer_cleanups_world_then_time_source(tmp_path: Path) -> None:
    log: list[str] = []
    holder: list[StackSession] = []
    hal = _Witness(holder, log)
    session = StackSession(hal, [LastWords()], record_to=tmp_path / "r.mcap")
    holder.append(session)
    session.add_cleanup(lambda: log.append("cleanup 1"))
    session.add_cleanup(lambda: log.append("cleanup 2"))
    jump = JumpSource()

    async def main() -> None:
        loop = asyncio.get_running_loop()
        assert isinstance(loop, VirtualTimeLoop)
        async with session.running(close=False):
            assert loop.source is hal
            await anyio.sleep(0.2)

        def epilogue(writer: object) -> None:
            log.append(f"epilogue (time source still the world: {loop.source is hal})")

        session.close(epilogue=epilogue)
        source: object = loop.source
        log.append(f"time source given back: {source is jump}")

    with asyncio.Runner(loop_factory=virtual_loop_factory(jump)) as runner:
        runner.run(main())
    assert log == [
        "epilogue (time source still the world: True)",
        "cleanup 2",
        "cleanup 1",
        "world closed (writer finished: True)",
        "time source given back: True",
    ]
    lines = [(m.name, m.msg) for _t, _s, m in read_messages(tmp_path / "r.mcap", ["/rosout"])]
    assert lines[-1] == ("recorder", "stopped")
