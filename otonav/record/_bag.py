"""A rosbag2 bag directory around a finished recording (``--bag``; docs/adr/0044).

``ros2 bag info DIR``, ``ros2 bag play DIR`` and ``rosbags`` read a bag as a directory:
``metadata.yaml`` (``rosbag2_bagfile_information``, version 9 as ROS 2 Jazzy writes it)
beside the storage file. The recording is already what rosbag2_storage_mcap writes
(profile ``ros2``, CDR, ``ros2msg`` schemas, ``offered_qos_profiles`` and
``topic_type_hash`` per channel), so the directory is the same bytes, linked (or copied
where a link cannot be made), plus a metadata file derived from the MCAP's summary:
message counts per topic, start and duration, and each topic's QoS and type hash as
its channel carries them.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any, Final

import yaml
from mcap.exceptions import McapError
from mcap.reader import make_reader

__all__ = ("METADATA_VERSION", "write_bag_directory")

METADATA_VERSION: Final = 9
"""rosbag2's metadata version of ROS 2 Jazzy (QoS as a YAML list, enums by name)."""


class _Dumper(yaml.SafeDumper):
    """No ``&id``/``*id`` aliases for repeated values: each written out, as rosbag2 does."""

    def ignore_aliases(self, data: Any) -> bool:
        return True


def _place(recording: Path, target: Path) -> None:
    target.unlink(missing_ok=True)
    try:
        os.link(recording, target)  # the same bytes, no second copy on disk
    except OSError:  # another file system, or one without hard links
        shutil.copy2(recording, target)


def write_bag_directory(recording: Path, bag: Path) -> Path:
    """Make ``bag`` a rosbag2 directory holding ``recording`` (a finished, indexed
    MCAP) as ``<bag name>_0.mcap`` and its ``metadata.yaml``; returns ``bag``."""
    try:
        with recording.open("rb") as stream:
            summary = make_reader(stream).get_summary()
    except McapError:
        summary = None
    if summary is None or summary.statistics is None:
        raise ValueError(f"{recording}: no summary (an unfinished recording: salvage it first)")
    stats = summary.statistics
    bag.mkdir(parents=True, exist_ok=True)
    name = f"{bag.name}_0.mcap"
    count = stats.message_count
    start = stats.message_start_time if count else 0
    duration = stats.message_end_time - stats.message_start_time if count else 0
    topics: list[dict[str, Any]] = []
    for channel_id in sorted(summary.channels):
        channel = summary.channels[channel_id]
        schema = summary.schemas.get(channel.schema_id)
        if schema is None:
            raise ValueError(f"{recording}: channel '{channel.topic}' has no schema")
        qos = yaml.safe_load(channel.metadata.get("offered_qos_profiles", "")) or []
        topics.append(
            {
                "topic_metadata": {
                    "name": channel.topic,
                    "type": schema.name,
                    "serialization_format": channel.message_encoding,
                    "offered_qos_profiles": qos,
                    "type_description_hash": channel.metadata.get("topic_type_hash", ""),
                },
                "message_count": stats.channel_message_counts.get(channel_id, 0),
            }
        )
    span = {"starting_time": {"nanoseconds_since_epoch": start}}
    information = {
        "version": METADATA_VERSION,
        "storage_identifier": "mcap",
        "duration": {"nanoseconds": duration},
        **span,
        "message_count": count,
        "topics_with_message_count": topics,
        "compression_format": "",
        "compression_mode": "",
        "relative_file_paths": [name],
        "files": [
            {"path": name, **span, "duration": {"nanoseconds": duration}, "message_count": count}
        ],
        "custom_data": {"recorded_by": "otonav"},
        "ros_distro": "jazzy",
    }
    _place(recording, bag / name)
    text = yaml.dump(
        {"rosbag2_bagfile_information": information},
        Dumper=_Dumper,
        default_flow_style=False,
        sort_keys=False,
    )
    temporary = bag / "metadata.yaml.tmp"
    temporary.write_text(text, encoding="utf-8")
    temporary.replace(bag / "metadata.yaml")
    return bag
