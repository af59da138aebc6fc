"""Recordings: MCAP files of ROS 2 CDR messages (profile ``ros2``), written, read,
summarised, salvaged after a cut-off, and laid out as a rosbag2 bag directory.

- write: :class:`RecordingWriter` (one file), :class:`RotatingRecordingWriter` (a new
  file every N bytes, for long-lived services); the stack's recorder actor uses them;
- read: :func:`read_messages` (:mod:`otonav.msgs` messages in log-time order),
  :func:`summarize_recording` (``otonav info``); a damaged file is a :class:`DamagedRecordingError`;
- repair: :func:`salvage` (what a killed writer left, as a readable, indexed copy);
- ROS 2: :func:`write_bag_directory` (``metadata.yaml`` beside the file, for
  ``ros2 bag`` and rosbags).

Each name is imported on first use (``otonav info`` reads a file without loading the
writer's dependencies).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from otonav.record.bag import write_bag_directory
    from otonav.record.reader import (
        DamagedRecordingError,
        RecordingError,
        RecordingSummary,
        TopicSummary,
        read_messages,
    )
    from otonav.record.reader import summarize as summarize_recording
    from otonav.record.rotating import RotatingRecordingWriter
    from otonav.record.salvage import salvage
    from otonav.record.writer import RecordingWriter

__all__ = (
    "DamagedRecordingError",
    "RecordingError",
    "RecordingSummary",
    "RecordingWriter",
    "RotatingRecordingWriter",
    "TopicSummary",
    "read_messages",
    "salvage",
    "summarize_recording",
    "write_bag_directory",
)

_LAZY = {
    "write_bag_directory": "otonav.record.bag",
    "DamagedRecordingError": "otonav.record.reader",
    "RecordingError": "otonav.record.reader",
    "RecordingSummary": "otonav.record.reader",
    "TopicSummary": "otonav.record.reader",
    "read_messages": "otonav.record.reader",
    "summarize_recording": "otonav.record.reader",
    "RotatingRecordingWriter": "otonav.record.rotating",
    "salvage": "otonav.record.salvage",
    "RecordingWriter": "otonav.record.writer",
}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        # summarize_recording: reader's summarize (sweep.summarize is a sweep's summary)
        attr = "summarize" if name == "summarize_recording" else name
        return getattr(importlib.import_module(_LAZY[name]), attr)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
