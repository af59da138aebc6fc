"""Static geoms placed once, not at every step: MuJoCo 4.0's sleeping, used for that alone
(ADR 0062).

``mj_kinematics`` places every geom at every step, the world body's too (~9 ns a box:
the whole per-box cost of a physics step at 1000 boxes). MuJoCo 4.0 skips the geoms (and
sites) of static bodies, and of sleeping ones, but only while some tree sleeps
(``nbody_awake < nbody``); a static geom's pose is then the one ``mj_resetData`` /
``mj_makeData`` computed, with the same arithmetic (``mj_local2Global`` of a body that
never moves). So a world with many static geoms gets, with ``mjENBL_SLEEP``:

- one more body, :data:`ANCHOR`, last in the model: a slide joint, no geom, no site,
  asleep from the start (``mjSLEEP_INIT``) and never woken (nothing touches it: no geom,
  no tendon, no equality, no force);
- every other tree's sleep policy ``mjSLEEP_NEVER`` (set on its root body), so nothing
  else ever sleeps and the physics is the same as without sleeping, bit for bit (tested
  on the 1000-box course: the ground truth and every scan; and the recordings of the
  built-in scenarios with the anchor forced on).

A scene that enables sleeping itself is left as it is (its own policies hold).
"""

from __future__ import annotations

from typing import Any, Final

from otonav.hal.mujoco._lib import mujoco
from otonav.limits import STATIC_SLEEP_MIN_GEOMS

__all__ = ["ANCHOR", "MIN_STATIC_GEOMS", "anchor_static_geoms", "static_geom_count"]

ANCHOR: Final = "otonav_static_anchor"
"""The sleeping body's name."""

MIN_STATIC_GEOMS: Final = STATIC_SLEEP_MIN_GEOMS
"""From this many static geoms: below, MuJoCo's sleep bookkeeping (~0.6 us a step) costs
more than placing the geoms (~9 ns each)."""


def static_geom_count(spec: Any) -> int:
    """Geoms on the world body and on bodies welded to it (no joint, not mocap, under a
    static body): the geoms ``mj_kinematics`` places at every step for nothing."""
    count = len(spec.worldbody.geoms)
    stack = list(spec.worldbody.bodies)
    while stack:
        body = stack.pop()
        if len(body.joints) == 0 and not body.mocap:
            count += len(body.geoms)
            stack.extend(body.bodies)
    return count


def _tree_roots(spec: Any) -> list[Any]:
    """The bodies that carry a sleep policy: the first moving body (one with a joint)
    down each branch from the world."""
    roots = []
    stack = list(spec.worldbody.bodies)
    while stack:
        body = stack.pop()
        if len(body.joints) > 0:
            roots.append(body)
        elif not body.mocap:
            stack.extend(body.bodies)
    return roots


def anchor_static_geoms(spec: Any) -> bool:
    """Before ``spec.compile()``: with :data:`MIN_STATIC_GEOMS` static geoms or more (and
    sleeping not enabled by the scene), enable sleeping, keep every body awake and add
    the sleeping :data:`ANCHOR`. Returns whether it did; check the compiled model with
    :func:`anchored`."""
    if spec.option.enableflags & mujoco.mjtEnableBit.mjENBL_SLEEP:
        return False
    if spec.body(ANCHOR) is not None or static_geom_count(spec) < MIN_STATIC_GEOMS:
        return False
    for root in _tree_roots(spec):
        root.sleep = mujoco.mjtSleepPolicy.mjSLEEP_NEVER
    anchor = spec.worldbody.add_body(
        name=ANCHOR, mass=1.0, inertia=[1.0, 1.0, 1.0], explicitinertial=True
    )
    anchor.sleep = mujoco.mjtSleepPolicy.mjSLEEP_INIT
    anchor.add_joint(type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1.0, 0.0, 0.0])
    spec.option.enableflags |= mujoco.mjtEnableBit.mjENBL_SLEEP
    return True


def anchored(m: Any, d: Any) -> bool:
    """Is the compiled world as :func:`anchor_static_geoms` meant it: the anchor's tree
    alone may sleep, and it sleeps (so MuJoCo skips the static geoms)?"""
    body = int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, ANCHOR))
    if body < 0:
        return False
    tree = int(m.body_treeid[body])
    never = (mujoco.mjtSleepPolicy.mjSLEEP_NEVER, mujoco.mjtSleepPolicy.mjSLEEP_AUTO_NEVER)
    others = [int(p) for t, p in enumerate(m.tree_sleep_policy) if t != tree]
    return all(p in never for p in others) and int(d.tree_awake[tree]) == 0
