"""Faults on a timetable (hal.sim.faults): each starts and ends at its time."""

from __future__ import annotations

from otonav.hal.sim.emulator import BusFaults
from otonav.hal.sim.schedule import FaultPlan, FaultSchedule, Window
from otonav.stack import StackConfig
from otonav.stack.faults import fault_plan
from otonav.stack.overrides import apply_overrides


class Recorder:
    """Stands in for the emulator: records what the schedule asks of it."""

    def __init__(self) -> None:
        self.faults = BusFaults()
        self.calls: list[tuple[str, object]] = []
        self.state: dict[str, object] = {"bus_off": False, "heartbeat": (0, False)}

    def _change(self, what: str, value: object) -> None:
        if self.state[what] != value:  # as the emulator: asking again changes nothing
            self.state[what] = value
            self.calls.append((what, value))

    def set_bus_off(self, off: bool) -> None:
        self._change("bus_off", off)

    def silence_heartbeat(self, node: int, silent: bool) -> None:
        self._change("heartbeat", (node, silent))

    def inject_axis_error(self, node: int, code: int) -> None:
        self.calls.append(("axis_error", (node, code)))


def test_each_fault_starts_and_ends_at_its_time() -> None:
    plan = FaultPlan(
        drop_rate=0.5, drop=Window(1.0, 2.0), bus_off=Window(3.0, 3.5),
        axis_error_node=1, axis_error_at=4.0, heartbeat_node=0, heartbeat_lost=Window(5.0),
    )  # fmt: skip
    schedule, emulator = FaultSchedule(plan), Recorder()
    seen = {}
    for k in range(0, 601):
        t = k * 0.01
        schedule.apply(emulator, t)  # type: ignore[arg-type]
        seen[round(t, 2)] = (emulator.faults.drop_rate, list(emulator.calls))
    assert seen[0.99][0] == 0.0
    assert seen[1.0][0] == 0.5
    assert seen[1.99][0] == 0.5
    assert seen[2.0][0] == 0.0
    calls = seen[6.0][1]
    assert ("bus_off", True) in calls
    assert calls.index(("bus_off", True)) < calls.index(("bus_off", False))
    assert calls.count(("axis_error", (1, 0x20))) == 1  # once, at 4 s
    assert ("axis_error", (1, 0x20)) not in seen[3.99][1]
    assert ("heartbeat", (0, True)) in calls
    assert ("heartbeat", (0, True)) not in seen[4.99][1]
    assert schedule.next_time == float("inf")


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
