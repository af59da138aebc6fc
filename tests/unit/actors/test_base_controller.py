"""The base controller: /cmd_vel -> limits -> kinematics -> /wheel_cmd, and its watchdog.

Driven by FakeHardware's clock (2 ms ticks); the base runs at its default 50 Hz, so one
control period is 20 ms. Every assertion is on sim time.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Awaitable, Callable, Sequence
from dataclasses import dataclass

import anyio
import pytest

from otonav.actors import BaseController, BaseLimits, Bridge, topics
from otonav.control import DiffDriveGeometry, twist_to_wheels, wheels_to_twist
from otonav.hal import FakeHardware
from otonav.msgs import Log, Twist, WheelCommand
from otonav.runtime import QoS, Reliability, System, virtual_loop_factory

pytestmark = pytest.mark.unit

GEOMETRY = DiffDriveGeometry(wheel_radius=0.05, wheel_separation=0.22)
LIMITS = BaseLimits()  # 0.5 m/s, 1.5 rad/s, 1 m/s², 3 rad/s²
PERIOD = 1.0 / 50.0
TIMEOUT = 0.5
OBSERVE = QoS(Reliability.BEST_EFFORT, depth=100_000)
EPS = 1e-9


@dataclass(frozen=True, slots=True)
class Sent:
    """One /wheel_cmd, as the twist it stands for."""

    t: float
    left: float
    right: float
    v: float
    omega: float


# A script of /cmd_vel: (sim time to publish at, v, omega).
Script = Sequence[tuple[float, float, float]]


def _drive(script: Script, *, until: float, base: BaseController | None = None) -> list[Sent]:
    """Run a base controller alone, publish ``script`` on /cmd_vel, return every
    /wheel_cmd published up to sim time ``until``."""
    hal = FakeHardware()  # the time source only: nothing here drives it
    base = base or BaseController(GEOMETRY)
    sent: list[Sent] = []

    async def main() -> None:
        async with System([base]) as system:
            wheel_cmd = system.subscribe(topics.WHEEL_CMD, WheelCommand, OBSERVE)
            cmd_vel = system.publisher(topics.CMD_VEL, Twist, topics.COMMAND_QOS)
            for at, v, omega in script:
                await anyio.sleep_until(at)
                await cmd_vel.publish(Twist.planar(v, omega))
            # Just past ``until``, so the control tick at ``until`` is in.
            await anyio.sleep_until(until + PERIOD / 4)
            while (message := wheel_cmd.try_recv()) is not None:
                v, omega = wheels_to_twist(message.left, message.right, GEOMETRY)
                stamp = message.header.stamp.to_seconds()
                sent.append(Sent(stamp, message.left, message.right, v, omega))

    _run(hal, main)
    return sent


def _run(hal: FakeHardware, main: Callable[[], Awaitable[None]]) -> None:
    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(hal, wall_ceiling=10)})


def _every(period: float, start: float, stop: float, v: float, omega: float) -> Script:
    """The same command every ``period`` s from ``start`` up to (not including) ``stop``."""
    n = round((stop - start) / period)
    return [(start + k * period, v, omega) for k in range(n)]


def _at(sent: list[Sent], t: float) -> Sent:
    (match,) = [s for s in sent if abs(s.t - t) < 1e-6]
    return match


# -- kinematics and velocity limits ------------------------------------------------------


@pytest.mark.parametrize(
    ("command", "clamped"),
    [
        pytest.param((0.3, 0.5), (0.3, 0.5), id="within-limits"),
        pytest.param((2.0, -5.0), (0.5, -1.5), id="clamped"),
        pytest.param((-0.8, 0.2), (-0.5, 0.2), id="reverse-clamped"),
        pytest.param((0.0, 1.0), (0.0, 1.0), id="turn-in-place"),
    ],
)
def test_steady_state_wheels_are_the_kinematics_of_the_clamped_command(
    command: tuple[float, float], clamped: tuple[float, float]
) -> None:
    sent = _drive(_every(0.1, 0.0, 2.0, *command), until=2.0)
    # 50 Hz: one /wheel_cmd per control period, stamped on the period.
    assert [round(s.t / PERIOD) for s in sent] == list(range(1, 101))
    left, right = twist_to_wheels(*clamped, GEOMETRY)
    last = sent[-1]
    assert (last.left, last.right) == pytest.approx((left, right), abs=EPS)
    for s in sent:
        assert abs(s.v) <= LIMITS.max_v + EPS
        assert abs(s.omega) <= LIMITS.max_omega + EPS


def test_custom_limits_clamp_velocity() -> None:
    limits = BaseLimits(max_v=0.2, max_omega=0.7, max_accel=2.0, max_alpha=5.0)
    base = BaseController(GEOMETRY, limits)
    sent = _drive(_every(0.1, 0.0, 1.0, 1.0, -3.0), until=1.0, base=base)
    left, right = twist_to_wheels(0.2, -0.7, GEOMETRY)
    assert (sent[-1].left, sent[-1].right) == pytest.approx((left, right), abs=EPS)
    assert max(abs(s.v) for s in sent) <= 0.2 + EPS
    assert max(abs(s.omega) for s in sent) <= 0.7 + EPS


# -- acceleration limits -----------------------------------------------------------------


def test_acceleration_ramp() -> None:
    sent = _drive(_every(0.1, 0.0, 1.0, 0.5, 1.5), until=1.0)
    after = _at(sent, 0.1)
    # 0.1 s of sim after the command: speed bounded by max_accel * 0.1 (and it is using
    # all of it: the ramp is as fast as allowed).
    assert 0.0 < after.v <= LIMITS.max_accel * 0.1 + EPS
    assert after.v == pytest.approx(LIMITS.max_accel * 0.1, abs=EPS)
    assert 0.0 < after.omega <= LIMITS.max_alpha * 0.1 + EPS
    # Every step, not just the first 0.1 s, respects the limits.
    previous = (0.0, 0.0)
    for s in sent:
        assert abs(s.v - previous[0]) <= LIMITS.max_accel * PERIOD + EPS
        assert abs(s.omega - previous[1]) <= LIMITS.max_alpha * PERIOD + EPS
        previous = (s.v, s.omega)
    # The targets are reached: 0.5 m/s after 0.5 s, 1.5 rad/s after 0.5 s.
    assert _at(sent, 0.5).v == pytest.approx(0.5, abs=EPS)
    assert _at(sent, 0.5).omega == pytest.approx(1.5, abs=EPS)


def test_deceleration_is_ramped_too() -> None:
    script = [*_every(0.1, 0.0, 1.0, 0.5, 0.0), *_every(0.1, 1.0, 2.0, 0.0, 0.0)]
    sent = _drive(script, until=2.0)
    assert _at(sent, 0.98).v == pytest.approx(0.5, abs=EPS)  # cruising
    for before, after in itertools.pairwise(sent):
        assert before.v - after.v <= LIMITS.max_accel * PERIOD + EPS
    # 0.5 m/s at 1 m/s²: half a second to stop, not one step.
    assert _at(sent, 1.4).v > 0.0
    assert _at(sent, 1.5).v == pytest.approx(0.0, abs=EPS)


# -- watchdog ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    "phase",
    [0.0, 0.002, 0.01, 0.018],
    ids=["on-tick", "2ms-after", "10ms-after", "18ms-after"],
)
def test_watchdog_ramps_to_zero_half_a_second_after_the_last_cmd_vel(phase: float) -> None:
    """``phase``: where, inside the 20 ms control period, /cmd_vel arrives."""
    base = BaseController(GEOMETRY)
    script = _every(0.1, phase, phase + 1.0, 0.3, 0.0)
    last_cmd = script[-1][0]
    sent = _drive(script, until=3.0, base=base)
    cruising = [s for s in sent if s.t < last_cmd + TIMEOUT - EPS]
    assert cruising[-1].v == pytest.approx(0.3, abs=EPS)
    # The first /wheel_cmd slower than the one before it: the watchdog started the ramp.
    first_decrease = next(
        after for before, after in itertools.pairwise(sent) if after.v < before.v - EPS
    )
    delay = first_decrease.t - last_cmd
    assert delay >= TIMEOUT - EPS, f"watchdog fired {delay:.3f} s after the last /cmd_vel"
    assert delay <= TIMEOUT + PERIOD + EPS, (
        f"watchdog ramp started {delay:.3f} s after the last /cmd_vel (at {last_cmd:.3f} s), "
        f"more than cmd_timeout {TIMEOUT} s + one control period {PERIOD} s"
    )
    # A ramp, not a step, down to zero, and zero it stays.
    assert first_decrease.v == pytest.approx(0.3 - LIMITS.max_accel * PERIOD, abs=EPS)
    assert sent[-1].v == 0.0
    assert sent[-1].omega == 0.0
    assert base.watchdog_trips == 1


def test_watchdog_does_not_trip_while_commands_keep_coming() -> None:
    base = BaseController(GEOMETRY)
    # Every 0.45 s, in between control ticks: always inside the 0.5 s timeout.
    sent = _drive(_every(0.45, 0.011, 3.0, 0.3, 0.0), until=3.0, base=base)
    assert base.watchdog_trips == 0
    cruise = [s for s in sent if s.t >= 0.4]
    assert all(s.v == pytest.approx(0.3, abs=EPS) for s in cruise)


def test_watchdog_trips_counts_each_timeout_once() -> None:
    base = BaseController(GEOMETRY)
    script = [
        *_every(0.1, 0.0, 0.5, 0.2, 0.0),  # timeout 1 at ~0.9 s
        *_every(0.1, 2.0, 2.5, 0.2, 0.0),  # timeout 2 at ~2.9 s
        *_every(0.1, 4.0, 4.5, 0.2, 0.0),  # timeout 3 at ~4.9 s
    ]
    sent = _drive(script, until=6.0, base=base)
    assert base.watchdog_trips == 3
    assert sent[-1].v == 0.0
    # Each new command after a timeout is obeyed again.
    assert _at(sent, 2.4).v == pytest.approx(0.2, abs=EPS)


def test_no_command_no_motion_no_trip() -> None:
    base = BaseController(GEOMETRY)
    sent = _drive([], until=1.0, base=base)
    assert len(sent) == 50
    assert all(s.left == s.right == 0.0 for s in sent)
    assert base.watchdog_trips == 0


def test_rate_and_timeout_must_be_positive() -> None:
    with pytest.raises(ValueError, match="cmd_timeout"):
        BaseController(GEOMETRY, cmd_timeout=0.0)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_non_finite_cmd_vel_is_rejected_and_logged_and_the_stack_runs_on(bad: float) -> None:
    # Before: one NaN twist became a NaN wheel command, the HAL refused it, the bridge
    # crashed and the whole stack stopped (issue 17, item 6).
    hal = FakeHardware()
    base = BaseController(GEOMETRY)
    sent: list[tuple[float, float]] = []
    logs: list[Log] = []

    async def main() -> None:
        async with System([Bridge(hal), base]) as system:
            wheel_cmd = system.subscribe(topics.WHEEL_CMD, WheelCommand, OBSERVE)
            rosout = system.subscribe(topics.ROSOUT, Log, OBSERVE)
            cmd_vel = system.publisher(topics.CMD_VEL, Twist, topics.COMMAND_QOS)
            for k in range(50):  # 1 s of commands every 20 ms, one of them bad
                await anyio.sleep_until(k * PERIOD)
                await cmd_vel.publish(Twist.planar(bad if k == 25 else 0.2, 0.0))
            await anyio.sleep_until(1.0 + PERIOD / 4)
            while (message := wheel_cmd.try_recv()) is not None:
                sent.append((message.header.stamp.to_seconds(), message.left))
            while (log := rosout.try_recv()) is not None:
                logs.append(log)

    _run(hal, main)  # raises if any actor crashed
    assert sent[-1][0] == pytest.approx(1.0)  # the base kept publishing to the end
    assert all(math.isfinite(left) for _t, left in sent)
    # The bad command was dropped, the robot kept the last good one: no jump, no stop.
    cruise = twist_to_wheels(0.2, 0.0, GEOMETRY)[0]
    assert [left for t, left in sent if 0.5 <= t <= 1.0] == pytest.approx(
        [cruise] * len([t for t, _ in sent if 0.5 <= t <= 1.0])
    )
    assert base.rejected_commands == 1
    (warning,) = [log for log in logs if log.name == "base"]
    assert warning.level == Log.WARN
    assert "/cmd_vel" in warning.msg
    assert "not finite" in warning.msg
    assert warning.stamp.to_seconds() == pytest.approx(26 * PERIOD)


def test_a_stream_of_bad_commands_is_logged_at_most_once_per_second() -> None:
    hal = FakeHardware()
    base = BaseController(GEOMETRY)
    logs: list[Log] = []

    async def main() -> None:
        async with System([base]) as system:
            rosout = system.subscribe(topics.ROSOUT, Log, OBSERVE)
            cmd_vel = system.publisher(topics.CMD_VEL, Twist, topics.COMMAND_QOS)
            for k in range(150):  # 3 s of NaN every 20 ms
                await anyio.sleep_until(k * PERIOD)
                await cmd_vel.publish(Twist.planar(math.nan, 0.0))
            await anyio.sleep_until(3.0)
            while (log := rosout.try_recv()) is not None:
                logs.append(log)

    _run(hal, main)
    assert base.rejected_commands == 150
    assert [round(log.stamp.to_seconds(), 2) for log in logs] == [0.02, 1.02, 2.02]
    assert "(49 more since the last warning)" in logs[1].msg  # 0.04 .. 1.00 s


def test_a_deadband_is_added_to_each_turning_wheel_in_its_direction() -> None:
    """ADR 0066: a servo that loses 1 rad/s to friction gets it added to every wheel
    that turns, in its direction (a turn in place: one wheel each way); a wheel asked
    nothing gets nothing."""
    base = BaseController(GEOMETRY, deadband=1.0)
    without = _drive([(0.0, 0.0, 1.0), *_every(0.1, 0.1, 1.0, 0.0, 1.0)], until=1.0)
    carried = _drive([(0.0, 0.0, 1.0), *_every(0.1, 0.1, 1.0, 0.0, 1.0)], until=1.0, base=base)
    assert (carried[-1].left, carried[-1].right) == pytest.approx(
        (without[-1].left - 1.0, without[-1].right + 1.0), abs=EPS
    )
    assert without[-1].left < 0 < without[-1].right
    stopped = _drive(
        _every(0.1, 0.0, 0.5, 0.0, 0.0), until=0.5, base=BaseController(GEOMETRY, deadband=1.0)
    )
    assert {(s.left, s.right) for s in stopped} == {(0.0, 0.0)}
