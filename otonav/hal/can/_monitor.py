"""Watching the drives: startup, fault detection, recovery. Pure logic on sim time.

The interface feeds a :class:`DriveMonitor` what it hears (heartbeats, encoder frames,
error frames, failed sends) and calls :meth:`DriveMonitor.check` at every instant it
polls the bus. ``check`` returns the :class:`Action` frames to send and keeps
:attr:`DriveMonitor.health` current. Phases:

    STARTING --all nodes report CLOSED_LOOP_CONTROL--> RUNNING --fault--> FAULT
    FAULT --cause clear for recovery_delay--> RECOVERING (Clear_Errors + closed loop)
    RECOVERING --all nodes in closed loop--> RUNNING      (logged as a recovery)
    STARTING / RECOVERING --startup_timeout--> FAULT       (naming the silent node ids)

Faults, and what the interface does on detection (ADR "CAN interface"):

=================  ======================================================  ==========
fault              detected when                                           action
=================  ======================================================  ==========
startup_timeout    a node does not report closed loop within the timeout   Estop all
heartbeat_lost     a node's heartbeat is older than ``heartbeat_timeout``  Estop all
axis_error         a heartbeat shows an error, or a state not closed loop  Estop all
encoder_stale      a node's newest encoder estimate is older than the         zero vel
                   timeout: none arrived, or it was measured that long ago
frame_loss         encoder frames lost over ``loss_window`` > max          zero vel
bus_off            an error frame says bus-off, or a send fails            zero vel
=================  ======================================================  ==========

A fault latches; recovery starts only once its cause has been clear for
``recovery_delay`` s. Recovery attempts are counted per drive, whatever the fault's
kind, and a drive's count starts again from zero only after ``recovery_reset`` s of
running without a fault: a drive that faults again soon after each recovery (an axis
error, then a stale encoder, then an axis error...) gets ``max_recovery_attempts`` in
all. Then, or at once for a fault no recovery can clear (a wrong node id: the expected
drive is silent while another answers), the fault is *permanent*
(:attr:`HardwareHealth.permanent`): the monitor stops trying, and a scenario run ends
with the fault as its verdict (issue 27).
"""

from __future__ import annotations

import enum
import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass

from otonav.hal._health import HardwareHealth, HealthLevel
from otonav.hal.can._protocol import AxisState, error_names
from otonav.params import MonitorLimits

__all__ = ["Action", "DriveMonitor", "MonitorLimits", "NodeLabel", "Phase"]

_CLOSED_LOOP = AxisState.CLOSED_LOOP_CONTROL


class Phase(enum.Enum):
    """The monitor's state: starting, running, in a fault, or recovering from one."""

    STARTING = "starting"
    RUNNING = "running"
    FAULT = "fault"
    RECOVERING = "recovering"


class Action(enum.Enum):
    """What the interface must put on the bus after a check."""

    ESTOP_ALL = "estop_all"
    ZERO_ALL = "zero_all"
    START_ALL = "start_all"
    """Clear_Errors, Set_Controller_Mode (velocity), Set_Axis_State(CLOSED_LOOP)."""


@dataclass(frozen=True, slots=True)
class NodeLabel:
    node_id: int
    label: str

    def __str__(self) -> str:
        return f"node {self.node_id} ({self.label})"


_LIMITS = MonitorLimits()


class _Node:
    __slots__ = ("arrivals", "encoder_at", "error", "heartbeat_at", "label", "state")

    def __init__(self, label: NodeLabel) -> None:
        self.label = label
        self.heartbeat_at = -math.inf
        self.encoder_at = -math.inf
        self.error = 0
        self.state = int(AxisState.UNDEFINED)
        self.arrivals: deque[float] = deque()


