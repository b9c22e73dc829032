"""How each kind of real link puts spacing (a break) on the line.

pyserial's ``send_break()`` cannot make an SDI-12 break on POSIX (it rounds up to a quarter
second or more), and its RFC 2217 client waits for the server's acknowledgement after every
change of ``break_condition`` (polling every 50 ms), so breaks and the marking after them come
out far too long. The makers here only switch the line; the link times the spacing itself and
records the duration it achieved.
"""

from __future__ import annotations

from typing import Protocol

import serial
from serial import rfc2217


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
