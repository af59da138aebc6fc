"""otonav: a deterministic, faster-than-real-time robot stack of asyncio actors on MuJoCo.

Layers, top to bottom; imports point down only (import-linter contracts in pyproject.toml):
    cli, testing, embed  what users touch: ``python -m otonav``, the pytest plugin and
                         fixtures, a live stack and fast runs inside an asyncio service
    engine               what the entry points share above the stack: the config's optional
                         sections (foxglove, ros2) wired in one place
    sweep, replay, ros2, foxglove
                         families of runs on a pool or Ray (sweep.backends); re-simulating
                         actors against a recording; the ROS 2 bridge over DDS (only ros2.dds
                         imports cyclonedds); the Foxglove live view (only foxglove.protocol
                         imports websockets)
    scenario             run a scenario in sim time, judge it from ground truth, plot it
    stack                the launch file as data: robot description + actors -> world + actors
    actors               bridge, base controller, navigator, safety layer, recorder
    record               MCAP recordings in ROS 2 CDR (record.cdr: the codec, both ways):
                         write, read, info, salvage, bags
    hal                  RobotHardwareInterface, FakeHardware, robot descriptions, the viewer
                         window; hal.mujoco (the MuJoCo world: scene, prepare, derive, world;
                         only its _lib imports mujoco); hal.can (wheels over CAN, only
                         hal.can.bus imports python-can); hal.sim (the drive emulator: test
                         equipment)
    nav, control         pure math: planning, the safety limit, diff-drive kinematics
    msgs, runtime        ROS 2-shaped messages; virtual-time loop, actors, topics, QoS, waits
    errors               OtonavError and UsageError (bad input: one line, exit 2)
Beside them: bench (the stack's own benchmarks), limits (every bound and why), params
(the parameter models: every default once; numpy-free, the config and the nav math read it).
"""

from otonav._version import __version__

__all__ = ["__version__"]
