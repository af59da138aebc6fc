"""Reading recordings back: a summary (like ``ros2 bag info``), the messages of a topic
in a time range as otonav's own message types (decoded by otonav's CDR decoder, as
replay's are), and the cut-off case (no footer: the process was killed)."""

from __future__ import annotations

import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from operator import itemgetter
from pathlib import Path
from typing import Any

from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader, make_reader
from mcap.records import Channel, Metadata, Schema
from mcap.records import Message as Message_
from mcap.writer import MCAP0_MAGIC as MAGIC

from otonav.errors import UsageError
from otonav.msgs import Message
from otonav.record._fastreader import ChunkDamageError, read_raw_messages
from otonav.record._verify import (
    CUT_OFF_ERRORS,
    Damage,
    _finished,
    _one_line,
    describe_damage,
    iter_verified,
    summary_damage,
    summary_start,
)
from otonav.record.cdr import decode

__all__ = [
    "CUT_OFF_ERRORS",
    "MAGIC",
    "Damage",
    "DamagedRecordingError",
    "RecordingError",
    "RecordingSummary",
    "TopicSummary",
    "iter_readable",
    "read_messages",
    "summarize",
]


class RecordingError(UsageError):
    """A file that is not a readable recording: one line naming it and why."""


class DamagedRecordingError(RecordingError):
    """A recording with a chunk that fails its CRC (or does not decode): reading it
    would give damaged data as if it had been recorded."""


@dataclass(slots=True)
class TopicSummary:
    topic: str
    type: str
    count: int
    first_ns: int | None = None
    last_ns: int | None = None

    @property
    def rate_hz(self) -> float:
        if self.count < 2 or self.first_ns is None or self.last_ns is None:
            return 0.0
        span = (self.last_ns - self.first_ns) / 1e9
        return (self.count - 1) / span if span > 0 else 0.0


@dataclass(slots=True)
class RecordingSummary:
    path: Path
    size_bytes: int
    profile: str
    library: str
    start_ns: int
    end_ns: int
    topics: list[TopicSummary]
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    truncated: bool = False
    """True when the file has no footer/index (cut off); figures come from its complete chunks."""
    damaged: tuple[Damage, ...] = ()
    """Chunks that failed their CRC (or did not decode): their messages are counted by
    the index but cannot be read."""

    @property
    def duration_s(self) -> float:
        return max(0, self.end_ns - self.start_ns) / 1e9

    @property
    def message_count(self) -> int:
        return sum(t.count for t in self.topics)


def check_file(path: Path) -> None:
    """One line for a path that cannot be a recording: missing, a directory, no MCAP magic."""
    if not path.exists():
        raise RecordingError(f"{path}: no such file")
    if path.is_dir():
        raise RecordingError(f"{path}: is a directory, not an MCAP file")
    with path.open("rb") as f:
        head = f.read(len(MAGIC))
    if head != MAGIC:
        raise RecordingError(f"{path}: not an MCAP file (it does not start with the MCAP magic)")


def summarize(path: str | Path) -> RecordingSummary:
    """Topics, types, counts, rates and duration; falls back to a streaming scan of the
    complete chunks when the file was cut off (``truncated=True``)."""
    path = Path(path)
    check_file(path)
    size = path.stat().st_size
    with path.open("rb") as f:
        try:
            reader = make_reader(f)
            header = reader.get_header()
            summary = reader.get_summary()
            if summary is None or summary.statistics is None:
                raise McapError("no summary section")
            stats = summary.statistics
            topics = [
                TopicSummary(
                    ch.topic,
                    summary.schemas[ch.schema_id].name if ch.schema_id in summary.schemas else "?",
                    stats.channel_message_counts.get(ch.id, 0),
                )
                for ch in summary.channels.values()
            ]
            by_topic = {t.topic: t for t in topics}
            of_channel = {ch.id: by_topic[ch.topic] for ch in summary.channels.values()}
            metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        except CUT_OFF_ERRORS as exc:
            return _scan(path, size, _index_damage(path, exc))
    index_damage = summary_damage(path)
    if index_damage is not None:  # the index's counts cannot be trusted: count ourselves
        return _scan(path, size, index_damage)
    # First/last time per topic for the rate, reading every chunk and checking its CRC
    # (the index alone would not notice a damaged chunk).
    damage: list[Damage] = []
    for record in iter_readable(path, damage):
        if isinstance(record, Message_) and record.channel_id in of_channel:
            t = of_channel[record.channel_id]
            if t.first_ns is None or record.log_time < t.first_ns:
                t.first_ns = record.log_time
            if t.last_ns is None or record.log_time > t.last_ns:
                t.last_ns = record.log_time
    return RecordingSummary(
        path,
        size,
        header.profile,
        header.library,
        stats.message_start_time,
        stats.message_end_time,
        sorted(topics, key=lambda t: t.topic),
        metadata,
        damaged=tuple(damage),
    )


