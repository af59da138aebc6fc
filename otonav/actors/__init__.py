"""The actors: thin adapters that subscribe, call a pure function, and publish.

``topics`` is a public module: the stack's topic names and QoS profiles (``topics.ODOM``,
``topics.SENSOR_QOS``), as a ROS 2 interface package names them.
"""

from otonav.actors import _topics as topics
from otonav.actors._avoiding_navigator import AvoidingNavigator
from otonav.actors._base_controller import BaseController, BaseLimits
from otonav.actors._bridge import Bridge
from otonav.actors._command_watch import EXTERNAL_COMMAND_WAIT, CommandWatch
from otonav.actors._navigator import Navigator
from otonav.actors._safety_layer import SafetyLayer

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
