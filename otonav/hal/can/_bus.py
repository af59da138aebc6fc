"""The python-can boundary: the only otonav module that imports :mod:`can`.

A :class:`CanEndpoint` wraps one python-can bus and speaks :class:`RawFrame` (id, data,
flags) to the rest of otonav. It never starts a thread: :meth:`CanEndpoint.poll`
drains what arrived with ``recv(timeout=0)``, called from sim time (no ``Notifier``,
whose reader thread would run on the wall clock: ADR 0016).

On the ``virtual`` interface every endpoint opened on the same channel in this process
hears every other one, so a stack and its drive emulator meet there. Error frames use
the Linux SocketCAN error classes (``linux/can/error.h``): a controller that went
bus-off reports ``CAN_ERR_BUSOFF``, and one restarted after bus-off ``CAN_ERR_RESTARTED``.
"""

from __future__ import annotations

import queue
from typing import Any, Final, NamedTuple

import can
from can.interfaces.virtual import VirtualBus

__all__ = [
    "CAN_ERR_BUSOFF",
    "CAN_ERR_RESTARTED",
    "BusError",
    "CanEndpoint",
    "RawFrame",
    "open_endpoint",
]

CAN_ERR_BUSOFF: Final = 0x40
"""Error class bit of a controller in bus-off (SocketCAN error frame id)."""
CAN_ERR_RESTARTED: Final = 0x100
"""Error class bit of a controller restarted after bus-off."""


class RawFrame(NamedTuple):
    """One classic CAN frame: 11-bit ``arbitration_id``, up to 8 ``data`` bytes.

    A named tuple, not a frozen dataclass: just as immutable, built in a third of the
    time (~0.17 us instead of ~0.4 us, measured), and the receive path unpacks it."""

    arbitration_id: int
    data: bytes = b""
    is_error: bool = False
    is_remote: bool = False


class _Outgoing(can.Message):
    """The message an endpoint refills for its data frames: a :class:`can.Message` whose
    deep copy is made directly instead of through the constructor.

    ``VirtualBus.send`` deep-copies the sent message once per receiver; python-can's
    ``Message.__deepcopy__`` calls ``Message(...)`` with twelve keyword arguments and
    deep-copies the payload and channel (three ``copy.deepcopy`` calls): 2.8 of the 5.6
    us a frame costs on a virtual bus (measured). This copy sets the same slots to the
    same values and types -- a plain ``can.Message``, ``data`` a new ``bytearray`` -- so
    what a receiver gets is what python-can's own copy would give (a unit test compares
    every slot of both). The bus code is python-can's, unchanged."""

    __slots__ = ()

    def __deepcopy__(self, memo: dict[int, Any] | None) -> can.Message:
        channel = self.channel
        if not (channel is None or isinstance(channel, str | int)):
            return super().__deepcopy__(memo)  # a channel object: python-can's deep copy
        if memo is not None:
            # copy.deepcopy then keeps the original alive in memo[id(memo)], a list it
            # makes by catching a KeyError on the first copy of every deepcopy call (each
            # of ours): an exception per frame, ~0.2 us. An empty list here spares it.
            memo.setdefault(id(memo), [])
        copy: can.Message = _new_message(can.Message)
        copy.timestamp = self.timestamp
        copy.arbitration_id = self.arbitration_id
        copy.is_extended_id = self.is_extended_id
        copy.is_remote_frame = self.is_remote_frame
        copy.is_error_frame = self.is_error_frame
        copy.channel = channel
        copy.is_fd = self.is_fd
        copy.is_rx = self.is_rx
        copy.bitrate_switch = self.bitrate_switch
        copy.error_state_indicator = self.error_state_indicator
        copy.data = bytearray() if self.is_remote_frame else bytearray(self.data)
        copy.dlc = self.dlc
        return copy


_new_message = object.__new__


class BusError(RuntimeError):
    """The bus refused a frame or could not be opened (bus-off, link down, no driver)."""


