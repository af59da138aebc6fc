"""The actors: thin adapters that subscribe, call a pure function, and publish."""

from otonav.actors.base_controller import BaseController, BaseLimits
from otonav.actors.bridge import Bridge
from otonav.actors.navigator import Navigator

__all__ = ("BaseController", "BaseLimits", "Bridge", "Navigator")
