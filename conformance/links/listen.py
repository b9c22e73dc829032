"""A listen-only link: the serial link's reader on a port the tool never transmits on.

A bus monitor is one more receiver on the wire. It must never disturb the bus it watches, so
:class:`ListenLink` is the :class:`~conformance.links.serial_link.SerialLink` reader (the same
stamping, kernel receive stamps where the port has them, the same :class:`TimingMeter`) with
its transmitting half refused: ``write`` and ``send_break`` raise :class:`ListenOnly`, no break
maker, pulse maker or transmit-enable line is ever built, and the port is opened without
touching RTS or DTR after pyserial's own open.

Nobody here knows who sent a byte, so every event has origin
:data:`~conformance.transcript.BUS` and the view infers the direction from the protocol. A
UART reads a break as a 0x00 with a framing error (no SDI-12 character is NUL), so a NUL is
recorded as a break whose start is about one frame before it was read; how long the spacing
went on after that the UART does not say, and the event says so
(``duration_uncertainty``).
"""

from __future__ import annotations

from dataclasses import replace

import serial

from ..protocol.timing import CHAR_TIME
from ..transcript import BUS, Event, EventKind
from .base import LinkInfo
from .echo import EchoMode, Heard
from .errors import LinkError
from .factory import (
    LOOP_UNCERTAINTY,
    LOW_LATENCY_UNCERTAINTY,
    USB_UNCERTAINTY,
    _low_latency,
    _net_uncertainty,
    _open,
    check_network_url,
)
from .registry import find
from .serial_link import SerialLink

#: How uncertain the length of a break read as a NUL is (s): the UART says only that the
#: spacing lasted at least a frame, so the length is unknown beyond that; a judge given this
#: figure can never decide a break-length rule from such a break.
UNKNOWN_LENGTH = 1.0
BREAK_TEXT = (
    "a NUL read with a framing error: a break (spacing for at least one frame; "
    "how much longer the UART does not say)"
)


class ListenOnly(LinkError):
    """Something asked a listen-only link to transmit."""


class ListenLink(SerialLink):
    """Hears everything on the bus through ``port``; never transmits."""

    def __init__(self, port: serial.SerialBase, info: LinkInfo, *, name: str = "") -> None:
        super().__init__(port, replace(info, can_break=False), None, name=name, echo=EchoMode.OFF)

    def _record(self, heard: Heard) -> None:
        """One received byte as a BUS event (caller holds the lock). Its uncertainty is the
        local one: a byte that came in a batch was stamped back to back with the others, so
        where it really ended is known only to the batch's room (the monitor read a gap of
        its own making before such a batch as a change of talker, and a reply start inside
        it as 0.2 ms, and flagged the sensor for both)."""
        u = self.meter.latest_between(heard.end - CHAR_TIME, heard.end)
        if heard.byte == 0:
            event = Event(
                EventKind.BREAK,
                BUS,
                heard.end - CHAR_TIME,
                heard.end,
                text=BREAK_TEXT,
                uncertainty=u,
                duration_uncertainty=UNKNOWN_LENGTH,
            )
        else:
            start = heard.end - CHAR_TIME
            event = Event(EventKind.CHAR, BUS, start, heard.end, wire=heard.byte, uncertainty=u)
        self.transcript.add(event)

    def heard_since(self, index: int) -> list[Event]:
        """The events recorded from ``index`` on (a copy); raises
        :class:`~conformance.links.errors.PortVanished` if the port failed."""
        self._check()
        with self._cond:
            return list(self.transcript.events[index:])

    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        raise ListenOnly(f"{self.name} is open listen-only: nothing is ever sent on it")

    def send_break(self, duration: float, *, exact: bool = False) -> Event:
        raise ListenOnly(f"{self.name} is open listen-only: no break is ever sent on it")


def open_listen_link(port: str) -> ListenLink:
    """Open ``port`` (a device or any pyserial URL) at 1200 baud 8N1 for listening only.
    Raises :class:`~conformance.links.errors.PortError` with the reason if it cannot."""
    kind = find(port)
    name = kind.name if kind.name in ("rfc2217", "socket", "loop") else "serial"
    check_network_url(port)
    raw = _open(port, name)
    if name in ("rfc2217", "socket"):
        floor = _net_uncertainty(port)
    elif name == "loop":
        floor = LOOP_UNCERTAINTY
    else:
        floor = LOW_LATENCY_UNCERTAINTY if _low_latency(raw) else USB_UNCERTAINTY
    info = LinkInfo(name, can_break=False, timing_uncertainty=floor)
    return ListenLink(raw, info, name=port)
