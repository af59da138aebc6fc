"""A recording that never grows without limit: when the current file passes
``max_bytes`` (checked each time a chunk is written), it is finished (an indexed file)
and renamed ``NAME.1.mcap`` (the older ones move to ``.2``, ``.3``, ...; at most ``keep``
of them stay), and a new ``NAME.mcap`` starts with the same start-of-recording metadata
records. Disk use stays under about ``(keep + 1) * max_bytes`` plus one chunk.

For long-lived recordings (a service's live robot); a scenario run's recording is
bounded by its sim budget and needs none of this."""

from __future__ import annotations

from pathlib import Path

from otonav.msgs import Message
from otonav.record._writer import CHUNK_SIZE, RecordingWriter


class RotatingRecordingWriter(RecordingWriter):
    """A :class:`RecordingWriter` on ``path`` that rotates at ``max_bytes``."""

    def __init__(
        self, path: str | Path, *, max_bytes: int, keep: int = 1, chunk_size: int = CHUNK_SIZE
    ) -> None:
        if max_bytes < chunk_size:
            raise ValueError(f"max_bytes must be at least one chunk ({chunk_size}): {max_bytes}")
        if keep < 0:
            raise ValueError(f"keep must be >= 0, got {keep}")
        super().__init__(path, chunk_size=chunk_size)
        self.max_bytes = max_bytes
        self.keep = keep
        self.rotations = 0
        self._chunk_size = chunk_size
        self._start_metadata: list[tuple[str, dict[str, str]]] = []

    def rotated(self, n: int) -> Path:
        """The path of the ``n``-th newest finished file (1: the last one rotated out)."""
        return self.path.with_name(f"{self.path.stem}.{n}{self.path.suffix}")

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        if self.messages == 0:  # a start-of-recording record: every file gets it
            self._start_metadata.append((name, dict(data)))
        super().add_metadata(name, data)

    def write(self, topic: str, message: Message, sim_time: float) -> bool:
        chunk = super().write(topic, message, sim_time)
        if chunk and self._file.tell() >= self.max_bytes:  # the size moves by chunks
            self._rotate()
        return chunk

    def _rotate(self) -> None:
        super().finish()
        for n in range(self.keep, 0, -1):
            older = self.path if n == 1 else self.rotated(n - 1)
            if older.exists():
                older.replace(self.rotated(n))
        if self.keep == 0:
            self.path.unlink()
        start, messages, offered = self._start_metadata, self.messages, self.offered_qos
        # A fresh file under the same name: the base class's own set-up, again.
        RecordingWriter.__init__(self, self.path, chunk_size=self._chunk_size)
        self.messages, self.offered_qos = messages, offered
        for name, data in start:
            super().add_metadata(name, data)
        self.rotations += 1
