"""What the robot really reaches: a short identification in sim time, on a copy of the
world with only the robot and the floor in it (ADR 0066). The world itself is not
touched, so the run's physics and its recording are the same with or without it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from otonav.hal._types import Reach
from otonav.hal.mujoco._derive import _actuator_of
from otonav.hal.mujoco._lib import mujoco

__all__ = ["SECONDS"]

_SETTLE: Final = 0.25  # s at rest before the step, as the world settles
_STRAIGHT: Final = 3.0  # s of the straight step
_TURN: Final = 2.0  # s of the turn in place
_STEADY: Final = 1.0  # s at the end of each step whose mean speed is the reached one
_SAMPLE: Final = 0.01  # s between speed samples
SECONDS: Final = 3 * _SETTLE + 2 * _STRAIGHT + _TURN
"""s of sim one identification runs (three steps, each from rest)."""


@dataclass(frozen=True, slots=True)
class _Robot:
    """Where the robot sits in the compiled world, by name (the copy's ids differ)."""

    body: str
    left: str
    right: str
    scale: tuple[float, float]  # ctrl per rad/s of wheel speed, the sign included
    radius: float
    separation: float


def identify(spec: Any, robot: _Robot, v: float, omega: float) -> Reach:
    """Step the wheels to ``v`` m/s straight ahead, then to ``omega`` rad/s in place,
    and measure the steady speeds and the time to 90 % of them."""
    model, data = _alone(spec, robot.body)
    body = int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, robot.body))
    dof = int(model.jnt_dofadr[model.body_jntadr[body]])
    acts = [
        _actuator_of(model, int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)))
        for name in (robot.left, robot.right)
    ]

    def run(left: float, right: float, seconds: float, speed: Any) -> tuple[float, float]:
        mujoco.mj_resetData(model, data)
        mujoco.mj_step(model, data, nstep=max(1, round(_SETTLE / model.opt.timestep)))
        data.ctrl[acts[0]] = left * robot.scale[0]
        data.ctrl[acts[1]] = right * robot.scale[1]
        every = max(1, round(_SAMPLE / model.opt.timestep))
        samples = []
        for _ in range(round(seconds / (every * model.opt.timestep))):
            mujoco.mj_step(model, data, nstep=every)
            samples.append(float(speed()))
        trace = np.asarray(samples)
        steady = float(trace[-round(_STEADY / (every * model.opt.timestep)) :].mean())
        if not np.isfinite(steady) or steady <= 0.0:
            return 0.0, 0.0
        first = int(np.argmax(trace >= 0.9 * steady)) + 1
        return steady, 0.9 * steady / (first * every * model.opt.timestep)

    def forward() -> float:
        w, _, _, z = data.qpos[model.jnt_qposadr[model.body_jntadr[body]] + 3 :][:4]
        yaw = 2.0 * np.arctan2(z, w)
        return float(data.qvel[dof] * np.cos(yaw) + data.qvel[dof + 1] * np.sin(yaw))

    wheel = v / robot.radius
    speed, accel = run(wheel, wheel, _STRAIGHT, forward)
    half, _ = run(wheel / 2, wheel / 2, _STRAIGHT, forward)
    turn = omega * robot.separation / 2.0 / robot.radius
    rate, alpha = run(-turn, turn, _TURN, lambda: data.qvel[dof + 5])
    # reached = gain x asked - loss, in wheel rad/s: the loss over the gain is what a
    # command must carry more to get where it asks (a servo's friction, its deadband).
    gain = (speed - half) / (v / 2)
    deadband = (gain * wheel - speed / robot.radius) / gain if gain > 0.0 else 0.0
    return Reach(
        asked_v=v,
        asked_omega=omega,
        v=speed,
        omega=rate,
        accel=accel,
        alpha=alpha,
        deadband=max(0.0, deadband),
    )


def _alone(spec: Any, body: str) -> tuple[Any, Any]:
    """The world compiled with only the robot's body and the floor planes left in it."""
    alone = spec.copy()
    for child in list(alone.worldbody.bodies):
        if child.name != body:
            alone.delete(child)
    for geom in list(alone.worldbody.geoms):
        if geom.type != mujoco.mjtGeom.mjGEOM_PLANE:
            alone.delete(geom)
    model = alone.compile()
    return model, mujoco.MjData(model)
