"""Test equipment at the far end of the HAL: the ODrive drive emulator.

Never imported by robot code (an import-linter contract): only the stack builder, which
composes a simulated robot, and tests use it.
"""

from otonav.hal.sim._emulator import DriveEmulator, DriveMount
from otonav.hal.sim._odrive import AxisModel, AxisParams
from otonav.hal.sim._schedule import BusFaults

__all__ = ("AxisModel", "AxisParams", "BusFaults", "DriveEmulator", "DriveMount")
