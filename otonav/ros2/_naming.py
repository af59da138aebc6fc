"""What a ROS 2 node on Cyclone DDS puts on the wire, as plain data (no cyclonedds here).

Each rule is rmw_cyclonedds_cpp's (``rmw_node.cpp``; docs/adr/0047 cites the lines):

- a topic ``/odom`` is the DDS topic ``rt/odom`` (``ROS_TOPIC_PREFIX`` + the name);
- a type ``nav_msgs/msg/Odometry`` is ``nav_msgs::msg::dds_::Odometry_``;
- QoS (``create_readwrite_qos``): history keep-last ``depth``; reliable with an infinite
  max blocking time, or best-effort; transient-local with a durability service keeping
  the same history; deadline and lifespan unset (infinite); liveliness automatic with an
  infinite lease; writers do not auto-dispose; ``USER_DATA`` carries
  ``typehash=RIHS01_...;`` (Iron and later, ``rmw_dds_common``);
- payloads are XCDR1, little endian, as in the bags (:mod:`otonav.record.cdr`): the
  data representation a Cyclone writer takes by default for a final type;
- discovery (``check_create_domain``): ``LOCALHOST`` turns multicast off and lists
  ``localhost`` as a peer with participant indices ``auto`` (at most 32).

Two settings rmw_cyclonedds does not need and otonav does, to talk to ROS 2's default
rmw (Fast DDS; measured against Jazzy's and Kilted's rclpy, docs/adr/0065):

- on LOCALHOST the interface is ``lo``: Cyclone 11 drops SPDP that arrives on an interface
  it did not select, and it selects eth0, so a Fast DDS node that started after the
  bridge was never discovered;
- Fast DDS's XTypes type information is ignored (vendor 1.15) and types match by name,
  as with Jazzy: Fast DDS 3 (Kilted) announces type objects for types with arrays or
  sequences that Cyclone rejects as invalid ("ddsi_xt_type_add_typeobj with invalid
  type object" on the terminal), and its readers of /odom, /scan and /imu then never
  matched.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Final

from otonav.errors import UsageError
from otonav.msgs import Message
from otonav.record._type_hash import rihs01
from otonav.runtime import Durability, QoS, Reliability

__all__ = (
    "MAX_DOMAIN_ID",
    "DdsQos",
    "Discovery",
    "Ros2Error",
    "dds_qos",
    "dds_topic",
    "dds_type_name",
    "discovery",
    "domain_id",
)

MAX_DOMAIN_ID: Final = 232
"""The highest domain id whose RTPS ports fit (7400 + 250 * id + offsets < 65536)."""

TOPIC_PREFIX: Final = "rt"
_ROS_NAME = re.compile(r"^(/[A-Za-z_][A-Za-z0-9_]*)+$")

_FAST_DDS_TYPES: Final = (
    "<Compatibility><IgnoreTypeInformation>1.15</IgnoreTypeInformation></Compatibility>"
)
LOCALHOST_CONFIG: Final = (
    "<CycloneDDS><Domain><General><AllowMulticast>false</AllowMulticast>"
    '<Interfaces><NetworkInterface name="lo"/></Interfaces></General>'
    "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
    "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"
    f'<Peers><Peer address="localhost"/></Peers></Discovery>{_FAST_DDS_TYPES}'
    "</Domain></CycloneDDS>"
)
"""rmw_cyclonedds_cpp's configuration for ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``,
on the loopback interface, with Fast DDS's type information ignored."""
NETWORK_CONFIG: Final = f"<CycloneDDS><Domain>{_FAST_DDS_TYPES}</Domain></CycloneDDS>"
"""Cyclone's defaults (multicast on its interfaces), with Fast DDS's type information
ignored."""
LOCKSTEP_CONFIG: Final = (
    "<CycloneDDS><Domain><Internal>"
    '<HeartbeatInterval min="1ms" minsched="1ms">1ms</HeartbeatInterval>'
    "</Internal></Domain></CycloneDDS>"
)
"""In lockstep, a writer's heartbeat every 1 ms instead of 100: the bridge waits for the
node's acknowledgement of /odom before each /clock it answers (docs/adr/0065), and a
reader acknowledges only when a heartbeat asks."""


class Ros2Error(UsageError):
    """The ROS 2 bridge cannot start: one line naming the flag, key or variable."""


def dds_topic(name: str) -> str:
    """``/odom`` -> ``rt/odom`` (a ROS 2 topic on DDS)."""
    if not _ROS_NAME.match(name):
        raise Ros2Error(f"{name!r}: not a ROS 2 topic name (like /odom or /nav/state)")
    return TOPIC_PREFIX + name