class CanEndpoint:
    """One node's access to a CAN bus: ``send`` frames, ``poll`` what arrived."""

    def __init__(self, bus: can.BusABC, channel: str) -> None:
        self._bus = bus
        self._bus_send = bus.send
        self.channel = channel
        self._closed = False
        # A virtual bus's receive queue (a public attribute of VirtualBus): poll reads
        # exactly what it holds instead of ending on an empty recv(0), which raises and
        # catches queue.Empty inside python-can (1.1 us, at every bus instant).
        self._rx_queue: queue.Queue[can.Message] | None = None
        self.sim_stamps = isinstance(bus, VirtualBus) and bool(
            getattr(bus, "preserve_timestamps", False)
        )
        """The frames' timestamps are the senders' sim times (a virtual bus that keeps
        them): :meth:`poll` can report them, and a receiver can tell how old a frame
        is. On other buses they are the kernel's wall-clock receive times."""
        # On a virtual bus, one Message per endpoint for its data frames, refilled:
        # VirtualBus.send deep-copies it for every receiver before returning, so nothing
        # keeps it (~1.5 us less per frame than a new Message, measured). Its flags
        # stay those of a classic data frame; error and remote frames get their own.
        self._template: can.Message | None = None
        if isinstance(bus, VirtualBus):
            self._rx_queue = bus.queue
            self._template = _Outgoing(is_extended_id=False, check=False)

    def send_data(self, arbitration_id: int, data: bytes, timestamp: float = 0.0) -> None:
        """Put a classic data frame on the bus (the hot path: no :class:`RawFrame`).

        ``data`` is immutable ``bytes``: python-can deep-copies the payload of every
        frame for every receiver, and a copy of its own bytearray took 11 us instead of
        4.6 us (measured). ``timestamp``: sim seconds, kept on virtual buses."""
        message = self._template
        if message is None:
            message = can.Message(is_extended_id=False, check=False)
        message.timestamp = timestamp
        message.arbitration_id = arbitration_id
        message.data = data  # type: ignore[assignment]
        message.dlc = len(data)
        try:
            self._bus_send(message, timeout=0.0)
        except can.CanError as exc:
            raise BusError(f"CAN send on {self.channel} failed: {exc}") from exc

    def send(self, frame: RawFrame, timestamp: float = 0.0) -> None:
        """Put ``frame`` on the bus (``timestamp``: sim seconds, kept on virtual buses)."""
        if not (frame.is_error or frame.is_remote):
            self.send_data(frame.arbitration_id, frame.data, timestamp)
            return
        message = can.Message(
            timestamp=timestamp,
            arbitration_id=frame.arbitration_id,
            is_extended_id=False,
            is_error_frame=frame.is_error,
            is_remote_frame=frame.is_remote,
            check=False,
        )
        message.data = frame.data  # type: ignore[assignment]
        message.dlc = len(frame.data)
        try:
            self._bus_send(message, timeout=0.0)
        except can.CanError as exc:
            raise BusError(f"CAN send on {self.channel} failed: {exc}") from exc

    def poll(self, stamps: list[float] | None = None) -> list[RawFrame]:
        """Every frame received since the last poll, in arrival order; never blocks.

        ``stamps``: if given, each frame's timestamp is appended to it (the sender's sim
        time where :attr:`sim_stamps`)."""
        recv = self._bus.recv
        # A virtual bus: exactly as many frames as its queue holds; others: until empty.
        n = -1 if self._rx_queue is None else self._rx_queue.qsize()
        frames: list[RawFrame] = []
        append = frames.append
        try:
            while n:
                message = recv(0.0)
                if message is None:
                    break
                append(
                    RawFrame(
                        message.arbitration_id,
                        bytes(message.data),
                        message.is_error_frame,
                        message.is_remote_frame,
                    )
                )
                if stamps is not None:
                    stamps.append(message.timestamp)
                n -= 1
        except can.CanError as exc:
            raise BusError(f"CAN receive on {self.channel} failed: {exc}") from exc
        return frames

    def close(self) -> None:
        """Shut the bus down. Idempotent."""
        if not self._closed:
            self._closed = True
            self._bus.shutdown()


def open_endpoint(interface: str, channel: str, *, label: str | None = None) -> CanEndpoint:
    """Open ``channel`` on python-can ``interface`` (``virtual``, ``socketcan``, ...).

    ``label`` is the name the endpoint reports as its channel (default ``channel``): a
    private virtual channel keeps the name people configured.

    Raises :class:`BusError` naming the interface and channel when python-can cannot
    (an unknown interface, a missing ``can0``). The bitrate of a SocketCAN link is set
    by ``ip link``, not here.
    """
    kwargs: dict[str, Any] = {}
    if interface == "virtual":
        kwargs["preserve_timestamps"] = True  # sim time, not the wall clock
    try:
        bus = can.Bus(interface=interface, channel=channel, **kwargs)
    except (can.CanError, OSError, ValueError, ImportError, NotImplementedError) as exc:
        raise BusError(
            f"cannot open CAN channel {channel!r} on interface {interface!r}: {exc}"
        ) from exc
    return CanEndpoint(bus, channel if label is None else label)
