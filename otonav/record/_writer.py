"""Writing one MCAP file: profile ``ros2``, ``ros2msg`` schemas, CDR payloads, sim-time
stamps. Crash-safe by construction (ADR 0004):

- chunks of 64 KiB (a 1 MiB chunk held the longest ``add_message`` pause at 8.4 ms vs
  0.9 ms, and a kill loses at most one chunk);
- the file is flushed whenever a chunk (or the header) has been written, so each
  finished chunk is in the OS at once (with a 1 MiB buffered file a SIGKILL left an
  empty file: even the header was held). An unbuffered file is not an option: mcap's
  writer produced a file with no valid footer on one (measured here);
- ``finish()`` (footer + index) runs on every exit path: the owner calls it in ``finally``
  and the CLI turns SIGINT/SIGTERM into cancellation. What a SIGKILL leaves, ``salvage``
  rewrites as an indexed file;
- a full disk (``ENOSPC``, ``EDQUOT``, ``EFBIG``) raises :class:`DiskFullError` once;
  the file is cut back to the end of its last chunk that reached the disk and closed
  with a footer that has no index (50 bytes; MCAP readers then scan it), so it stays
  readable; if even that does not fit, it ends at that chunk, which ``salvage`` reads.
  Later writes are dropped (:attr:`RecordingWriter.dropped`) (issue 27).
"""

from __future__ import annotations

import contextlib
import errno
import os
import struct
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from types import TracebackType
from typing import IO

from mcap.writer import MCAP0_MAGIC as _MAGIC
from mcap.writer import CompressionType

from otonav._version import __version__
from otonav.msgs import Message
from otonav.msgs._flat import real_type
from otonav.record._diskfull import DiskFullError, is_disk_full
from otonav.record._fastwriter import FastWriter
from otonav.record._qos_profile import offered_qos_yaml
from otonav.record._schemas import schema_for
from otonav.record._type_hash import rihs01
from otonav.record.cdr import encode
from otonav.runtime._qos import QoS

CHUNK_SIZE = 64 * 1024

FORMAT_METADATA = "otonav.recording"
"""The metadata record every recording starts with: ``format_version``."""
FORMAT_VERSION = 2
"""What a run's bytes mean besides the messages' types: the engine's order within an
instant. A replay of a recording of another version says what differs (ADR 0084)."""
FORMAT_CHANGES: dict[int, str] = {
    2: (
        "a /wheel_cmd is applied to the hardware in its publisher's call, no longer a "
        "pass later by the bridge's own task: a reading later in the same instant (the "
        "IMU's linear acceleration) sees the new command"
    ),
}
"""What each version changed from the one before (version 1: no record)."""


def format_difference(recorded: int) -> str | None:
    """What differs between a recording of format ``recorded`` and this otonav's; None
    when they are the same."""
    if recorded == FORMAT_VERSION:
        return None
    newer, older = max(recorded, FORMAT_VERSION), min(recorded, FORMAT_VERSION)
    changes = "; ".join(
        f"format {v}: {FORMAT_CHANGES.get(v, 'unknown to this otonav')}"
        for v in range(older + 1, newer + 1)
    )
    return (
        f"the recording is format_version {recorded}, this otonav writes {FORMAT_VERSION} "
        f"({changes})"
    )


# DataEnd (CRC 0: not computed) and a Footer with no summary section, then the magic:
# what closes a data section nobody can index any more (MCAP spec, records 0x0F, 0x02).
_BARE_END = struct.pack("<BQI", 0x0F, 4, 0) + struct.pack("<BQQQI", 0x02, 20, 0, 0, 0) + _MAGIC


def _library() -> str:
    # The code's version, never the installed metadata on disk (otonav/_version.py).
    return f"otonav {__version__}"


class RecordingGoneError(FileNotFoundError):
    """The file was deleted (or replaced) while the run wrote it, e.g. its ``--out``
    directory was removed: what was written went nowhere (issue 41)."""

    def __init__(self, path: Path) -> None:
        super().__init__(
            errno.ENOENT,
            f"the recording was deleted while the run wrote it (was {path.parent} removed?); "
            "nothing of the run was kept",
            str(path),
        )


def _still_at(path: Path, file: IO[bytes]) -> bool:
    """``file`` is still the file at ``path`` (not deleted, not replaced)."""
    try:
        here = os.stat(path)
    except FileNotFoundError:
        return False
    held = os.fstat(file.fileno())
    return (here.st_dev, here.st_ino) == (held.st_dev, held.st_ino)


