"""Layer 0: the wheel users install carries what a typed, licensed library must: the
``py.typed`` marker (PEP 561: without it mypy ignores otonav's annotations in users'
code), the LICENSE text the metadata names, and the package data (MJCF assets)."""

from __future__ import annotations

import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _wheel(out: Path) -> zipfile.ZipFile:
    build = subprocess.run(
        [sys.executable, "-m", "hatchling", "build", "-t", "wheel", "-d", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert build.returncode == 0, build.stderr
    (wheel,) = out.glob("otonav-*.whl")
    return zipfile.ZipFile(wheel)


def test_the_wheel_ships_py_typed_the_license_and_the_assets(tmp_path: Path) -> None:
    with _wheel(tmp_path) as wheel:
        names = set(wheel.namelist())
        (dist_info,) = {n.split("/")[0] for n in names if n.split("/")[0].endswith(".dist-info")}
        assert "otonav/py.typed" in names
        licenses = sorted(n for n in names if n.startswith(f"{dist_info}/licenses/"))
        assert licenses == [f"{dist_info}/licenses/LICENSE"], sorted(names)
        text = wheel.read(licenses[0]).decode()
        metadata = wheel.read(f"{dist_info}/METADATA").decode()
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["license"]
    assert declared == "MIT"
    assert text.startswith("MIT License")
    assert "Permission is hereby granted, free of charge" in text
    assert "License-Expression: MIT" in metadata
    assert "License-File: LICENSE" in metadata
    assert {"otonav/hal/assets/robot.xml", "otonav/hal/assets/obstacles.xml"} <= names
