"""How each kind of real link puts spacing (a break) on the line.

pyserial's ``send_break()`` cannot make an SDI-12 break on POSIX (it rounds up to a quarter
second or more), and its RFC 2217 client waits for the server's acknowledgement after every
change of ``break_condition`` (polling every 50 ms), so breaks and the marking after them come
out far too long. The makers here only switch the line; the link times the spacing itself and
records the duration it achieved.
"""

from __future__ import annotations

import struct
from typing import Protocol

import serial
from serial import rfc2217

BAUD = 1200
NUL_SPACING_BITS = 9  # a NUL frame: start bit and 8 zero data bits, then the stop bit


class BreakMaker(Protocol):
    method: str  # shown in the break event, so a report says how the break was made

    def on(self) -> None: ...

    def off(self) -> None: ...


class UartBreak:
    """A local UART (or USB adapter): ``break_condition`` drives TIOCSBRK/TIOCCBRK."""

    method = "break_condition"

    def __init__(self, port: serial.SerialBase) -> None:
        self.port = port

    def on(self) -> None:
        self.port.break_condition = True

    def off(self) -> None:
        self.port.break_condition = False


class Rfc2217Break:
    """RFC 2217: the raw SET_CONTROL BREAK_ON/OFF messages, without waiting for the
    server's acknowledgement, so a break lasts what the link times (not 50 ms or more)."""

    method = "RFC 2217 SET_CONTROL"

    def __init__(self, port: rfc2217.Serial) -> None:
        self.port = port

    def on(self) -> None:
        self.port.rfc2217_send_subnegotiation(rfc2217.SET_CONTROL, rfc2217.SET_CONTROL_BREAK_ON)

    def off(self) -> None:
        self.port.rfc2217_send_subnegotiation(rfc2217.SET_CONTROL, rfc2217.SET_CONTROL_BREAK_OFF)


class BaudPulse:
    """Spacing timed by the UART's own bit clock: a NUL sent at a lower bit rate is spacing
    for exactly 9 bit times (1.875 ms at 4800 baud, 12.5 ms at 720), whatever the host's
    sleep or the link's latency do. The length is as exact as the UART's rate generator
    (``rate_error``); only where the pulse sits is left to the link's stamps.

    ``port`` is a local UART (the rate is switched with the port's settings, after draining
    what was queued) or an RFC 2217 client (the raw SET-BAUDRATE message, which the server
    applies in order with the data around it, without waiting for its acknowledgement).
    """

    MIN_BAUD = 150
    MAX_BAUD = 115200

    def __init__(self, port: serial.SerialBase, *, rate_error: float = 0.01) -> None:
        self.port = port
        self.rate_error = rate_error  # relative: FTDI-class generators stay well inside 1 %
        self.remote = isinstance(port, rfc2217.Serial)
        self.method = "RFC 2217 SET-BAUDRATE" if self.remote else "UART bit rate"
        # a local UART may hold the NUL in its FIFO after the host wrote it: wait that long
        self.settle = 0.0 if self.remote else 2e-3

    def can_make(self, duration: float) -> bool:
        baud = NUL_SPACING_BITS / duration if duration > 0 else 0
        return self.MIN_BAUD <= baud <= self.MAX_BAUD

    def baud_for(self, duration: float) -> int:
        return round(NUL_SPACING_BITS / duration)

    def send_nul(self, baud: int) -> None:
        self._rate(baud)
        self.port.write(b"\x00")

    def restore(self) -> None:
        if not self.remote:
            self.port.flush()
        self._rate(BAUD)

    def _rate(self, baud: int) -> None:
        if self.remote:
            self.port.rfc2217_send_subnegotiation(rfc2217.SET_BAUDRATE, struct.pack("!I", baud))
        else:
            self.port.flush()  # what was queued at the old rate goes out at the old rate
            self.port.baudrate = baud
