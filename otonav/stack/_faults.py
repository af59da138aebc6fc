"""``hal.sim.faults`` (config) as the emulator's :class:`~otonav.hal.sim._schedule.FaultPlan`."""

from __future__ import annotations

from otonav.hal.sim._schedule import FaultPlan, Window
from otonav.stack._config import FaultsConfig

__all__ = ["fault_plan"]


def fault_plan(faults: FaultsConfig) -> FaultPlan:
    """The timetable of faults the config asks for (empty: none)."""
    drop, delay, axis, bus, beat = (
        faults.drop,
        faults.delay,
        faults.axis_error,
        faults.bus_off,
        faults.heartbeat,
    )
    return FaultPlan(
        drop_rate=drop.rate,
        drop=Window(drop.at, drop.until),
        delay=delay.delay,
        jitter=delay.jitter,
        delayed=Window(delay.at, delay.until),
        axis_error_node=axis.node_id,
        axis_error_code=axis.code,
        axis_error_at=axis.at,
        bus_off=Window(bus.at, bus.until) if bus.at is not None else None,
        heartbeat_node=beat.node_id,
        heartbeat_lost=Window(beat.at, beat.until),
    )
