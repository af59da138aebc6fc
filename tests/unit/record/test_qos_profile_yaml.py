"""The offered_qos_profiles text is formatted directly (ADR 0058); it must stay the text
``yaml.safe_dump`` gives for the same profiles, which rosbag2 and our own tools parse."""

from __future__ import annotations

import itertools

import yaml

from otonav.record._qos_profile import offered_qos_profiles, offered_qos_yaml
from otonav.runtime._qos import MAX_DEPTH, Durability, QoS, Reliability


def _by_dump(offered: list[QoS]) -> str:
    text: str = yaml.safe_dump(
        offered_qos_profiles(offered), default_flow_style=False, sort_keys=False
    )
    return text.strip()


PROFILES = [
    QoS(reliability, depth, durability)
    for reliability, durability, depth in itertools.product(
        Reliability, Durability, (1, 5, 10, 100, 9999, MAX_DEPTH)
    )
]


def test_every_single_profile_is_the_dumped_text() -> None:
    for qos in PROFILES:
        assert offered_qos_yaml([qos]) == _by_dump([qos]), qos


def test_lists_of_profiles_and_none_are_the_dumped_text() -> None:
    assert offered_qos_yaml([]) == _by_dump([])  # ROS 2's default profile
    for n in (2, 3, 5):
        offered = PROFILES[n::5][:n]
        assert offered_qos_yaml(offered) == _by_dump(offered)


def test_the_text_parses_back_to_the_profiles() -> None:
    offered = PROFILES[:4]
    assert yaml.safe_load(offered_qos_yaml(offered)) == offered_qos_profiles(offered)
