"""How each kind of real link puts spacing (a break) on the line.

pyserial's ``send_break()`` cannot make an SDI-12 break on POSIX (it rounds up to a quarter
second or more), and its RFC 2217 client waits for the server's acknowledgement after every
change of ``break_condition`` (polling every 50 ms), so breaks and the marking after them come
out far too long. The makers here only switch the line; the link times the spacing itself and
records the duration it achieved.
"""

from __future__ import annotations

import struct
import time
from typing import Protocol

import serial
from serial import rfc2217

from ..protocol.timing import BAUD

CONFIRM_WAIT = 0.5  # s: how long a server has to confirm a bit-rate change
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


class PulseRefused(RuntimeError):
    """The far end did not take the bit-rate change a UART-timed pulse needs."""


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

    def rate(self, baud: int) -> None:
        """Switch to ``baud``; over RFC 2217, wait until the server confirms it set exactly
        that rate (a server that ignores the change would send the NUL at 1200 baud: 7.5 ms
        of spacing instead of the length asked). Raises :class:`PulseRefused`."""
        if not self.remote:
            self.port.flush()  # what was queued at the old rate goes out at the old rate
            self.port.baudrate = baud
            return
        setting = self.port._rfc2217_port_settings["baudrate"]
        deadline = time.monotonic() + CONFIRM_WAIT
        while setting.state == rfc2217.REQUESTED and time.monotonic() < deadline:
            time.sleep(0.0005)  # the answer to the last restore first: it must not be ours
        setting.set(struct.pack("!I", baud))
        deadline = time.monotonic() + CONFIRM_WAIT
        while time.monotonic() < deadline:
            try:
                if setting.is_ready():
                    return
            except ValueError as exc:
                raise PulseRefused(f"the server set another bit rate than {baud}") from exc
            time.sleep(0.0005)
        raise PulseRefused(f"the server did not confirm the bit rate {baud}")

    def send_nul(self) -> None:
        self.port.write(b"\x00")

    def restore(self) -> None:
        """Back to 1200 baud (over RFC 2217 in order with the data: not waited for)."""
        if not self.remote:
            self.port.flush()
            self.port.baudrate = BAUD
            return
        self.port._rfc2217_port_settings["baudrate"].set(struct.pack("!I", BAUD))
