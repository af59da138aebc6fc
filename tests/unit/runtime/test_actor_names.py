"""The framework's names on an actor (``name``, ``clock``, ``ports``, ``topic_of``,
``parameters``, the hooks) cannot be shadowed silently: a port or attribute that would
is an error at class definition or wiring time, naming the attribute and the class."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import anyio
import pytest

from otonav.runtime import (
    Actor,
    ActorDefinitionError,
    Input,
    Output,
    System,
    WiringError,
    virtual_loop_factory,
)

pytestmark = pytest.mark.unit

FRAMEWORK = ["name", "clock", "ports", "topic_of", "parameters"]


@dataclass(frozen=True, slots=True)
class Tick:
    n: int


def _define(attr: str, value: Any) -> type[Actor]:
    return type("Shadowing", (Actor,), {attr: value})


@pytest.mark.parametrize("attr", FRAMEWORK)
def test_a_port_named_like_a_framework_attribute_fails_at_class_definition(attr: str) -> None:
    with pytest.raises(ActorDefinitionError) as err:
        _define(attr, Output("/clock", Tick))
    text = str(err.value)
    assert f"Shadowing.{attr}" in text  # the class and the attribute
    assert f"Actor.{attr}" in text  # what it would shadow
    assert "rename" in text  # the fix
    assert isinstance(err.value, TypeError)  # what Python raises for a bad class
    assert isinstance(err.value, WiringError)  # one except for every wiring problem


@pytest.mark.parametrize("attr", FRAMEWORK)
def test_any_attribute_named_like_a_framework_attribute_fails(attr: str) -> None:
    with pytest.raises(ActorDefinitionError, match=f"Shadowing.{attr}"):
        _define(attr, lambda self: None)


@pytest.mark.parametrize("hook", ["on_wired", "on_start", "run", "on_failure", "on_stop"])
def test_a_port_named_like_a_hook_fails_but_overriding_the_hook_is_the_point(hook: str) -> None:
    with pytest.raises(ActorDefinitionError, match=f"Shadowing.{hook}.*hook"):
        _define(hook, Input("/tick", Tick))

    async def body(self: Actor, *args: Any) -> None:
        return None

    assert issubclass(_define(hook, body), Actor)


def test_the_bridge_style_name_is_fine_and_clock_still_works() -> None:
    class Bridge(Actor):
        clock_out = Output("/clock", Tick)

        async def run(self) -> None:
            await self.clock.sleep(0.5)
            await self.clock_out.publish(Tick(int(self.clock.now() * 10)))

    bridge = Bridge()
    assert bridge.name == "bridge"

    async def main() -> None:
        async with System([bridge]) as system:
            sub = system.subscribe("/clock", Tick)
            await system.wait_finished()
            assert sub.take_latest() == Tick(5)

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})


class _Keeps(Actor):
    odom = Input("/odom", Tick)

    def __init__(self) -> None:
        super().__init__("keeps")
        self.odom = None  # type: ignore[assignment]  # the user's own state, same name


def test_an_instance_attribute_a_port_would_overwrite_fails_at_wiring() -> None:
    """Wiring used to replace ``self.odom`` with the mailbox without a word."""
    with pytest.raises(ActorDefinitionError) as err:
        System([_Keeps()])
    text = str(err.value)
    assert "actor 'keeps'" in text
    assert "_Keeps.odom" in text
    assert "Input('/odom'" in text
    assert "rename" in text


class _ShadowsPorts(Actor):
    tick = Output("/tick", Tick)

    def __init__(self) -> None:
        super().__init__()
        self.ports = ["mine"]  # type: ignore[method-assign,assignment]


def test_an_instance_attribute_shadowing_a_framework_method_fails_at_wiring() -> None:
    """It used to surface as "'list' object is not callable" from inside the System."""
    with pytest.raises(ActorDefinitionError, match=r"_ShadowsPorts\.ports.*Actor\.ports"):
        System([_ShadowsPorts()])


class _NoSuper(Actor):
    tick = Output("/tick", Tick)

    def __init__(self) -> None:  # forgets super().__init__()
        self.rate = 1.0


def test_an_actor_whose_init_skipped_the_base_init_is_told_so() -> None:
    with pytest.raises(ActorDefinitionError, match=r"_NoSuper.__init__.*super\(\).__init__"):
        System([_NoSuper()])


def test_the_same_actor_can_be_wired_again_by_a_new_system() -> None:
    """Its own earlier binding is not a user attribute (a harness re-runs one instance)."""

    class Ticker(Actor):
        tick = Output("/tick", Tick)

    ticker = Ticker()
    System([ticker])
    System([ticker])
