"""``otonav play RECORDING``: the recording onto DDS at its recorded pace, with its /clock,
as ``ros2 bag play --clock`` does, so a ROS 2 node (``use_sim_time``) runs against it.
Exit 0 when played; 2: bad input (one line); 130: Ctrl-C."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any


def add_parser(commands: Any) -> None:
    p = commands.add_parser(
        "play",
        help="play a recording onto ROS 2 (DDS) at its recorded pace, /clock included",
        description=(
            "Write every topic of a recording on its DDS topic (rt/odom ...) with the QoS "
            "it was recorded with, at its recorded pace: a ROS 2 node with use_sim_time "
            "follows the recording's /clock (ros2 bag play --clock). Stays on this host "
            "unless ROS_AUTOMATIC_DISCOVERY_RANGE says otherwise."
        ),
    )
    p.add_argument("recording", type=Path, help="an MCAP recording (e.g. out/recording.mcap)")
    p.add_argument(
        "--rate", type=float, default=1.0, metavar="R", help="speed, (0, 1000] (default 1)"
    )
    p.add_argument(
        "--topic",
        dest="topics",
        action="append",
        default=[],
        metavar="TOPIC",
        help="play only this topic (repeatable; default: every topic)",
    )
    p.add_argument(
        "--ros2-domain",
        type=int,
        default=None,
        metavar="N",
        help="DDS domain 0..232 (default: ROS_DOMAIN_ID, else 0)",
    )
    p.add_argument(
        "--wait",
        type=float,
        default=None,
        metavar="S",
        help="hold the start until a ROS 2 node subscribed, at most S wall seconds",
    )
    p.set_defaults(handler=main)


def main(args: argparse.Namespace) -> int:
    from otonav.ros2._naming import Ros2Error

    if args.wait is not None and not 0 < args.wait <= 3600:
        raise Ros2Error(f"--wait {args.wait}: must be a number of seconds in (0, 3600]")
    from otonav.ros2._play import play

    def started(domain: int, topics: Sequence[str]) -> None:
        print(
            f"play: {len(topics)} topics on DDS domain {domain} at {args.rate:g}x",
            file=sys.stderr,
            flush=True,
        )

    result = play(
        args.recording,
        rate=args.rate,
        topics=args.topics,
        domain=args.ros2_domain,
        wait=args.wait,
        env=os.environ,
        on_start=started,
    )
    skipped = f"; not played (type unknown): {', '.join(result.skipped)}" if result.skipped else ""
    print(
        f"played {result.sent} messages, {result.sim_span:.2f} s of sim time{skipped}",
        file=sys.stderr,
    )
    return 0
