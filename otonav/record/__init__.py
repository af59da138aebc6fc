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
    from otonav.record._bag import write_bag_directory
    from otonav.record._reader import (
        DamagedRecordingError,
        RecordingError,
        RecordingSummary,
        TopicSummary,
        read_messages,
    )
    from otonav.record._reader import summarize as summarize_recording
    from otonav.record._rotating import RotatingRecordingWriter
    from otonav.record._salvage import salvage
    from otonav.record._writer import RecordingWriter

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
    "write_bag_directory": "otonav.record._bag",
    "DamagedRecordingError": "otonav.record._reader",
    "RecordingError": "otonav.record._reader",
    "RecordingSummary": "otonav.record._reader",
    "TopicSummary": "otonav.record._reader",
    "read_messages": "otonav.record._reader",
    "summarize_recording": "otonav.record._reader",
    "RotatingRecordingWriter": "otonav.record._rotating",
    "salvage": "otonav.record._salvage",
    "RecordingWriter": "otonav.record._writer",
}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        # summarize_recording: reader's summarize (sweep.summarize is a sweep's summary)
        attr = "summarize" if name == "summarize_recording" else name
        return getattr(importlib.import_module(_LAZY[name]), attr)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
