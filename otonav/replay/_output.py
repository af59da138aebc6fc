"""``--out``: a new MCAP file holding the replayed outputs beside the recorded inputs.

Every recorded topic that is not an output of the replayed actors is copied as it was
(same schema, same bytes, same instants): the inputs, /tf, the rest of the context
Foxglove needs to draw. The replayed outputs go on their own topics, and the recorded
outputs they replace on ``/recorded<topic>`` (e.g. ``/recorded/cmd_vel``), so a plot
can show both. The ``otonav`` metadata carries the config the replay ran with, and an
``otonav_replay`` record says what was replayed and how it compared.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from mcap.writer import CompressionType

from otonav.msgs import Message
from otonav.record._fastwriter import FastWriter
from otonav.record._qos_profile import offered_qos_yaml
from otonav.record._schemas import schema_for
from otonav.record._type_hash import rihs01
from otonav.record._writer import CHUNK_SIZE
from otonav.record.cdr import encode
from otonav.replay._recording import Recording, load_recording
from otonav.replay._runner import ReplayResult

RECORDED_PREFIX = "/recorded"
SKIPPED = frozenset({"/scenario/verdict"})
"""Topics about the original run as a whole, not copied."""


def write_replay(result: ReplayResult, out: Path) -> Path:
    """Write ``out`` (see the module docstring); returns its path."""
    if out.resolve() == result.recording.resolve():
        raise ValueError(f"--out {out}: is the recording being replayed; choose another path")
    source = load_recording(result.recording, topics=None)
    outputs = {t.topic for t in result.topics}
    rows: list[tuple[int, int, str, bytes]] = []  # (time, order, topic, data)
    for message in source.messages:
        if message.topic in SKIPPED:
            continue
        topic = RECORDED_PREFIX + message.topic if message.topic in outputs else message.topic
        rows.append((message.time_ns, len(rows), topic, message.data))
    types: dict[str, type[Message]] = {}
    for replayed in result.replayed:
        types[replayed.topic] = type(replayed.message)
        rows.append((replayed.time_ns, len(rows), replayed.topic, encode(replayed.message)))
    rows.sort()
    out.parent.mkdir(parents=True, exist_ok=True)
    # All or nothing: written beside, renamed over ``out`` once finished and indexed (an
    # interrupted replay leaves no partial file, and an earlier ``out`` as it was).
    partial = out.with_name(f".{out.name}.partial")
    try:
        _write(result, source, rows, types, partial)
        os.replace(partial, out)
    except BaseException:
        partial.unlink(missing_ok=True)
        raise
    return out


def _write(
    result: ReplayResult,
    source: Recording,
    rows: list[tuple[int, int, str, bytes]],
    types: dict[str, type[Message]],
    path: Path,
) -> None:
    with path.open("wb") as f:
        writer = FastWriter(f, chunk_size=CHUNK_SIZE, compression=CompressionType.ZSTD)
        writer.start(profile="ros2", library="otonav replay")
        schema_ids: dict[str, int] = {}
        channels: dict[str, int] = {}
        # Each channel keeps its recorded metadata (offered_qos_profiles, the type
        # hash); a replayed output gets the QoS its recorded topic was offered with.
        recorded_metadata = {
            c.topic: dict(c.metadata)
            for c in (source.summary.channels.values() if source.summary is not None else ())
        }
        sequences: dict[int, int] = {}

        def channel(topic: str) -> int:
            channel_id = channels.get(topic)
            if channel_id is not None:
                return channel_id
            metadata = recorded_metadata.get(topic.removeprefix(RECORDED_PREFIX), {})
            if topic in types:
                name, definition = schema_for(types[topic])
                encoding, data = "ros2msg", definition.encode()
                metadata = {
                    "offered_qos_profiles": metadata.get("offered_qos_profiles")
                    or offered_qos_yaml(()),
                    "topic_type_hash": rihs01(types[topic]),
                }
            else:
                recorded = source.schemas[topic.removeprefix(RECORDED_PREFIX)]
                name, encoding, data = recorded.name, recorded.encoding, recorded.data
            schema_id = schema_ids.get(name)
            if schema_id is None:
                schema_id = schema_ids[name] = writer.register_schema(name, encoding, data)
            channel_id = channels[topic] = writer.register_channel(
                topic, "cdr", schema_id, metadata
            )
            sequences[channel_id] = 0
            return channel_id

        for time_ns, _order, topic, data in rows:
            channel_id = channel(topic)
            sequences[channel_id] += 1
            writer.add_message(channel_id, time_ns, data, time_ns, sequences[channel_id])
        meta = dict(source.metadata.get("otonav", {}))
        meta["stack_config"] = result.stack.model_dump_json()
        writer.add_metadata("otonav", meta)
        writer.add_metadata(
            "otonav_replay",
            {
                "source": str(result.recording),
                "nodes": ",".join(result.nodes),
                "byte_identical": json.dumps(result.byte_identical),
                "passed": json.dumps(result.passed),
                "divergences": str(len(result.divergences)),
                "first_divergence": str(result.first_divergence or ""),
            },
        )
        writer.finish()  # type: ignore[no-untyped-call]