class RecordingWriter:
    """Append messages of any otonav type on any topic; channels appear on first use."""

    def __init__(self, path: str | Path, *, chunk_size: int = CHUNK_SIZE) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: IO[bytes] = open(self.path, "wb")  # noqa: SIM115 - closed in finish()
        self._writer = FastWriter(
            self._file, chunk_size=chunk_size, compression=CompressionType.ZSTD
        )
        self._writer.start(profile="ros2", library=_library())
        self._writer.add_metadata(FORMAT_METADATA, {"format_version": str(FORMAT_VERSION)})
        self._file.flush()
        self._good = self._file.tell()  # the end of what is on disk, at a record boundary
        self.failed: DiskFullError | None = None
        """Set when the disk filled up: nothing more is written."""
        self.dropped = 0
        """Messages not written because the disk was full."""
        self._schemas: dict[type[Message], int] = {}
        self._channels: dict[str, int] = {}
        self._sequence: dict[int, int] = {}
        self.messages = 0
        self.finished = False
        self.offered_qos: Callable[[str], Sequence[QoS]] = lambda _topic: ()
        """The QoS profiles a topic's publishers offer, asked once when its channel
        opens (the recorder answers from the bus); none: ROS 2's default profile."""

    def _channel(self, topic: str, kind: type[Message]) -> int:
        schema_id = self._schemas.get(kind)
        if schema_id is None:
            name, definition = schema_for(kind)
            schema_id = self._writer.register_schema(name, "ros2msg", definition.encode())
            self._schemas[kind] = schema_id
        # The ros2 profile's required key, and the type hash rosbag2 (Jazzy) adds.
        metadata = {
            "offered_qos_profiles": offered_qos_yaml(self.offered_qos(topic)),
            "topic_type_hash": rihs01(kind),
        }
        channel_id = self._writer.register_channel(topic, "cdr", schema_id, metadata)
        self._channels[topic] = channel_id
        self._sequence[channel_id] = 0
        return channel_id

    def write(self, topic: str, message: Message, sim_time: float) -> bool:
        """Record ``message`` on ``topic`` at ``sim_time`` seconds (log and publish time).
        True when this completed a chunk (it is in the file now)."""
        if self.failed is not None:
            self.dropped += 1
            return False
        try:
            channel_id = self._channels.get(topic)
            if channel_id is None:
                channel_id = self._channel(topic, real_type(type(message)))
            stamp = round(sim_time * 1e9)
            self._sequence[channel_id] += 1
            # Messages accumulate in memory until a chunk is full; when one was written,
            # it goes to the OS at once. (Asking the file its position after every message
            # instead cost an lseek syscall per message.)
            chunk = self._writer.add_message_and_check(
                channel_id, stamp, encode(message), stamp, self._sequence[channel_id]
            )
            if chunk:
                self._flush()
        except OSError as exc:
            raise self._disk_full(exc) from exc
        self.messages += 1
        return chunk

    def _flush(self) -> None:
        self._file.flush()
        self._good = self._file.tell()

    def write_all(self, deliveries: Iterable[tuple[str, float, Message]]) -> None:
        """:meth:`write` each ``(topic, sim_time, message)`` in order (a recorder's
        drain): the same records, encoded one after another and handed to the MCAP
        writer as one batch (:meth:`FastWriter.add_batch`), split where a message opens
        a new channel (its channel record goes into the chunk before that message, as
        :meth:`write` puts it). A subclass that overrides :meth:`write` gets its
        :meth:`write` called."""
        if type(self).write is not RecordingWriter.write:
            for topic, sim_time, message in deliveries:
                self.write(topic, message, sim_time)
            return
        if self.failed is not None:
            self.dropped += sum(1 for _ in deliveries)
            return
        try:
            self._write_all(deliveries)
        except OSError as exc:
            raise self._disk_full(exc) from exc

    def _write_all(self, deliveries: Iterable[tuple[str, float, Message]]) -> None:
        channels, sequences = self._channels, self._sequence
        batch: list[tuple[int, int, bytes, int, int]] = []
        append = batch.append
        chunks = 0
        # A publisher's batch (the CAN tap's flush: ~13 frames) arrives as a run of one
        # topic and instant, and the messages of an instant share it: the channel and the
        # stamp are looked up when they change (0.12 us a frame less, measured).
        last_topic: str | None = None
        last_time: float | None = None
        channel_id = stamp = 0
        try:
            for topic, sim_time, message in deliveries:
                if topic is not last_topic:
                    found = channels.get(topic)
                    if found is None:
                        chunks += self._add_batch(batch)
                        found = self._channel(topic, real_type(type(message)))
                    channel_id, last_topic = found, topic
                if sim_time != last_time:
                    stamp, last_time = round(sim_time * 1e9), sim_time
                sequence = sequences[channel_id] = sequences[channel_id] + 1
                append((channel_id, stamp, encode(message), stamp, sequence))
        finally:
            # What was encoded is written even when a later message fails to encode
            # (write() would have written each one before the failure, too).
            chunks += self._add_batch(batch)
            if chunks:
                self._flush()

    def _add_batch(self, batch: list[tuple[int, int, bytes, int, int]]) -> int:
        if not batch:
            return 0
        chunks = self._writer.add_batch(batch)
        self.messages += len(batch)
        batch.clear()
        return chunks

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        if self.failed is not None:
            return
        try:
            self._writer.add_metadata(name, data)
        except OSError as exc:
            raise self._disk_full(exc) from exc

    def finish(self) -> None:
        """Write the footer and index and close the file; safe to call twice. A full
        disk raises :class:`DiskFullError` (once: then the file is closed as it can be)."""
        if self.finished:
            return
        self.finished = True
        try:
            try:
                self._writer.finish()  # type: ignore[no-untyped-call]
                self._file.flush()
                here = _still_at(self.path, self._file)
            finally:
                self._file.close()
        except OSError as exc:
            raise self._disk_full(exc) from exc
        if not here:
            raise RecordingGoneError(self.path)

    def _disk_full(self, exc: OSError) -> OSError | DiskFullError:
        """On a full disk: close the file readable (see the module), remember and return
        the :class:`DiskFullError`; any other OSError is returned as it is."""
        if not is_disk_full(exc):
            return exc
        self.finished = True
        with contextlib.suppress(OSError):
            self._file.close()  # its buffer cannot be flushed: the close still closes
        good, path = self._good, self.path
        try:
            with open(path, "r+b") as f:
                f.truncate(good)
                f.seek(good)
                f.write(_BARE_END)
            kept = "closed without an index (readable)"
        except OSError:
            with contextlib.suppress(OSError):
                os.truncate(path, good)
            kept = "cut off after its last complete chunk"
        self.failed = DiskFullError(path, exc, f"the recording was {kept} at {good} bytes")
        return self.failed

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.finish()
