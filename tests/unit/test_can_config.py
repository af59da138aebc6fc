"""``hal.can.*`` and ``hal.sim.*`` are bounded like every other section (ADR 0019,
``otonav/limits.py``): out of range is one line naming the key and the valid range,
exit 2, nothing run. Before the bounds, ``hal.can.left.gear_ratio=1e300`` overflowed
the float32 Set_Input_Vel encoder (a traceback at sim time 0) and
``hal.sim.encoder_period=1e-9`` silently became one frame per tick."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.cli import main
from otonav.stack import StackConfig
from otonav.stack._overrides import apply_overrides

pytestmark = pytest.mark.unit


def _fails(capsys: pytest.CaptureFixture[str], tmp_path: Path, override: str) -> str:
    code = main(["run", "--set", "hal.kind=can", "--set", override, "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert not list(tmp_path.iterdir()), "nothing may run (or be written) on bad input"
    return lines[0]


@pytest.mark.parametrize(
    ("override", "valid"),
    [
        ("hal.can.encoder_period=1e9", "must be in [0.001, 1] s (got 1000000000.0)"),
        ("hal.can.encoder_period=0", "must be in [0.001, 1] s"),
        ("hal.sim.encoder_period=1e-9", "must be in [0.001, 1] s (got 1e-09)"),
        ("hal.sim.heartbeat_period=1e300", "must be in [0.001, 1] s"),
        ("hal.can.startup_timeout=0", "must be in (0, 10] s (got 0"),
        ("hal.can.heartbeat_timeout=1e9", "must be in (0, 10] s"),
        ("hal.can.encoder_timeout=-1", "must be in (0, 10] s"),
        ("hal.can.loss_window=3600", "must be in (0, 10] s"),
        ("hal.can.recovery_delay=-0.1", "must be in [0, 10] s"),
        ("hal.can.command_keepalive=11", "must be in [0, 10] s"),
        ("hal.can.max_recovery_attempts=1000000", "must be in [0, 100]"),
        ("hal.can.max_frame_loss=1.5", "must be in [0, 1]"),
        ("hal.can.left.gear_ratio=1e300", "must be in [0.01, 100] (got 1e+300)"),
        ("hal.can.right.node_id=64", "must be in [0, 63] (got 64)"),
        ("hal.sim.left_node_id=-1", "must be in [0, 63]"),
        ("hal.sim.vel_limit=1e300", "must be in (0, 200] turns/s"),
        ("hal.sim.vel_ramp_rate=0", "must be in (0, 100000] turns/s^2"),
        ("hal.sim.watchdog_timeout=1e300", "must be in [0, 10] s"),
        ("hal.sim.arm_time=100", "must be in [0, 10] s"),
        ("hal.sim.seed=-1", "greater than or equal to 0"),
        ("hal.can.channel=" + "c" * 65, "at most 64 characters"),
    ],
)
def test_can_numbers_out_of_range_name_the_key_and_the_range(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, override: str, valid: str
) -> None:
    line = _fails(capsys, tmp_path, override)
    key = override.partition("=")[0]
    assert line.startswith(f"otonav: error: --set: {key}: "), line
    assert valid in line, line


@pytest.mark.parametrize(
    ("overrides", "fragments"),
    [
        (
            ["hal.sim.encoder_period=0.001"],
            ["hal.sim.encoder_period = 0.001 s", "shorter than a physics tick", "0.002 s"],
        ),
        (
            ["world.timestep=0.005", "hal.can.encoder_period=0.002"],
            ["hal.can.encoder_period = 0.002 s", "world.timestep = 0.005 s"],
        ),
        (
            ["hal.can.encoder_timeout=0.01"],
            ["hal.can.encoder_timeout (0.01 s) must be longer than hal.can.encoder_period"],
        ),
        (
            ["hal.can.loss_window=0.005"],
            ["hal.can.loss_window (0.005 s) must be at least hal.can.encoder_period (0.01 s)"],
        ),
        (
            ["hal.can.left.node_id=1"],
            ["hal.can.left.node_id and hal.can.right.node_id must differ (both 1)"],
        ),
    ],
)
def test_can_values_inconsistent_together_are_one_line(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    overrides: list[str],
    fragments: list[str],
) -> None:
    argv = ["run", "--set", "hal.kind=can", "--out", str(tmp_path)]
    for override in overrides:
        argv += ["--set", override]
    assert main(argv) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    # A whole-config check quotes its keys, not a dump of the section.
    assert "(got {" not in lines[0]


def test_the_bounds_admit_the_defaults_and_their_edges() -> None:
    config = apply_overrides(
        StackConfig(),
        [
            "hal.kind=can",
            "hal.can.encoder_period=1.0",
            "hal.can.encoder_timeout=10",
            "hal.can.loss_window=1.0",
            "hal.can.command_keepalive=0",
            "hal.can.recovery_delay=0",
            "hal.can.left.gear_ratio=100",
            "hal.sim.encoder_period=0.002",
            "hal.sim.heartbeat_period=1.0",
            "hal.sim.watchdog_timeout=0",
            "hal.sim.vel_limit=200",
        ],
    )
    assert config.hal.can.encoder_period == 1.0
    assert config.hal.sim.encoder_period == 0.002
