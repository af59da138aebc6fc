"""What replay reads from a recording: the stack config it ran with, each topic's
type, and the messages of the topics in play, in recorded order.

The recorded order is the order the messages were published in: the recorder funnels
every topic into one queue as messages are published, and the file keeps that order.
Replay depends on it (``otonav.replay._feed``), so messages are read in file order and
only then sorted by time, stably (a publisher held up by backpressure is stamped with
the instant it published, and may sit later in the file).
"""

from __future__ import annotations

import json
from collections.abc import Collection
from dataclasses import dataclass, field
from operator import itemgetter
from pathlib import Path
from typing import Any, BinaryIO, NamedTuple

from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader, make_reader
from pydantic import ValidationError

from otonav.record._fastreader import ChunkDamageError, read_raw_messages
from otonav.record._reader import CUT_OFF_ERRORS, RecordingError, check_file
from otonav.record._verify import _finished, _one_line, describe_damage, summary_damage
from otonav.scenario._config import StartSpec
from otonav.stack import StackConfig


class ReplayInputError(ValueError):
    """Bad input to a replay (a file, a node name, a topic): one line, what is valid."""


class RecordedMessage(NamedTuple):
    """One recorded message, still encoded (CDR). A named tuple: a replay makes one per
    message it reads (2,241 for the navigator on the acceptance recording), and a frozen
    dataclass took 0.5 us more each to build."""

    topic: str
    time_ns: int
    data: bytes


@dataclass(frozen=True, slots=True)
class RecordedSchema:
    name: str
    encoding: str
    data: bytes


@dataclass(slots=True)
class Recording:
    """The parts of a recording that replay uses."""

    path: Path
    stack: StackConfig | None
    """The stack config stored in the ``otonav`` metadata (None: not an otonav scenario
    recording, e.g. one made with ``running_stack(record_to=...)``)."""
    types: dict[str, str]
    """topic -> ROS type name (the schema name), for every recorded topic."""
    schemas: dict[str, RecordedSchema]
    """topic -> its schema record (to copy topics into a new file)."""
    messages: list[RecordedMessage]
    """The messages of the topics asked for, in recorded order (sorted by time, stably)."""
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    summary: Any = None
    """mcap's parsed summary section (channels, schemas, chunk indexes), for
    :func:`read_topics`."""

    @property
    def start(self) -> tuple[float, float, float]:
        """Where the run started (x, y, yaw): the stored scenario's start, where its
        odometry and its navigator's map are anchored; the origin when none is stored
        (a recording made with ``running_stack``, which starts there by default)."""
        text = self.metadata.get("otonav", {}).get("scenario_config")
        if text is None:
            return (0.0, 0.0, 0.0)
        try:
            start = StartSpec.model_validate(json.loads(text).get("start", {}))
        except (ValueError, AttributeError):  # not JSON, not an object, not a start
            raise ReplayInputError(
                f"{self.path}: its stored scenario has no readable start pose"
            ) from None
        return start.as_tuple()


def _cut_off(path: Path) -> ReplayInputError:
    return ReplayInputError(
        f"{path}: the recording is cut off (no footer or index: the process was killed); "
        f"recover its complete chunks with 'otonav salvage {path} RECOVERED.mcap' and "
        "replay that file"
    )


