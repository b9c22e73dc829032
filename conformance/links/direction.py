"""Transmit enable: interfaces whose driver is switched by RTS or DTR.

Many SDI-12 interfaces built from an RS-485-style transceiver enable their driver with a
modem-control line. The tool raises it for exactly its own transmissions (a break, a
command) and releases it after the last stop bit, so the sensor can answer; how long after
the stop bit the release happened (the turnaround) is measured by the link, because a
driver still enabled when the sensor starts its reply would swallow it.

On a local UART the line is switched with the port's ``rts``/``dtr``; over RFC 2217 with the
raw SET_CONTROL message, without waiting for the server's acknowledgement (pyserial's own
setter polls for it every 50 ms).
"""

from __future__ import annotations

from enum import StrEnum

import serial
from serial import rfc2217


class DirectionLine(StrEnum):
    NONE = "none"
    RTS = "rts"
    DTR = "dtr"


_RFC2217 = {
    (DirectionLine.RTS, True): rfc2217.SET_CONTROL_RTS_ON,
    (DirectionLine.RTS, False): rfc2217.SET_CONTROL_RTS_OFF,
    (DirectionLine.DTR, True): rfc2217.SET_CONTROL_DTR_ON,
    (DirectionLine.DTR, False): rfc2217.SET_CONTROL_DTR_OFF,
}


class Direction:
    """Switches one modem-control line of ``port`` as the driver's enable."""

    def __init__(self, port: serial.SerialBase, line: DirectionLine) -> None:
        self.port = port
        self.line = str(line)
        self._line = line

    def set(self, on: bool) -> None:
        if isinstance(self.port, rfc2217.Serial):
            self.port.rfc2217_send_subnegotiation(rfc2217.SET_CONTROL, _RFC2217[self._line, on])
        elif self._line is DirectionLine.RTS:
            self.port.rts = on
        else:
            self.port.dtr = on
