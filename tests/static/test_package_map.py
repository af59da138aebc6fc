"""``otonav/__init__.py``'s map of the package names every subpackage and top module,
nested packages by their dotted name (``hal.mujoco``, ``sweep.backends``)."""

from __future__ import annotations

import re
from pathlib import Path

import otonav

PACKAGE = Path(otonav.__file__).parent


def _map() -> str:
    return (otonav.__doc__ or "").split("Layers,", 1)[1]


def test_the_package_map_matches_the_tree() -> None:
    named = set(re.findall(r"[a-z0-9_]+", _map()))
    parts = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    parts |= {p.stem for p in PACKAGE.glob("*.py") if not p.stem.startswith("_")}
    missing = sorted(parts - named)
    assert not missing, f"otonav/__init__.py's map omits {missing}"


def test_the_package_map_names_every_nested_package() -> None:
    named = set(re.findall(r"[a-z0-9_]+(?:\.[a-z0-9_]+)+", _map()))
    nested = {
        ".".join(init.parent.relative_to(PACKAGE).parts) for init in PACKAGE.glob("*/*/__init__.py")
    }
    missing = sorted(nested - named)
    assert not missing, f"otonav/__init__.py's map omits {missing}"