def iter_readable(
    path: Path, damage: list[Damage] | None = None
) -> Iterator[Schema | Channel | Message_ | Metadata]:
    """The schema, channel, message and metadata records of ``path`` in file order, up to
    where it was cut off (a cut-off file ends mid-record: the rest is not readable).
    Works on a complete file too (it is read front to back, index ignored). Every chunk
    is checked against its CRC: with a ``damage`` list a damaged chunk is skipped and
    appended to it; without one it raises :class:`DamagedRecordingError`."""
    found: list[Damage] = [] if damage is None else damage
    for record in iter_verified(path, found):
        if damage is None and found:
            raise DamagedRecordingError(describe_damage(path, found))
        yield record
    if damage is None and found:
        raise DamagedRecordingError(describe_damage(path, found))


def _index_damage(path: Path, exc: BaseException) -> Damage | None:
    """None when ``path`` was cut off (no index yet); a damaged index when it is finished
    (it ends with the magic) and the index still does not read."""
    if not _finished(path):
        return None
    return Damage(
        summary_start(path) or path.stat().st_size,
        f"the index (summary section) does not read ({_one_line(exc)}): read front to back instead",
    )


def _scan(path: Path, size: int, index_damage: Damage | None) -> RecordingSummary:
    """The summary of a front-to-back read: of a cut-off file (``index_damage`` None:
    ``truncated``) or of a finished one whose index is damaged."""
    damage: list[Damage] = []
    topics: dict[str, TopicSummary] = {}
    profile = library = ""
    start = end = 0
    with path.open("rb") as f:
        try:
            header = NonSeekingReader(f).get_header()
            profile, library = header.profile, header.library
        except CUT_OFF_ERRORS as exc:
            # The magic and then no header: not a cut-off recording, not a recording.
            raise RecordingError(
                f"{path}: no readable MCAP header after the magic ({_one_line(exc)}); "
                "not a recording otonav can read"
            ) from None
    schemas: dict[int, str] = {}
    channels: dict[int, TopicSummary] = {}
    metadata: dict[str, dict[str, str]] = {}
    for record in iter_readable(path, damage):
        if isinstance(record, Schema):
            schemas[record.id] = record.name
        elif isinstance(record, Channel):
            t = topics.get(record.topic)
            if t is None:
                t = topics[record.topic] = TopicSummary(
                    record.topic, schemas.get(record.schema_id, "?"), 0
                )
            channels[record.id] = t
        elif isinstance(record, Metadata):
            metadata[record.name] = dict(record.metadata)
        elif record.channel_id in channels:
            t = channels[record.channel_id]
            t.count += 1
            t.first_ns = record.log_time if t.first_ns is None else min(t.first_ns, record.log_time)
            t.last_ns = record.log_time if t.last_ns is None else max(t.last_ns, record.log_time)
    firsts = [t.first_ns for t in topics.values() if t.first_ns is not None]
    lasts = [t.last_ns for t in topics.values() if t.last_ns is not None]
    if firsts:
        start, end = min(firsts), max(lasts)
    return RecordingSummary(
        path,
        size,
        profile,
        library,
        start,
        end,
        sorted(topics.values(), key=lambda t: t.topic),
        metadata,
        truncated=index_damage is None,
        damaged=(*damage, *([index_damage] if index_damage else [])),
    )


def read_messages(
    path: str | Path,
    topics: Sequence[str] | None = None,
    *,
    start: float | None = None,
    end: float | None = None,
    damage: list[Damage] | None = None,
) -> Iterator[tuple[str, float, Any]]:
    """Yield ``(topic, sim_time_s, message)`` in log-time order, for ``topics`` (every
    topic otonav has a message type for when None; a named topic of another type is a
    :class:`RecordingError`) with ``start <= t < end`` (seconds of sim time). Each
    message is the :mod:`otonav.msgs` type its schema names (or a user's own
    :class:`~otonav.msgs.Message` subclass of that ``ros_type``), decoded by otonav's own
    CDR decoder (:func:`otonav.record.cdr.decode`) from the chunks replay's reader reads
    (:mod:`otonav.record._fastreader`). A cut-off file yields the messages of its
    complete chunks, in file order.

    Every chunk read is checked against its CRC: a damaged one raises
    :class:`DamagedRecordingError`, or, given a ``damage`` list, is skipped and appended
    to it (the file is then read front to back, in file order)."""
    path = Path(path)
    check_file(path)
    first = -1 if start is None else round(start * 1e9)
    last = None if end is None else round(end * 1e9)
    raw = _read_indexed(path, topics) if damage is None else None
    for topic, kind, at, data in _read_front_to_back(path, topics, damage) if raw is None else raw:
        if at >= first and (last is None or at < last):
            yield topic, at / 1e9, _decode(path, topic, kind, at, data)


