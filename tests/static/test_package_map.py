"""``otonav/__init__.py``'s map of the package names every subpackage and top module."""

from __future__ import annotations

import re
from pathlib import Path

import otonav

PACKAGE = Path(otonav.__file__).parent


def test_the_package_map_matches_the_tree() -> None:
    doc = otonav.__doc__ or ""
    named = set(re.findall(r"[a-z0-9_]+", doc.split("Layers,", 1)[1]))
    parts = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    parts |= {p.stem for p in PACKAGE.glob("*.py") if not p.stem.startswith("_")}
    missing = sorted(parts - named)
    assert not missing, f"otonav/__init__.py's map omits {missing}"
