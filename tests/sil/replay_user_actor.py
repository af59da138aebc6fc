"""A user's actor for ``otonav replay --node replay_user_actor:make_navigator`` (tests)."""

from __future__ import annotations

from otonav.actors import Navigator
from otonav.runtime import Actor
from otonav.stack import StackConfig, build_actors, build_world


def make_navigator(stack: StackConfig) -> Actor:
    """The stack's own navigator, built by a user function from the replay's config."""
    world = build_world(stack)
    try:
        (nav,) = [a for a in build_actors(stack, world) if isinstance(a, Navigator)]
    finally:
        world.close()
    return nav
