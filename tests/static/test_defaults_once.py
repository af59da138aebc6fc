"""Layer 0: a parameter's default is written once (issue 36, ADR 0085), and reading the
stack's config loads no numpy.

The finder walks every module of otonav/ (AST, nothing imported): the literal defaults
of class fields (dataclass and pydantic fields, ``Field(default, ...)`` and
``field(default=...)`` too) and of function parameters, grouped by the name they set
(``ALIASES``: one parameter, two names). A name with the same literal default in two
places is one parameter written twice: the next change moves one and not the other.
Neutral values (0, "", True, False, None) are not knowledge and are left out. A default
that refers to another (``max_accel: float = _BASE.max_accel``) is not a literal: that
is the fix.

``KNOWN`` lists what is still written twice, by file, each in a part of otonav that
issue 36's other items change in parallel (hal/, the bridge, scenario/, sweep/,
replay/, runtime/, ros2/), or two parameters that share a name and a value by chance
(the CAN tap's rate and the safety layer's, the generator's grid cell and the
localizer's). A new duplicate fails; so does an entry that is gone: the list only
shrinks.
"""

from __future__ import annotations

import ast
import subprocess
import sys
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

ALIASES = {"rotate_threshold": "turn_in_place_threshold"}
"""Fields of the nav math named apart from the config key that sets them."""

KNOWN: dict[tuple[str, object], str] = {
    ("arm_time", 0.01): "hal/sim/odrive.py stack/config.py",
    ("arrival", "stop"): "scenario/config.py scenario/judge.py",
    ("backend", "process"): "sweep/api.py",
    ("clock_hz", 100.0): "actors/bridge.py stack/config.py",
    ("command_keepalive", 0.1): "hal/can/interface.py stack/config.py",
    ("deadlock_grace", 0.5): "runtime/loop.py",
    ("depth", 10000): "actors/recorder.py runtime/funnel.py",
    ("encoder_period", 0.01): "hal/can/monitor.py hal/sim/emulator.py stack/config.py",
    ("encoder_timeout", 0.05): "hal/can/monitor.py stack/config.py",
    ("expect", "reached"): "scenario/config.py scenario/verdict.py",
    ("gear_ratio", 1.0): "hal/can/interface.py hal/sim/emulator.py stack/config.py",
    ("goal_tolerance", 0.15): "scenario/config.py scenario/generator.py",
    ("heartbeat_period", 0.1): "hal/sim/emulator.py stack/config.py",
    ("heartbeat_timeout", 0.25): "hal/can/monitor.py stack/config.py",
    ("imu_hz", 100.0): "actors/bridge.py stack/config.py",
    ("loss_window", 0.5): "hal/can/monitor.py stack/config.py",
    ("max_frame_loss", 0.2): "hal/can/monitor.py stack/config.py",
    ("max_recovery_attempts", 3): "hal/can/monitor.py stack/config.py",
    ("name", "external"): "runtime/system.py",
    ("name", "sweep"): "sweep/api.py sweep/report.py sweep/spec.py",
    ("odom_hz", 100.0): "actors/bridge.py stack/config.py",
    ("rate", 1.0): "replay/feed.py ros2/play.py",
    ("rate_hz", 20.0): "hal/can/tap.py params.py",
    ("recovery_delay", 0.3): "hal/can/monitor.py stack/config.py",
    ("recovery_reset", 5.0): "hal/can/monitor.py stack/config.py",
    ("resolution", 0.05): "params.py scenario/generator.py scenario/generator_grid.py",
    ("scale", 1.0): "msgs/otonav_msgs.py runtime/clock.py runtime/timemode.py",
    ("scan_hz", 10.0): "actors/bridge.py stack/config.py",
    ("scene", "obstacles"): "hal/mujoco/world.py stack/config.py",
    ("sign", 1): "hal/can/interface.py hal/sim/emulator.py stack/config.py",
    ("source", "scenario"): "embed/runs.py scenario/assembly.py scenario/run.py "
    "scenario/validate.py",
    ("startup_timeout", 1.0): "hal/can/monitor.py stack/config.py",
    ("vel_limit", 20.0): "hal/sim/odrive.py stack/config.py",
    ("vel_ramp_rate", 200.0): "hal/sim/odrive.py stack/config.py",
    ("wall_ceiling", 300.0): "embed/runs.py scenario/run.py",
    ("watchdog_timeout", 0.2): "hal/sim/odrive.py stack/config.py",
}
"""(name, default) -> the files (under otonav/, a private ``_`` dropped) that still write
it, as they do today."""