class DriveMonitor:
    """Startup, fault detection and recovery for the drives ``nodes``."""

    def __init__(self, nodes: Sequence[NodeLabel], limits: MonitorLimits = _LIMITS):
        self.limits = limits
        self._nodes = {n.node_id: _Node(n) for n in nodes}
        self._foreign: set[int] = set()
        self.phase = Phase.STARTING
        self._requested_at = 0.0
        self._running_since = 0.0
        self._fault = ""
        self._fault_message = ""
        self._clear_since: float | None = None
        self._attempts: dict[int, int] = {}  # recovery attempts per drive (node id)
        self._fault_nodes: tuple[int, ...] = ()  # the drives the current fault is about
        self.permanent = False
        """The fault will not be recovered from (gave up, or a wrong node id)."""
        self._bus_off = False
        self._loss_due = -math.inf
        # RUNNING: no check can find a fault before this instant (see check()).
        self._quiet_until = -math.inf
        self.events: list[tuple[float, str]] = []
        self.drivable = False
        """``health.drivable``, kept as a plain attribute (read at every wheel write)."""
        self.health = HardwareHealth(
            level=HealthLevel.WARN,
            ready=False,
            fault="",
            message="starting: waiting for "
            + ", ".join(str(n) for n in nodes)
            + " to report CLOSED_LOOP_CONTROL",
            since=0.0,
        )

    # -- what the interface heard --------------------------------------------------------

    def heartbeat(self, node_id: int, error: int, state: int, now: float) -> None:
        node = self._nodes.get(node_id)
        if node is None:
            self._foreign.add(node_id)
            return
        node.heartbeat_at, node.error, node.state = now, error, state
        if error or state != _CLOSED_LOOP:
            self._quiet_until = -math.inf  # an axis error: the next check must see it

    def encoder(self, node_id: int, now: float, measured: float | None = None) -> None:
        """An encoder frame of ``node_id`` arrived at ``now``; its estimate was measured
        at ``measured`` (its frame's timestamp; None: ``now``)."""
        node = self._nodes.get(node_id)
        if node is None:
            self._foreign.add(node_id)
            return
        node.encoder_at = now if measured is None else measured
        node.arrivals.append(now)

    def bus_off(self, now: float, detail: str) -> None:
        self._bus_off = True
        if self.phase is not Phase.FAULT or self._fault != "bus_off":
            self._enter_fault(now, "bus_off", f"CAN bus-off: {detail}", tuple(self._nodes))

    def bus_restarted(self, now: float) -> None:
        if self._bus_off:
            self._bus_off = False
            self.events.append((now, "CAN controller restarted after bus-off"))

    def requested(self, now: float) -> None:
        """The interface sent the closed-loop request (startup or recovery)."""
        self._requested_at = now

    # -- the check -----------------------------------------------------------------------

    def check(self, now: float) -> tuple[Action, ...]:
        """The interface calls this at every bus instant (every 10 ms).

        While running, a full check runs only from the first instant at which one of
        its conditions could hold: the oldest heartbeat or encoder estimate reaching
        its timeout, the next frame-loss judgement, or at once after a heartbeat that
        shows an error or a state other than closed loop. Frames arriving in between
        only push those instants later, so detection happens at the same instant as
        with a full check every time (the fault tests pin it), for a fifth of the cost."""
        phase = self.phase
        if phase is Phase.RUNNING:
            if now < self._quiet_until:
                return ()
            return self._check_running(now)
        if phase is Phase.STARTING or phase is Phase.RECOVERING:
            return self._check_starting(now)
        return self._check_fault(now)

    def _in_closed_loop(self, node: _Node) -> bool:
        return (
            node.heartbeat_at > self._requested_at
            and node.error == 0
            and node.state == _CLOSED_LOOP
        )

    def _check_starting(self, now: float) -> tuple[Action, ...]:
        if self._bus_off:
            return (Action.ZERO_ALL,)
        nodes = self._nodes.values()
        if all(self._in_closed_loop(n) for n in nodes):
            recovering = self.phase is Phase.RECOVERING
            self.phase = Phase.RUNNING
            self._running_since = now
            self._quiet_until = -math.inf
            for node in nodes:
                node.arrivals.clear()
            names = ", ".join(str(n.label) for n in nodes)
            if recovering:
                message = (
                    f"recovered from {self._fault} ({self._fault_message}): {names} "
                    "in CLOSED_LOOP_CONTROL again"
                )
            else:
                message = f"running: {names} in CLOSED_LOOP_CONTROL"
            self._set(now, HealthLevel.OK, True, "", message)
            self._fault = self._fault_message = ""
            return ()
        if now - self._requested_at > self.limits.startup_timeout + 1e-9:
            silent = tuple(n.label.node_id for n in nodes if n.heartbeat_at <= self._requested_at)
            if self.phase is Phase.RECOVERING:
                fault, faulted = self._fault, self._fault_nodes
                cause = self._fault_message.split("; recovery from")[0]
                message = f"{cause}; recovery from {fault} failed: {self._startup_message(now)}"
            else:
                fault, message = "startup_timeout", self._startup_message(now)
                faulted = tuple(n.label.node_id for n in nodes if not self._in_closed_loop(n))
            self._enter_fault(now, fault, message, faulted)
            if silent and self._foreign:
                # Our drive is silent while another node answers: a wrong node id (or a
                # drive on the wrong bus). No Clear_Errors will change that.
                self._give_up(now, "permanent: no drive answers on that node id")
            return (Action.ESTOP_ALL,)
        return ()

    def _startup_message(self, now: float) -> str:
        parts = []
        for node in self._nodes.values():
            if self._in_closed_loop(node):
                continue
            if node.heartbeat_at <= self._requested_at:
                parts.append(f"{node.label}: no heartbeat")
            else:
                parts.append(
                    f"{node.label}: state {_state_name(node.state)}, "
                    f"axis error 0x{node.error:08x} ({error_names(node.error)})"
                )
        text = (
            "; ".join(parts)
            + f" within {self.limits.startup_timeout:g} s of sim time after requesting "
            f"CLOSED_LOOP_CONTROL (at {self._requested_at:.2f} s)"
        )
        foreign = sorted(self._foreign)
        heard = any(n.heartbeat_at > self._requested_at for n in self._nodes.values())
        if foreign:
            text += f"; drives answering on this bus: node ids {foreign} (check hal.can.*.node_id)"
        elif not heard:
            text += "; no drive answered at all (check wiring, power and hal.can.channel)"
        return text

    def _check_running(self, now: float) -> tuple[Action, ...]:
        limits = self.limits
        # The earliest instant a timeout could fire next (see check()).
        quiet = math.inf
        for node in self._nodes.values():
            quiet = min(
                quiet,
                node.heartbeat_at + limits.heartbeat_timeout,
                node.encoder_at + limits.encoder_timeout,
            )
            found = self._node_fault(node, now)
            if found is not None:
                fault, why, action = found
                self._enter_fault(now, fault, f"{node.label}: {why}", (node.label.node_id,))
                return (action,)
        if now >= self._loss_due:
            self._loss_due = now + limits.loss_window / 10.0
        self._quiet_until = min(quiet, self._loss_due)
        return ()

    def _node_fault(self, node: _Node, now: float) -> tuple[str, str, Action] | None:
        """The fault ``node`` shows while running, why, and what to send."""
        lim, hb_age, enc_age = self.limits, now - node.heartbeat_at, now - node.encoder_at
        if hb_age > lim.heartbeat_timeout + 1e-9:
            why = f"no heartbeat for {hb_age:.3f} s of sim time"
            return (
                "heartbeat_lost",
                f"{why} (timeout {lim.heartbeat_timeout:g} s)",
                Action.ESTOP_ALL,
            )
        if node.error or node.state != _CLOSED_LOOP:
            why = f"axis error 0x{node.error:08x} ({error_names(node.error)})"
            return "axis_error", f"{why}, state {_state_name(node.state)}", Action.ESTOP_ALL
        if enc_age > lim.encoder_timeout + 1e-9:
            why = f"newest encoder estimate {enc_age:.3f} s old in sim time (timeout "
            return (
                "encoder_stale",
                f"{why}{lim.encoder_timeout:g} s; frames delayed or lost)",
                Action.ZERO_ALL,
            )
        if now < self._loss_due:  # the loss is judged ten times per window
            return None
        loss = self._loss(node, now, self._running_since)
        if loss is None or loss <= lim.max_frame_loss:
            return None
        why = f"{loss:.0%} of encoder frames lost over the last {lim.loss_window:g} s"
        return "frame_loss", f"{why} (max {lim.max_frame_loss:.0%})", Action.ZERO_ALL

    def _loss(self, node: _Node, now: float, since: float) -> float | None:
        """Fraction of encoder frames missing over the loss window; None until a whole
        window has passed ``since``."""
        limits = self.limits
        start = now - limits.loss_window
        arrivals = node.arrivals
        while arrivals and arrivals[0] <= start + 1e-9:
            arrivals.popleft()
        if now - since < limits.loss_window - 1e-9:
            return None
        expected = limits.loss_window / limits.encoder_period
        return max(0.0, 1.0 - len(arrivals) / expected)

    def _cause_clear(self, now: float) -> bool:
        limits = self.limits
        if self._bus_off:
            return False
        fresh = all(now - n.heartbeat_at <= limits.heartbeat_timeout for n in self._nodes.values())
        if self._fault in ("encoder_stale", "frame_loss"):
            for node in self._nodes.values():
                loss = self._loss(node, now, -math.inf)
                if now - node.encoder_at > limits.encoder_timeout or (
                    loss is not None and loss > limits.max_frame_loss
                ):
                    return False
        return fresh

    def _check_fault(self, now: float) -> tuple[Action, ...]:
        limits = self.limits
        if self.permanent or not self._cause_clear(now):
            self._clear_since = None
            return ()
        if self._clear_since is None:
            self._clear_since = now
        if now - self._clear_since < limits.recovery_delay - 1e-9:
            return ()
        attempts = self._attempts
        worst = max(self._fault_nodes, key=lambda n: attempts.get(n, 0), default=None)
        if worst is not None and attempts.get(worst, 0) >= limits.max_recovery_attempts:
            self._give_up(
                now,
                f"gave up after {attempts.get(worst, 0)} recovery attempts of "
                f"{self._nodes[worst].label}: restart the drives",
            )
            return ()
        for node_id in self._fault_nodes:
            attempts[node_id] = attempts.get(node_id, 0) + 1
        self.phase = Phase.RECOVERING
        self._requested_at = now
        attempt = max((attempts[n] for n in self._fault_nodes), default=0)
        self._set(
            now,
            HealthLevel.WARN,
            False,
            self._fault,
            f"recovering from {self._fault} (attempt {attempt}): cause clear for "
            f"{now - self._clear_since:.2f} s; Clear_Errors and CLOSED_LOOP_CONTROL sent to "
            + ", ".join(str(n.label) for n in self._nodes.values()),
        )
        self._clear_since = None
        return (Action.START_ALL,)

    def _give_up(self, now: float, why: str) -> None:
        """The fault is permanent: no more recovery, a run ends on it."""
        self.permanent = True
        self._set(now, HealthLevel.ERROR, False, self._fault, f"{self._fault_message}; {why}")

    def _enter_fault(self, now: float, fault: str, message: str, nodes: tuple[int, ...]) -> None:
        if (
            self.phase is Phase.RUNNING
            and now - self._running_since >= self.limits.recovery_reset - 1e-9
        ):
            self._attempts.clear()  # ran long enough without a fault: a fresh start
        self.phase = Phase.FAULT
        self._fault, self._fault_message = fault, message
        self._fault_nodes = nodes
        self._clear_since = None
        self._set(now, HealthLevel.ERROR, False, fault, message)

    def _set(self, now: float, level: HealthLevel, ready: bool, fault: str, message: str) -> None:
        values = tuple(
            (
                f"node {n.label.node_id}",
                f"{n.label.label}: state {_state_name(n.state)}, error 0x{n.error:08x}",
            )
            for n in self._nodes.values()
        )
        self.health = HardwareHealth(
            level=level,
            ready=ready,
            fault=fault,
            message=message,
            since=now,
            permanent=self.permanent,
            values=(("phase", self.phase.value), *values),
        )
        self.drivable = self.health.drivable
        self.events.append((now, message))


def _state_name(state: int) -> str:
    try:
        return AxisState(state).name
    except ValueError:
        return str(state)
