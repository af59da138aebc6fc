"""Salvage: rewrite the readable part of a cut-off recording as an indexed file (what
``mcap recover`` does): every message of every complete chunk, same schemas and
channels. Metadata records (written at the end by ``finish``) are not in a cut-off
file, so there are none to copy."""

from __future__ import annotations

from pathlib import Path

from mcap.reader import NonSeekingReader
from mcap.writer import CompressionType, Writer

from otonav.record.reader import CUT_OFF_ERRORS, RecordingError, _check_file
from otonav.record.writer import CHUNK_SIZE


def salvage(source: str | Path, target: str | Path) -> int:
    """Copy what can be read of ``source`` into ``target``; returns the message count."""
    source, target = Path(source), Path(target)
    _check_file(source)
    if source.resolve() == target.resolve():
        raise RecordingError(f"{target}: salvage writes a new file; choose another path")
    count = 0
    with source.open("rb") as f:
        try:
            header = NonSeekingReader(f).get_header()
        except CUT_OFF_ERRORS as exc:
            raise RecordingError(f"{source}: no readable MCAP header ({exc})") from None
    with source.open("rb") as f, target.open("wb") as out:
        reader = NonSeekingReader(f)
        writer = Writer(out, chunk_size=CHUNK_SIZE, compression=CompressionType.ZSTD)
        writer.start(profile=header.profile, library=header.library)
        schema_ids: dict[int, int] = {}
        channel_ids: dict[int, int] = {}
        try:
            for schema, channel, message in reader.iter_messages(log_time_order=False):
                if channel.id not in channel_ids:
                    schema_id = 0
                    if schema is not None:
                        if schema.id not in schema_ids:
                            schema_ids[schema.id] = writer.register_schema(
                                schema.name, schema.encoding, schema.data
                            )
                        schema_id = schema_ids[schema.id]
                    channel_ids[channel.id] = writer.register_channel(
                        channel.topic, channel.message_encoding, schema_id, dict(channel.metadata)
                    )
                writer.add_message(
                    channel_ids[channel.id],
                    log_time=message.log_time,
                    data=message.data,
                    publish_time=message.publish_time,
                    sequence=message.sequence,
                )
                count += 1
        except CUT_OFF_ERRORS:
            pass  # the cut-off point
        writer.finish()  # type: ignore[no-untyped-call]
    return count
