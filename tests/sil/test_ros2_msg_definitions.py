"""Our recorded ``ros2msg`` schemas against the ``.msg`` files of real ROS 2 distributions
(Jazzy's and Kilted's interface packages from PyPI, ``make ros2-peers``): every type we
share with a package the distro ships, top level and every dependency, field by field.

The layouts are generated from the pydantic models plus a short table of ROS types
(``otonav/record/_schemas.py``); this is the check that table and models say what ROS says.
"""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pytest

import otonav.msgs
from otonav.msgs import Message
from otonav.record._schemas import PRIMITIVES, schema_for

pytestmark = pytest.mark.sil

ROOT = Path(__file__).resolve().parents[2]
TYPES = sorted(
    {
        kind
        for name in otonav.msgs.__all__
        if inspect.isclass(kind := getattr(otonav.msgs, name))
        and issubclass(kind, Message)
        and "ros_type" in vars(kind)
    },
    key=lambda kind: kind.ros_type,
)
SHIPPED = {"builtin_interfaces", "geometry_msgs", "nav_msgs", "rcl_interfaces"}
SHIPPED |= {"rosgraph_msgs", "sensor_msgs", "std_msgs"}
"""The packages of our types that a distro's venv must hold: the test cannot pass empty."""

_CONSTANT = re.compile(r"^(\w+) (\w+)=(\S+)$")


def _lines(text: str, pkg: str) -> list[str]:
    """``.msg`` text of ``pkg`` -> ``type name`` and ``NAME=value`` lines: types with
    their package, no comments, no field defaults, no constant type (Humble's ``Log``
    constants are ``byte``, Jazzy's ``uint8``: constants are not part of the type hash
    nor of the CDR bytes)."""
    lines = []
    for raw in text.splitlines():
        words = raw.split("#", 1)[0].split()
        if not words:
            continue
        line = " ".join(words)
        constant = _CONSTANT.match(line)
        if constant:
            lines.append(f"{constant[2]}={constant[3]}")
            continue
        kind, name = words[:2]
        if "/" not in kind and kind.partition("[")[0] not in PRIMITIVES:
            kind = f"{pkg}/{kind}"  # a type of the same package
        lines.append(f"{kind} {name}")
    return lines


def _share(distro: str) -> Path:
    share = ROOT / ".venvs" / f"ros2-{distro}" / "share"
    assert share.is_dir(), f"{share} is missing: `make ros2-peers` installs it (make test does)"
    return share


@pytest.mark.parametrize("distro", ["jazzy", "kilted"])
def test_every_shared_schema_is_the_distros_msg_definition(distro: str) -> None:
    share = _share(distro)
    compared: set[str] = set()
    for kind in TYPES:
        pkg, _, name = kind.ros_type.split("/")
        if not (share / pkg / "msg" / f"{name}.msg").exists():
            continue
        top, *deps = schema_for(kind)[1].split("\n" + "=" * 80 + "\n")
        parts = [(f"{pkg}/{name}", top)]
        for dep in deps:
            header, _, body = dep.partition("\n")
            parts.append((header.removeprefix("MSG: "), body))
        for short, body in parts:
            dep_pkg, dep_name = short.split("/")
            ros = (share / dep_pkg / "msg" / f"{dep_name}.msg").read_text()
            assert _lines(body, dep_pkg) == _lines(ros, dep_pkg), (
                f"{kind.__name__}: {short} differs from {distro}"
            )
            compared.add(dep_pkg)
    assert compared >= SHIPPED, f"{distro} lacks {sorted(SHIPPED - compared)}"