def load_recording(path: Path, topics: Collection[str] | None) -> Recording:
    """Read ``path``: metadata, every topic's type, and the messages of ``topics`` (all
    when None; none, without reading a chunk, when empty). Raises
    :class:`ReplayInputError` for a missing, non-MCAP or cut-off file."""
    try:
        check_file(path)  # the reader's checks: missing, a directory, no MCAP magic
    except RecordingError as exc:
        raise ReplayInputError(str(exc)) from None
    with path.open("rb") as f:
        if not _has_header(f):  # the magic alone (issue 27: "Invalid argument")
            size = f.seek(0, 2)
            raise ReplayInputError(
                f"{path}: not a complete MCAP recording: {size} bytes, the MCAP magic and "
                "no readable header after it (an empty or cut-off file; nothing to salvage)"
            )
        f.seek(0)
        try:
            reader = make_reader(f)
            try:
                summary = reader.get_summary()
            except OSError as exc:  # too short to hold a footer: a seek before its start
                raise _unreadable(path, exc) from None
            if summary is None or summary.statistics is None:
                raise _unreadable(path, McapError("no index"))
            index = summary_damage(path)
            if index is not None:
                raise ReplayInputError(
                    f"{path}: damaged: {index.problem.partition(':')[0]}; 'otonav salvage "
                    f"{path} FIXED.mcap' rewrites its intact chunks with a new index"
                )
            types: dict[str, str] = {}
            schemas: dict[str, RecordedSchema] = {}
            for channel in summary.channels.values():
                schema = summary.schemas.get(channel.schema_id)
                types[channel.topic] = schema.name if schema is not None else "?"
                if schema is not None:
                    schemas[channel.topic] = RecordedSchema(
                        schema.name, schema.encoding, schema.data
                    )
            messages = _messages(f, summary, topics)
            metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        except (ChunkDamageError, *CUT_OFF_ERRORS) as exc:
            raise _unreadable(path, exc) from None
    return Recording(path, _stack_of(path, metadata), types, schemas, messages, metadata, summary)


def read_topics(recording: Recording, topics: Collection[str]) -> list[RecordedMessage]:
    """The messages of ``topics`` in ``recording`` (loaded by :func:`load_recording`,
    whose summary is reused), in recorded order."""
    path = recording.path
    try:
        with path.open("rb") as f:
            return _messages(f, recording.summary, topics)
    except OSError as exc:
        raise ReplayInputError(f"{path}: cannot read ({exc.strerror or exc})") from None
    except (ChunkDamageError, *CUT_OFF_ERRORS) as exc:
        raise _unreadable(path, exc) from None


def _messages(f: BinaryIO, summary: Any, topics: Collection[str] | None) -> list[RecordedMessage]:
    topic_of = {c.id: c.topic for c in summary.channels.values()}
    wanted = None if topics is None else set(topics)
    ids = None if wanted is None else [i for i, topic in topic_of.items() if topic in wanted]
    if ids == []:
        return []
    new = tuple.__new__
    messages = [
        new(RecordedMessage, (topic_of[channel], log_time, data))
        for channel, log_time, data in read_raw_messages(f, summary, ids)
    ]
    messages.sort(key=_time_of)  # stable: equal instants keep the file order
    return messages


_time_of = itemgetter(1)


def _has_header(f: BinaryIO) -> bool:
    """The MCAP header record follows the magic (``salvage`` has something to read)."""
    try:
        NonSeekingReader(f).get_header()
    except CUT_OFF_ERRORS:
        return False
    return True


def _unreadable(path: Path, exc: BaseException) -> ReplayInputError:
    if isinstance(exc, ReplayInputError):
        return exc
    if isinstance(exc, ChunkDamageError):
        return ReplayInputError(
            f"{describe_damage(path, [exc.damage])}; a replay would feed damaged data as "
            f"recorded ('otonav info {path}' lists every damaged chunk)"
        )
    if _finished(path):  # ends with the magic: not cut off, damaged
        return ReplayInputError(
            f"{path}: damaged: unreadable although finished ({_one_line(exc)}); "
            f"'otonav info {path}' says where"
        )
    return _cut_off(path)


def _stack_of(path: Path, metadata: dict[str, dict[str, str]]) -> StackConfig | None:
    text = metadata.get("otonav", {}).get("stack_config")
    if text is None:
        return None
    try:
        return StackConfig.model_validate_json(text)
    except ValidationError as exc:
        raise ReplayInputError(
            f"{path}: its stored stack config does not validate with this otonav "
            f"({exc.error_count()} error(s), first: {exc.errors()[0]['msg']}); it was "
            "recorded by another version"
        ) from None
