"""The actors: thin adapters that subscribe, call a pure function, and publish.

``topics`` is a public module: the stack's topic names and QoS profiles (``topics.ODOM``,
``topics.SENSOR_QOS``), as a ROS 2 interface package names them.
"""

from otonav.actors import topics
from otonav.actors.avoiding_navigator import AvoidingNavigator
from otonav.actors.base_controller import BaseController, BaseLimits
from otonav.actors.bridge import Bridge
from otonav.actors.command_watch import EXTERNAL_COMMAND_WAIT, CommandWatch
from otonav.actors.navigator import Navigator
from otonav.actors.safety_layer import SafetyLayer

__all__ = (
    "EXTERNAL_COMMAND_WAIT",
    "AvoidingNavigator",
    "BaseController",
    "BaseLimits",
    "Bridge",
    "CommandWatch",
    "Navigator",
    "SafetyLayer",
    "topics",
)
