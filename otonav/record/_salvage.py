"""Salvage: rewrite the readable part of a cut-off recording as an indexed file (what
``mcap recover`` does): every message of every complete chunk, same schemas and
channels, and every metadata record that was written before the cut (``otonav``'s
world and run records are written when the recording starts; the verdict's record at
the end is lost with the end of the file).

Only chunks that match their CRC are copied: a damaged chunk is skipped and reported,
never rewritten under a fresh CRC (that would make damaged data look recorded).

A target that cannot be finished (a full disk, Ctrl-C) is removed: a partial copy
is no salvage, and a retry would have to ``--force`` past it."""

from __future__ import annotations

from pathlib import Path

from mcap.reader import NonSeekingReader
from mcap.records import Channel, Metadata, Schema
from mcap.writer import CompressionType, Writer

from otonav.record._diskfull import DiskFullError, is_disk_full
from otonav.record._reader import (
    CUT_OFF_ERRORS,
    DamagedRecordingError,
    RecordingError,
    check_file,
    iter_readable,
)
from otonav.record._verify import Damage, describe_damage
from otonav.record._writer import CHUNK_SIZE


def salvage(
    source: str | Path,
    target: str | Path,
    *,
    overwrite: bool = False,
    damaged: list[Damage] | None = None,
) -> int:
    """Copy what can be read of ``source`` into ``target``; returns the message count.
    An existing ``target`` is a :class:`RecordingError` unless ``overwrite``. Damaged
    chunks are not copied: they are appended to ``damaged``, or, without that list,
    reported by a :class:`DamagedRecordingError` once ``target`` is written."""
    source, target = Path(source), Path(target)
    check_file(source)
    if source.resolve() == target.resolve():
        raise RecordingError(f"{target}: salvage writes a new file; choose another path")
    if target.is_dir():
        raise RecordingError(f"{target}: is a directory; name the new .mcap file")
    if target.exists() and not overwrite:
        raise RecordingError(f"{target}: already exists; choose another path or pass --force")
    with source.open("rb") as f:
        try:
            header = NonSeekingReader(f).get_header()
        except CUT_OFF_ERRORS:
            raise RecordingError(
                f"{source}: no readable MCAP header after the magic ({source.stat().st_size} "
                "bytes): not a recording, nothing to salvage"
            ) from None
    damage: list[Damage] = [] if damaged is None else damaged
    try:
        count = _copy(source, target, header.profile, header.library, damage)
    except BaseException as exc:
        # A partial target is no salvage (and a retry would refuse it without --force).
        target.unlink(missing_ok=True)
        if isinstance(exc, OSError) and is_disk_full(exc):
            raise DiskFullError(
                target,
                exc,
                "the partial copy was removed: free some space or salvage to another disk",
            ) from exc
        raise
    if damaged is None and damage:
        raise DamagedRecordingError(
            f"{describe_damage(source, damage)}; {target} holds the {count} messages of "
            "the intact chunks"
        )
    return count


def _copy(source: Path, target: Path, profile: str, library: str, damage: list[Damage]) -> int:
    count = 0
    with target.open("wb") as out:
        writer = Writer(out, chunk_size=CHUNK_SIZE, compression=CompressionType.ZSTD)
        writer.start(profile=profile, library=library)
        schemas: dict[int, Schema] = {}
        channels: dict[int, Channel] = {}
        schema_ids: dict[int, int] = {}
        channel_ids: dict[int, int] = {}
        for record in iter_readable(source, damage):
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
            elif isinstance(record, Metadata):
                writer.add_metadata(record.name, dict(record.metadata))
            elif record.channel_id in channels:
                if record.channel_id not in channel_ids:
                    channel = channels[record.channel_id]
                    schema_id = 0
                    schema = schemas.get(channel.schema_id)
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
                    channel_ids[record.channel_id],
                    log_time=record.log_time,
                    data=record.data,
                    publish_time=record.publish_time,
                    sequence=record.sequence,
                )
                count += 1
        writer.finish()  # type: ignore[no-untyped-call]
    return count
