"""A DDS participant in a process of its own that writes raw CDR payloads on rt/goal, or
on rt/cmd_vel_nav (reliable, volatile: ``ros2 topic pub``'s offer), one per hex line read
from stdin, so a
test can send what no well-behaved node would. Prints ``matched`` once the bridge's goal
reader matched, then ``N written`` after each payload (``N refused``: Cyclone's writer
would not take it: it checks a payload's size against the type's).

    python dds_fuzz_peer.py DOMAIN [goal | cmd_vel_nav]
"""

from __future__ import annotations

import os
import sys

from otonav.msgs import Message, PoseStamped, Twist
from otonav.ros2._dds import Participant
from otonav.ros2._naming import dds_qos, discovery
from otonav.runtime import QoS

HANG = 30.0
"""Wall seconds a wait for the bridge may take: a hang."""


def main() -> None:
    participant = Participant(int(sys.argv[1]), discovery(os.environ).config)
    topic = sys.argv[2] if len(sys.argv) > 2 else "goal"
    kinds: dict[str, type[Message]] = {"goal": PoseStamped, "cmd_vel_nav": Twist}
    kind = kinds[topic]
    writer = participant.writer(f"rt/{topic}", kind, dds_qos(QoS(depth=1), kind))
    if not participant.wait(lambda: writer.matched.count > 0, HANG):
        sys.exit(f"the bridge's {topic} reader never matched")
    print("matched", flush=True)
    for n, line in enumerate(sys.stdin, 1):
        written = writer.write(bytes.fromhex(line.strip()))
        print(f"{n} {'written' if written else 'refused'}", flush=True)
    participant.close()


if __name__ == "__main__":
    main()
