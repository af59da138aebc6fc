"""The actors: thin adapters that subscribe, call a pure function, and publish."""

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
)
