"""Recording throughput: encode (CDR) + write (MCAP, zstd, 64 KiB chunks) for a 360-beam
LaserScan and for Odometry, messages per second, median of N runs, against the
generic mcap_ros2 encoder measured in the same run.

    python benchmarks/record_bench.py [--n 10000] [--reps 5]
"""

from __future__ import annotations

import argparse
import math
import statistics
import tempfile
import time
from pathlib import Path

from mcap_ros2.writer import Writer as Ros2Writer

from otonav.msgs import (
    Header,
    LaserScan,
    Message,
    Odometry,
    Point,
    Pose,
    PoseWithCovariance,
    Quaternion,
    Time,
)
from otonav.record._schemas import schema_for
from otonav.record._writer import RecordingWriter


def _scan(i: int) -> LaserScan:
    return LaserScan(
        header=Header(stamp=Time.from_seconds(i * 0.1), frame_id="laser"),
        angle_min=-math.pi,
        angle_max=math.pi,
        angle_increment=2 * math.pi / 360,
        range_min=0.12,
        range_max=8.0,
        ranges=tuple(1.0 + 0.001 * ((i + k) % 1000) for k in range(360)),
    )


def _odom(i: int) -> Odometry:
    return Odometry(
        header=Header(stamp=Time.from_seconds(i * 0.01), frame_id="odom"),
        child_frame_id="base_link",
        pose=PoseWithCovariance(
            pose=Pose(
                position=Point(x=0.001 * i, y=0.002 * i), orientation=Quaternion.from_yaw(0.01 * i)
            )
        ),
    )


def ours(messages: list[Message], topic: str, path: Path) -> float:
    start = time.perf_counter()
    with RecordingWriter(path) as writer:
        for i, message in enumerate(messages):
            writer.write(topic, message, i * 0.01)
    return len(messages) / (time.perf_counter() - start)


def generic(messages: list[Message], topic: str, path: Path) -> float:
    name, text = schema_for(type(messages[0]))
    start = time.perf_counter()
    with path.open("wb") as f:
        writer = Ros2Writer(f, chunk_size=64 * 1024)
        schema = writer.register_msgdef(name, text)
        for i, message in enumerate(messages):
            writer.write_message(topic, schema, message.model_dump(), log_time=i * 10_000_000)
        writer.finish()  # type: ignore[no-untyped-call]
    return len(messages) / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=10_000)
    parser.add_argument("--reps", type=int, default=5)
    args = parser.parse_args()
    cases: list[tuple[str, str, list[Message]]] = [
        ("LaserScan 360 beams", "/scan", [_scan(i) for i in range(args.n)]),
        ("Odometry", "/odom", [_odom(i) for i in range(args.n)]),
    ]
    with tempfile.TemporaryDirectory() as tmp:
        for label, topic, messages in cases:
            rates: dict[str, list[float]] = {"otonav": [], "mcap_ros2 generic": []}
            for rep in range(args.reps):
                rates["otonav"].append(ours(messages, topic, Path(tmp) / f"o{rep}.mcap"))
                rates["mcap_ros2 generic"].append(
                    generic(messages[: args.n // 5], topic, Path(tmp) / f"g{rep}.mcap")
                )
            mine, theirs = (statistics.median(r) for r in rates.values())
            print(
                f"{label:<20} otonav {mine:>9,.0f} msg/s   "
                f"mcap_ros2 generic {theirs:>8,.0f} msg/s   ratio {mine / theirs:.1f}x"
            )


if __name__ == "__main__":
    main()
