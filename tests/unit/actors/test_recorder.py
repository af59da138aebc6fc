"""The recorder keeps up in virtual time: a full funnel wakes it at once instead of
holding publishers back while the world steps on (issue 16, item 6)."""

from __future__ import annotations

import logging
from pathlib import Path

import anyio
import pytest

from otonav.actors._recorder import Recorder
from otonav.msgs import Clock, Time
from otonav.record._reader import read_messages
from otonav.record._writer import RecordingWriter
from otonav.runtime import Actor, Output, System, virtual_loop_factory

pytestmark = pytest.mark.unit

CHATTER = "/chatter"


class Chatter(Actor):
    """Publishes ``burst`` messages at each of ``hz`` instants per second (stamped)."""

    out = Output(CHATTER, Clock)

    def __init__(self, hz: float, burst: int = 1) -> None:
        super().__init__("chatter")
        self.hz = hz
        self.burst = burst
        self.published_until = 0.0

    async def run(self) -> None:
        rate = self.clock.rate(self.hz)
        while True:
            await rate.sleep()
            now = self.clock.now()
            for _ in range(self.burst):
                await self.out.publish(Clock(clock=Time.from_seconds(now)))
            self.published_until = now


def _record(tmp_path: Path, chatter: Chatter, *, depth: int, seconds: float) -> Recorder:
    writer = RecordingWriter(tmp_path / "r.mcap")
    recorder = Recorder(writer, period=1.0, depth=depth)

    async def main() -> None:
        async with System([recorder, chatter]):
            await anyio.sleep(seconds)

    try:
        anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    finally:
        writer.finish()
    return recorder


def test_a_full_funnel_does_not_hold_publishers_back_while_sim_time_runs_on(
    tmp_path: Path,
) -> None:
    """1000 messages/s into a funnel of 100 drained once a sim second: before the
    high-water wake the publisher waited for the next drain while sim time ran on, and
    the file held 1 message in 10 (Rate skips what it missed)."""
    chatter = Chatter(hz=1000.0)
    _record(tmp_path, chatter, depth=100, seconds=2.0)
    stamps = [t for _topic, t, _m in read_messages(tmp_path / "r.mcap", [CHATTER])]
    assert len(stamps) == 2000
    # Each message is stamped at the instant it was published, one per millisecond.
    assert stamps == pytest.approx([(k + 1) / 1000 for k in range(2000)])
    assert chatter.published_until == pytest.approx(2.0)


def test_a_burst_beyond_the_funnel_waits_within_its_instant_counted_and_logged(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A burst larger than the funnel must wait; it waits for the recorder in the same
    instant (no sim time passes), and the wait is counted and logged."""
    chatter = Chatter(hz=10.0, burst=250)
    with caplog.at_level(logging.WARNING):
        recorder = _record(tmp_path, chatter, depth=100, seconds=0.55)
    stamps = [t for _topic, t, _m in read_messages(tmp_path / "r.mcap", [CHATTER])]
    assert len(stamps) == 5 * 250
    assert sorted(set(stamps)) == pytest.approx([0.1, 0.2, 0.3, 0.4, 0.5])
    stats = recorder.funnel.statistics()
    assert stats.blocked_publishes > 0
    assert stats.blocked_topics == (CHATTER,)
    assert any(CHATTER in r.getMessage() and "waited" in r.getMessage() for r in caplog.records)
