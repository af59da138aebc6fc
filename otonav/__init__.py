"""otonav: a deterministic, faster-than-real-time robot stack of asyncio actors on MuJoCo.

Layers, top to bottom; imports point down only (import-linter contracts in pyproject.toml):
    cli, testing       what users touch: ``python -m otonav``, the pytest plugin and fixtures
    scenario           run a scenario in sim time, judge it from ground truth, plot it
    stack              the launch file as data: pydantic config -> world + actors
    actors             bridge, base controller, navigator, recorder: subscribe, compute, publish
    record             MCAP recordings in ROS 2 CDR: write, read, info, salvage
    hal                RobotHardwareInterface, FakeHardware; only hal.mujoco imports mujoco;
                       hal.can (wheels over CAN, only hal.can.bus imports python-can);
                       hal.sim (the drive emulator: test equipment, never robot code)
    nav, control       pure math: go-to-goal, obstacle guard, diff-drive kinematics
    msgs, runtime      ROS 2-shaped messages; virtual-time loop, actors, topics, QoS, waits
"""

from otonav._version import __version__

__all__ = ["__version__"]
