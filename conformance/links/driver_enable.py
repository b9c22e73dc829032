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

import threading
import time
from collections.abc import Callable
from enum import StrEnum

import serial
from serial import rfc2217

from .priority import READER, realtime_priority


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


class TimedRelease:
    """Releases the driver at a given instant from a real-time thread of its own.

    The thread that writes may be busy (or preempted on a loaded machine) when the last stop
    bit leaves; a driver released late swallows the start of the sensor's reply, which then
    looks late or malformed. A sleeping real-time thread wakes within microseconds of its
    deadline, so the release follows the stop bit by little more than the link's latency;
    the moment it really happened is kept, so the turnaround is measured, not assumed."""

    def __init__(self, direction: Direction, clock: Callable[[], float]) -> None:
        self.direction = direction
        self.clock = clock
        self._cond = threading.Condition()
        self._due: float | None = None
        self._released: float | None = None
        self._failure: BaseException | None = None
        self._closing = False
        self._thread = threading.Thread(target=self._run, name="sdi12-direction", daemon=True)
        self._thread.start()

    def schedule(self, at: float) -> None:
        with self._cond:
            self._due, self._released = at, None
            self._cond.notify_all()

    def wait(self, bound: float) -> float | None:
        """When the release happened (link clock), waiting at most ``bound`` s for it."""
        deadline = self.clock() + bound
        with self._cond:
            while self._released is None and self._failure is None:
                left = deadline - self.clock()
                if left <= 0:
                    break
                self._cond.wait(left)
            if self._failure is not None:
                failure, self._failure = self._failure, None
                raise failure
            return self._released

    def close(self) -> None:
        with self._cond:
            self._closing = True
            self._cond.notify_all()
        self._thread.join(timeout=1.0)

    def _run(self) -> None:
        realtime_priority(READER)
        while True:
            with self._cond:
                while self._due is None and not self._closing:
                    self._cond.wait()
                if self._closing:
                    return
                due = self._due
            left = due - self.clock()
            if left > 0:
                time.sleep(left)
            with self._cond:
                if self._due != due:  # rescheduled meanwhile
                    continue
                try:
                    self.direction.set(False)
                except Exception as exc:  # the port failed: the writer reports it
                    self._failure = exc
                self._due, self._released = None, self.clock()
                self._cond.notify_all()
