"""The public API is a curated tuple per package, and it does not drift: every exported
name exists, and every public name a package's __init__ imports is exported."""

from __future__ import annotations

import importlib

import pytest

pytestmark = pytest.mark.unit

PACKAGES = [
    "otonav.runtime",
    "otonav.msgs",
    "otonav.control",
    "otonav.nav",
    "otonav.hal",
    "otonav.actors",
    "otonav.stack",
    "otonav.scenario",
    "otonav.testing",
    "otonav.embed",
    "otonav.replay",
    "otonav.sweep",
]


@pytest.mark.parametrize("name", PACKAGES)
def test_all_is_a_tuple_of_existing_names(name: str) -> None:
    module = importlib.import_module(name)
    exported = module.__all__
    assert isinstance(exported, tuple)
    missing = [n for n in exported if not hasattr(module, n)]
    assert not missing, f"{name}.__all__ names what it does not have: {missing}"


@pytest.mark.parametrize("name", PACKAGES)
def test_every_public_import_is_exported(name: str) -> None:
    module = importlib.import_module(name)
    public = {
        n
        for n, value in vars(module).items()
        if not n.startswith("_")
        and getattr(value, "__module__", "").startswith("otonav.")
        and not isinstance(value, type(importlib))  # submodules are not API
    }
    assert public <= set(module.__all__), (
        f"{name} imports but does not export: {public - set(module.__all__)}"
    )