_Raw = tuple[str, type[Message], int, bytes]
"""(topic, its message class, log time ns, CDR data)"""


def _read_indexed(path: Path, topics: Sequence[str] | None) -> list[_Raw] | None:
    """The wanted messages by the index with replay's reader (file order, CRC checked),
    stably sorted by log time; None when the file is cut off or its index damaged."""
    with path.open("rb") as f:
        try:
            summary = make_reader(f).get_summary()
            if summary is None or summary_damage(path) is not None:
                return None
        except CUT_OFF_ERRORS:
            return None
        channels = summary.channels
        types = {
            i: kind
            for i, ch in channels.items()
            if (kind := _type_of(path, ch, summary.schemas, topics)) is not None
        }
        try:
            raw = read_raw_messages(f, summary, list(types))
        except ChunkDamageError as exc:  # say which chunks
            found: list[Damage] = []
            for _record in iter_verified(path, found):
                pass
            raise DamagedRecordingError(describe_damage(path, found or [exc.damage])) from None
    out = [(channels[i].topic, types[i], at, data) for i, at, data in raw]
    out.sort(key=itemgetter(2))
    return out


def _message_types() -> dict[str, type[Message]]:
    """ROS type name -> the message class that stands for it: otonav's and any a user
    defined (every subclass of Message), the first defined for a name (a flat or lazy
    stand-in subclasses its message class and is not another type)."""
    found: dict[str, type[Message]] = {}
    todo = Message.__subclasses__()
    while todo:
        kind = todo.pop(0)
        todo += kind.__subclasses__()
        name = getattr(kind, "ros_type", None)
        if isinstance(name, str):
            found.setdefault(name, kind)
    return found


def _type_of(
    path: Path, channel: Channel, schemas: dict[int, Schema], topics: Sequence[str] | None
) -> type[Message] | None:
    """The message class of ``channel``'s messages; None when its topic is not wanted,
    or (every topic wanted) otonav has no class for its type, which it then skips with a
    warning as ``ros2 bag play`` does; a named topic of such a type is a RecordingError."""
    if topics is not None and channel.topic not in topics:
        return None
    schema = schemas.get(channel.schema_id)
    name = schema.name if schema is not None else "?"
    kind = _message_types().get(name)
    if kind is None or channel.message_encoding != "cdr":
        what = f"{name} in {channel.message_encoding!r}"
        if topics is None:
            warnings.warn(
                f"{path}: skipping {channel.topic} ({what}: no otonav message type)", stacklevel=3
            )
            return None
        raise RecordingError(
            f"{path}: {channel.topic} holds {what}, which otonav has no message type for "
            "(it reads the types of otonav.msgs and of any Message subclass imported)"
        )
    return kind


def _decode(path: Path, topic: str, kind: type[Message], at: int, data: bytes) -> Message:
    try:
        return decode(kind, data)
    except ValueError as exc:
        raise DamagedRecordingError(
            f"{path}: the {topic} message at {at / 1e9:.9f} s does not "
            f"decode as {kind.ros_type} ({_one_line(exc)})"
        ) from None


def _read_front_to_back(
    path: Path, topics: Sequence[str] | None, damage: list[Damage] | None
) -> Iterator[_Raw]:
    schemas: dict[int, Schema] = {}
    channels: dict[int, tuple[str, type[Message]]] = {}
    for record in iter_readable(path, damage):
        if isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, Channel):
            if damage and record.schema_id not in schemas:
                continue  # its schema was in a damaged chunk (reported): its messages are lost
            kind = _type_of(path, record, schemas, topics)
            if kind is not None:
                channels[record.id] = (record.topic, kind)
        elif isinstance(record, Message_) and record.channel_id in channels:
            yield *channels[record.channel_id], record.log_time, record.data
