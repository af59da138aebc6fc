"""ROS 2 over DDS (``otonav run --ros2``, the extra ``otonav[ros2]``): the bridge actor
(:mod:`otonav.ros2._bridge`), the naming and QoS rules of rmw_cyclonedds as plain data
(:mod:`otonav.ros2._naming`), and the one module that imports cyclonedds
(:mod:`otonav.ros2._dds`, imported only when a bridge is made). docs/adr/0047."""

from otonav.ros2._bridge import Ros2Bridge, Ros2Statistics
from otonav.ros2._naming import Ros2Error

__all__ = ("Ros2Bridge", "Ros2Error", "Ros2Statistics")