Default = tuple[str, object, str]


def _literal(node: ast.expr | None) -> object:
    """The default ``node`` writes as a literal (None: not a literal, or neutral)."""
    if isinstance(node, ast.Call) and getattr(node.func, "id", "") in ("Field", "field"):
        given = [k.value for k in node.keywords if k.arg == "default"]
        node = node.args[0] if node.args else (given[0] if given else None)
    if node is None:
        return None
    try:
        value = ast.literal_eval(node)
    except ValueError:
        return None
    if isinstance(value, bool) or not isinstance(value, int | float | str) or not value:
        return None
    return value


def _defaults(path: Path, label: str) -> Iterator[Default]:
    """(name, literal default, where) of every class field and parameter in ``path``."""
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        pairs: list[tuple[str, ast.expr | None]] = []
        if isinstance(node, ast.ClassDef):
            pairs = [
                (s.target.id, s.value)
                for s in node.body
                if isinstance(s, ast.AnnAssign) and isinstance(s.target, ast.Name)
            ]
        elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            args = node.args
            positional = [*args.posonlyargs, *args.args]
            tail = positional[len(positional) - len(args.defaults) :]
            pairs = [(a.arg, d) for a, d in zip(tail, args.defaults, strict=True)]
            pairs += [(a.arg, d) for a, d in zip(args.kwonlyargs, args.kw_defaults, strict=True)]
        for name, default in pairs:
            value = _literal(default)
            if value is not None:
                yield ALIASES.get(name, name), value, label


def duplicated_defaults(package: Path) -> dict[tuple[str, object], str]:
    """(name, default) -> the files writing it, for each written in two places or more."""
    places: dict[tuple[str, object], list[str]] = defaultdict(list)
    for path in sorted(package.rglob("*.py")):
        # A module renamed private (``_dwa.py``) is the same place.
        parts = path.relative_to(package).parts
        where = "/".join(p if p.startswith("__") else p.removeprefix("_") for p in parts)
        for name, value, label in _defaults(path, where):
            places[name, value].append(label)
    return {key: " ".join(sorted(set(at))) for key, at in places.items() if len(at) > 1}


def test_no_default_is_written_twice() -> None:
    found = duplicated_defaults(ROOT / "otonav")
    new = {key: at for key, at in found.items() if KNOWN.get(key) != at}
    assert not new, f"a default written twice (keep it in one place, refer to it): {new}"
    gone = sorted(set(KNOWN) - set(found), key=str)
    assert not gone, f"written once now: remove {gone} from KNOWN"


def test_the_finder_finds_a_default_written_twice(tmp_path: Path) -> None:
    """The check can fail: a config field, a dataclass field under its alias and a
    keyword default with the same literal; a reference and a neutral value pass."""
    (tmp_path / "config.py").write_text(
        "class NavConfig:\n"
        "    turn_in_place_threshold: float = Field(0.6, gt=0.0)\n"
        "    rate_hz: float = 1.0 / _DWA.period\n"
        "    enabled: bool = False\n"
    )
    (tmp_path / "dwa.py").write_text(
        "class DwaParams:\n    rotate_threshold: float = field(default=0.6)\n"
        "    enabled: bool = False\n"
    )
    (tmp_path / "actor.py").write_text(
        "def start(period, *, turn_in_place_threshold=0.6, rate_hz=_NAV.rate_hz): ...\n"
    )
    assert duplicated_defaults(tmp_path) == {
        ("turn_in_place_threshold", 0.6): "actor.py config.py dwa.py"
    }


_PROBE = (
    "import importlib, sys; importlib.import_module(sys.argv[1]); "
    "print(' '.join(sorted(m for m in sys.modules if m.split('.')[0] in "
    "('numpy', 'mujoco') or m.startswith('otonav.nav') or m.startswith('otonav.hal'))))"
)


def _heavy_modules(module: str) -> set[str]:
    """What importing ``module`` in a fresh interpreter loads of numpy, MuJoCo, the nav
    math (the costmap) and the HAL."""
    out = subprocess.run(
        [sys.executable, "-c", _PROBE, module], capture_output=True, text=True, check=True
    )
    return set(out.stdout.split())


def test_importing_the_stack_config_loads_no_numpy() -> None:
    assert _heavy_modules("otonav.stack") == set()
    assert _heavy_modules("otonav.params") == set()


def test_the_import_probe_sees_numpy() -> None:
    """The check can fail: importing the nav math loads numpy and the costmap."""
    assert {"numpy", "otonav.nav._costmap"} <= _heavy_modules("otonav.nav")
