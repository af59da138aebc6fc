"""Faults on a timetable (hal.sim.faults): each starts and ends at its time."""

from __future__ import annotations

import pytest

from otonav.hal import FakeHardware
from otonav.hal.can import _protocol as p
from otonav.hal.can._bus import CAN_ERR_BUSOFF, CAN_ERR_RESTARTED, open_endpoint
from otonav.hal.sim import AxisParams, DriveEmulator, DriveMount
from otonav.hal.sim._schedule import FaultPlan, Window
from otonav.stack import StackConfig
from otonav.stack._faults import fault_plan
from otonav.stack._overrides import apply_overrides


def test_each_fault_starts_and_ends_at_its_time() -> None:
    """The emulator applies its plan at its 10 ms exchanges, watched from the host's
    end of a virtual bus: the drop rate, bus-off and its restart (error frames), the
    axis error (once), a drive's heartbeat stopping."""
    plan = FaultPlan(
        drop_rate=0.5, drop=Window(1.0, 2.0), bus_off=Window(3.0, 3.5),
        axis_error_node=1, axis_error_at=4.0, heartbeat_node=0, heartbeat_lost=Window(5.0),
    )  # fmt: skip
    world = FakeHardware()
    host = open_endpoint("virtual", "test-fault-schedule")
    emulator = DriveEmulator(
        open_endpoint("virtual", "test-fault-schedule"),
        world, AxisParams(0), AxisParams(1), schedule=plan,
        left_mount=DriveMount(1, 1.0), right_mount=DriveMount(1, 1.0),
        heartbeat_period=0.1, encoder_period=0.01,
    )  # fmt: skip
    drop_rate: dict[float, float] = {}
    bus_errors: list[tuple[float, int]] = []
    heartbeats: dict[int, list[float]] = {0: [], 1: []}
    axis_errors: list[float] = []
    try:
        for _ in range(601):
            t = round(world.ticks * world.tick, 2)
            emulator.exchange(world.ticks)
            drop_rate[t] = emulator.faults.drop_rate
            if emulator.drive(1).error and (not axis_errors or axis_errors[-1] < t - 0.015):
                axis_errors.append(t)
                emulator.drive(1).clear_errors()  # an injected error comes only once
            for frame in host.poll():
                if frame.is_error:
                    bus_errors.append((t, frame.arbitration_id))
                elif frame.arbitration_id & 0x1F == p.CMD_HEARTBEAT:
                    heartbeats[frame.arbitration_id >> 5].append(t)
            world.advance(5)
    finally:
        emulator.close()
        host.close()
    assert (drop_rate[0.99], drop_rate[1.0], drop_rate[1.99], drop_rate[2.0]) == (0, 0.5, 0.5, 0)
    assert bus_errors == [(3.0, CAN_ERR_BUSOFF), (3.5, CAN_ERR_RESTARTED)]
    assert axis_errors == [4.0]
    assert max(heartbeats[0]) == pytest.approx(4.9)  # the last before 5 s
    assert max(heartbeats[1]) == pytest.approx(6.0)
    assert not [t for t in heartbeats[0] + heartbeats[1] if 3.0 <= t < 3.5]  # bus off


def test_the_config_keys_make_the_plan() -> None:
    stack = apply_overrides(
        StackConfig(),
        ["hal.sim.faults.drop.rate=0.3", "hal.sim.faults.drop.at=2", "hal.sim.faults.bus_off.at=4"],
    )
    plan = fault_plan(stack.hal.sim.faults)
    assert plan.drop_rate == 0.3
    assert plan.drop == Window(2.0, None)
    assert plan.bus_off == Window(4.0, None)
    assert fault_plan(StackConfig().hal.sim.faults).empty