def dds_type_name(message: type[Message]) -> str:
    """``nav_msgs/msg/Odometry`` -> ``nav_msgs::msg::dds_::Odometry_``."""
    package, kind, name = message.ros_type.split("/")
    return f"{package}::{kind}::dds_::{name}_"


@dataclass(frozen=True, slots=True)
class DdsQos:
    """The DDS policies of one ROS 2 endpoint (what ``create_readwrite_qos`` sets)."""

    reliable: bool
    depth: int
    transient_local: bool
    user_data: bytes
    """``typehash=RIHS01_<sha256>;``"""


def dds_qos(qos: QoS, message: type[Message]) -> DdsQos:
    """otonav's QoS of a topic carrying ``message``, as ROS 2 offers it on DDS."""
    return DdsQos(
        reliable=qos.reliability is Reliability.RELIABLE,
        depth=qos.depth,
        transient_local=qos.durability is Durability.TRANSIENT_LOCAL,
        user_data=f"typehash={rihs01(message)};".encode(),
    )


def domain_id(value: int | None, env: Mapping[str, str]) -> int:
    """The DDS domain: ``value`` (a flag or config key) or ``ROS_DOMAIN_ID`` or 0."""
    if value is None:
        text = env.get("ROS_DOMAIN_ID", "").strip()
        if not text:
            return 0
        if not text.isdigit():
            raise Ros2Error(f"ROS_DOMAIN_ID={text!r}: must be a whole number 0..{MAX_DOMAIN_ID}")
        value, source = int(text), "ROS_DOMAIN_ID"
    else:
        source = "--ros2-domain"
    if not 0 <= value <= MAX_DOMAIN_ID:
        raise Ros2Error(f"{source} {value}: must be 0..{MAX_DOMAIN_ID} (ROS 2 uses 0..101 safely)")
    return value


@dataclass(frozen=True, slots=True)
class Discovery:
    """How far the bridge is seen: a Cyclone configuration and the line that says it."""

    config: str
    """XML given to the domain, then ``CYCLONEDDS_URI``'s (see :func:`discovery`)."""
    scope: str
    localhost: bool


def discovery(env: Mapping[str, str], *, lockstep: bool = False) -> Discovery:
    """ROS 2's discovery range from the environment; localhost unless asked otherwise.

    ``ROS_LOCALHOST_ONLY=1`` or ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` (or neither
    set: otonav's default, unlike ROS 2 Jazzy's SUBNET) keep it on this host; ``SUBNET``
    and ``SYSTEM_DEFAULT`` use Cyclone's defaults (multicast on every interface). ``OFF``
    would make the bridge invisible and is refused. ``CYCLONEDDS_URI`` still applies
    after ours, as in rmw_cyclonedds (Cyclone does not read it once a configuration is
    given: it is appended here). ``lockstep`` adds :data:`LOCKSTEP_CONFIG`.
    """
    extra = (LOCKSTEP_CONFIG,) if lockstep else ()
    localhost_only = env.get("ROS_LOCALHOST_ONLY", "").strip() == "1"
    wanted = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "").strip().upper()
    if localhost_only or wanted in ("", "LOCALHOST"):
        config = _with_uri((LOCALHOST_CONFIG, *extra), env)
        return Discovery(config, "this host only (localhost)", True)
    if wanted in ("SUBNET", "SYSTEM_DEFAULT"):
        scope = f"the network (ROS_AUTOMATIC_DISCOVERY_RANGE={wanted})"
        return Discovery(_with_uri((NETWORK_CONFIG, *extra), env), scope, False)
    if wanted == "OFF":
        raise Ros2Error(
            "ROS_AUTOMATIC_DISCOVERY_RANGE=OFF: no ROS 2 node could see the bridge "
            "(use LOCALHOST or SUBNET)"
        )
    raise Ros2Error(
        f"ROS_AUTOMATIC_DISCOVERY_RANGE={wanted}: must be LOCALHOST, SUBNET, SYSTEM_DEFAULT or OFF"
    )


def _with_uri(configs: tuple[str, ...], env: Mapping[str, str]) -> str:
    """``configs`` then the user's ``CYCLONEDDS_URI`` (a comma-separated list of files and
    XML, which Cyclone reads in order, the later overriding)."""
    user = env.get("CYCLONEDDS_URI", "").strip()
    return ",".join((*configs, user) if user else configs)
