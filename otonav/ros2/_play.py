"""A recording onto DDS at its recorded pace, as ``ros2 bag play`` does (``otonav play``).

Every channel of a recording whose type otonav knows is written on its DDS topic with the
QoS it was recorded with (``offered_qos_profiles``: a latched /tf_static stays transient
local), the payload's CDR bytes as they are in the file. The recording's own /clock is
among them, so a ``use_sim_time`` node's clock follows the recording (``ros2 bag play
--clock``'s job). Messages go out at their log times, scaled by ``rate``, on the wall
clock: this is for people and their nodes, not for otonav's virtual time.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from operator import itemgetter
from pathlib import Path
from typing import TYPE_CHECKING

from mcap.reader import make_reader

import otonav.msgs
from otonav.msgs import Message
from otonav.record._fastreader import read_raw_messages
from otonav.record._qos_profile import recorded_qos
from otonav.record._reader import RecordingError, summarize
from otonav.record._verify import describe_damage
from otonav.ros2._naming import Ros2Error, dds_qos, dds_topic, discovery, domain_id

if TYPE_CHECKING:
    from otonav.ros2._dds import Participant, RawWriter

__all__ = ("PlayResult", "play")

_MESSAGES: dict[str, type[Message]] = {
    cls.ros_type: cls
    for cls in (getattr(otonav.msgs, name) for name in otonav.msgs.__all__)
    if isinstance(cls, type) and issubclass(cls, Message) and cls is not Message
}
"""ROS type name -> otonav's message class, for every message otonav defines."""


@dataclass(frozen=True, slots=True)
class PlayResult:
    """What a play wrote."""

    sent: int
    """Messages written to DDS."""
    topics: tuple[str, ...]
    """Topics played."""
    skipped: tuple[str, ...]
    """Topics not played: a type otonav does not know."""
    sim_span: float
    """s of sim time from the first message played to the last."""


def play(
    recording: str | Path,
    *,
    rate: float = 1.0,
    topics: Sequence[str] = (),
    domain: int | None = None,
    wait: float | None = None,
    env: Mapping[str, str],
    on_start: Callable[[int, Sequence[str]], None] | None = None,
) -> PlayResult:
    """Play ``recording`` onto DDS (see the module docstring). ``topics``: only these
    (every one when empty). ``wait``: first hold until a DDS reader matched one of them
    and discovery settled, at most this many wall seconds. ``on_start(domain, topics)``
    is called once the writers exist. Bad input raises :class:`Ros2Error` or
    :class:`~otonav.record._reader.RecordingError`, one line each."""
    if not (rate > 0 and math.isfinite(rate) and rate <= 1000):
        raise Ros2Error(f"--rate {rate}: must be a number in (0, 1000]")
    path = Path(recording)
    summary = summarize(path)  # one line for a file that is not a readable recording
    if summary.truncated:
        raise RecordingError(f"{path}: not finished (no index); `otonav salvage` indexes it")
    if summary.damaged:  # played, it would send damaged data as recorded
        raise RecordingError(describe_damage(path, summary.damaged))
    where = discovery(env)
    dds_domain = domain_id(domain, env)
    from otonav.ros2._dds import Participant

    participant = Participant(dds_domain, where.config)
    try:
        return _play(participant, path, rate, topics, wait, dds_domain, on_start)
    finally:
        participant.close()


def _play(
    participant: Participant,
    path: Path,
    rate: float,
    wanted: Sequence[str],
    wait: float | None,
    dds_domain: int,
    on_start: Callable[[int, Sequence[str]], None] | None,
) -> PlayResult:
    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
        assert summary is not None, "summarize() refused a file without one"
        channels, schemas = summary.channels, summary.schemas
        present = {channel.topic for channel in channels.values()}
        unknown = [name for name in wanted if name not in present]
        if unknown:
            raise Ros2Error(
                f"--topic {unknown[0]}: not in {path.name} (its topics: "
                f"{', '.join(sorted(present))})"
            )
        writers: dict[int, RawWriter] = {}
        skipped: list[str] = []
        for channel_id, channel in sorted(channels.items()):
            if wanted and channel.topic not in wanted:
                continue
            schema = schemas.get(channel.schema_id)
            message = _MESSAGES.get(schema.name if schema is not None else "")
            if message is None or channel.message_encoding != "cdr":
                skipped.append(channel.topic)
                continue
            policy = dds_qos(
                recorded_qos(channel.metadata.get("offered_qos_profiles", "")), message
            )
            writers[channel_id] = participant.writer(dds_topic(channel.topic), message, policy)
        played = tuple(sorted(channels[i].topic for i in writers))
        if on_start is not None:
            on_start(dds_domain, played)
        if wait is not None and participant.wait(
            lambda: any(w.matched.count for w in writers.values()), wait
        ):
            participant.wait_quiet(0.5, wait)
        messages = read_raw_messages(f, summary, list(writers))  # CRC checked, file order
        messages.sort(key=itemgetter(1))  # stably: in log-time order
        sent, first, last = 0, math.nan, math.nan
        wall0 = time.monotonic()
        for channel_id, log_time, data in messages:
            t = log_time / 1e9
            if math.isnan(first):
                first = t
            delay = wall0 + (t - first) / rate - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            if writers[channel_id].write(data):
                sent += 1
            last = t
    return PlayResult(
        sent=sent,
        topics=played,
        skipped=tuple(sorted(set(skipped))),
        sim_span=0.0 if math.isnan(first) else last - first,
    )
