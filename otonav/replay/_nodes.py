"""Which actors replay can bring up, by name, and how.

The registry is the stack itself: every actor :func:`~otonav.stack.build_actors` makes
from a config is replayable under its own name (``nav``, ``base``, and whatever the
stack gains, e.g. a safety layer), except those that own the hardware, whose inputs
are physics rather than topics. A user's actor comes by import path,
``package.module:Name``, where ``Name`` is an :class:`~otonav.runtime.Actor` subclass
built with no arguments, or a callable ``f(stack: StackConfig) -> Actor``.

An actor is replayed through its declared ports only (``Actor.ports()``): its inputs
are fed from the recording, its outputs compared with it, so a new actor needs nothing
here beyond being built by the stack or named by path.

The actors are built for the recorded robot: given its recorded geometry
(:mod:`otonav.replay._world`), no world is built unless an actor asks for more than the
geometry; without it (an older recording, or ``--set world.*``), the robot model is
compiled as the stack does.
"""

from __future__ import annotations

import importlib
from collections.abc import Sequence

from otonav.hal import RobotGeometry, RobotHardwareInterface
from otonav.hal._types import Reach
from otonav.hal.mujoco import SceneError
from otonav.replay._recording import ReplayInputError
from otonav.replay._world import RecordedRobot
from otonav.runtime import Actor
from otonav.stack import StackConfig, build_actors, build_world

RecordedReach = tuple[tuple[float, float], Reach] | None
"""What a recording says its robot was identified to reach (ADR 0066), if it says."""

NOT_REPLAYABLE: dict[str, str] = {
    "bridge": "it owns the hardware: its inputs are physics, not topics",
    "can_tap": "it reads the CAN bus, not topics",
}
"""Stack actors that cannot be replayed, and why."""


def stack_actor_names(stack: StackConfig, geometry: RobotGeometry | None = None) -> list[str]:
    """The names of the actors the stack builds from ``stack`` that replay can run."""
    return [a.name for a in _stack_actors(stack, geometry) if a.name not in NOT_REPLAYABLE]


def _stack_actors(
    stack: StackConfig,
    geometry: RobotGeometry | None,
    start: tuple[float, float, float] = (0.0, 0.0, 0.0),
    reach: RecordedReach = None,
) -> list[Actor]:
    hal = _robot(stack, geometry, reach)
    try:
        return build_actors(stack, hal, initial_pose=start)
    except ImportError as exc:  # a CAN stack's modules without the extra
        raise ReplayInputError(
            f"hal.kind: {stack.hal.kind} needs a module that is not installed ({exc.name}): "
            "pip install 'otonav[can]'"
        ) from None
    finally:
        hal.close()


def _robot(
    stack: StackConfig, geometry: RobotGeometry | None, reach: RecordedReach = None
) -> RobotHardwareInterface:
    """The recorded robot (its world built on demand), or the world for ``stack``."""
    if geometry is None:
        return _world(stack)
    return RecordedRobot(geometry, lambda: _world(stack), reach)


def _world(stack: StackConfig) -> RobotHardwareInterface:
    """The robot model the actors are built for (wheel geometry for the base...). A few
    ms of MJCF compiling; no physics is stepped."""
    try:
        return build_world(stack)
    except (SceneError, OSError) as exc:
        raise ReplayInputError(
            f"world.scene {stack.world.scene!r}: cannot load the robot model the actors are "
            f"built for ({exc}); pass --set world.scene=PATH to the scene file"
        ) from None


def _valid_names(stack_names: Sequence[str]) -> str:
    return (
        f"replayable nodes: {', '.join(stack_names)} (the stack's actors), or a user actor "
        "as package.module:Name"
    )


def build_nodes(
    specs: Sequence[str],
    stack: StackConfig,
    geometry: RobotGeometry | None = None,
    start: tuple[float, float, float] = (0.0, 0.0, 0.0),
    reach: RecordedReach = None,
) -> list[Actor]:
    """The actors named by ``specs`` (stack names or import paths), built from ``stack``
    for a robot of ``geometry`` (None: the one ``stack``'s world compiles to) that
    started at ``start`` (x, y, yaw: the run's, as the run built them)."""
    if not specs:
        raise ReplayInputError("--node: name at least one node to replay")
    stack_actors = {a.name: a for a in _stack_actors(stack, geometry, start, reach)}
    replayable = [name for name in stack_actors if name not in NOT_REPLAYABLE]
    actors: list[Actor] = []
    for spec in specs:
        if ":" in spec:
            actors.append(_import_actor(spec, stack))
        elif spec in NOT_REPLAYABLE:
            raise ReplayInputError(
                f"--node {spec}: cannot be replayed ({NOT_REPLAYABLE[spec]}); "
                + _valid_names(replayable)
            )
        elif spec in stack_actors:
            actors.append(stack_actors[spec])
        else:
            raise ReplayInputError(f"--node {spec}: no such node; " + _valid_names(replayable))
    names = [a.name for a in actors]
    duplicates = sorted({n for n in names if names.count(n) > 1})
    if duplicates:
        raise ReplayInputError(f"--node: {', '.join(duplicates)} named more than once")
    return actors


def _import_actor(spec: str, stack: StackConfig) -> Actor:
    module_name, _, attr = spec.partition(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise ReplayInputError(f"--node {spec}: cannot import {module_name!r} ({exc})") from None
    target = getattr(module, attr, None)
    if target is None:
        raise ReplayInputError(f"--node {spec}: module {module_name!r} has no {attr!r}")
    try:
        if isinstance(target, type) and issubclass(target, Actor):
            actor = target()
        elif callable(target):
            actor = target(stack)
        else:
            raise TypeError(f"{attr} is a {type(target).__name__}")
    except TypeError as exc:
        raise ReplayInputError(
            f"--node {spec}: expected an Actor subclass built with no arguments or a "
            f"function (stack: StackConfig) -> Actor ({exc})"
        ) from None
    if not isinstance(actor, Actor):
        raise ReplayInputError(
            f"--node {spec}: {attr}(stack) returned a {type(actor).__name__}, not an Actor"
        )
    return actor
