"""A :class:`~conformance.links.base.Link` over any pyserial port or URL, in real time.

The port runs at 1200 baud 8N1; the even-parity bit of 7E1 characters is made and checked in
software (requirements.md implementation notes). A 7E1 frame and an 8N1 frame are both 10
bits, so commands go out as 7E1 and ``aDBn!`` packets come back as 8N1 on the same port
settings, and every received byte is kept whole in ``Event.wire``: a parity error is evidence
(``Event.parity_ok``), not something a UART silently drops.

A reader thread stamps each chunk of bytes with ``perf_counter_ns`` as it arrives and turns
the stamps into wire events (:mod:`~conformance.links.stamps`). Every public call is bounded
by its deadline; a port that fails while the run goes on raises
:class:`~conformance.links.errors.PortVanished` from the next call.
"""

from __future__ import annotations

import contextlib
import threading
import time
from collections import deque

import serial

from ..protocol.timing import CHAR_TIME
from ..transcript import DUT, TOOL, Event, EventKind, Transcript
from .base import Link, LinkInfo, StopCondition
from .breaks import BreakMaker
from .errors import BreakUnsupported, PortVanished
from .stamps import chunk_frames

READ_POLL = 0.02  # s: the reader thread's read timeout, so it notices close() promptly
SPIN = 0.0008  # s: the last stretch of a timed wait is polled, not slept (sleep overshoots)


def precise_sleep_until(clock_now, target: float) -> None:
    """Sleep until ``clock_now() >= target``: a coarse sleep, then short yields."""
    while True:
        left = target - clock_now()
        if left <= 0:
            return
        time.sleep(left - SPIN if left > 2 * SPIN else 0)


class SerialLink(Link):
    """The tool's end of a real bus reached through ``port`` (an open pyserial port)."""

    def __init__(
        self,
        port: serial.SerialBase,
        info: LinkInfo,
        breaker: BreakMaker | None,
        *,
        name: str = "",
    ) -> None:
        self.port = port
        self.info = info
        self.name = name or str(port.port)
        self.transcript = Transcript()
        self._breaker = breaker
        self._t0 = time.perf_counter_ns()
        self._cond = threading.Condition()
        self._rx: deque[Event] = deque()  # DUT characters not yet returned by receive()
        self._rx_floor = 0.0  # end of the last received frame: the next cannot start before
        self._tx_free = 0.0  # end of the tool's last frame on the wire
        self._failure: BaseException | None = None
        self._closing = threading.Event()
        self._reader = threading.Thread(target=self._read_loop, name=f"sdi12-rx {self.name}")
        self._reader.daemon = True
        self._reader.start()

    # -- clock ---------------------------------------------------------------------------------
    def now(self) -> float:
        return (time.perf_counter_ns() - self._t0) / 1e9

    def _stamp(self, ns: int) -> float:
        return (ns - self._t0) / 1e9

    # -- reader thread -------------------------------------------------------------------------
    def _read_loop(self) -> None:
        port = self.port
        while not self._closing.is_set():
            try:
                data = port.read(max(1, port.in_waiting))
            except Exception as exc:  # pyserial raises SerialException, OSError, TypeError...
                if not self._closing.is_set():
                    with self._cond:
                        self._failure = exc
                        self._cond.notify_all()
                return
            arrival = time.perf_counter_ns()
            if data:
                self._arrived(data, self._stamp(arrival))

    def _arrived(self, data: bytes, arrival: float) -> None:
        with self._cond:
            frames = chunk_frames(len(data), arrival, self._rx_floor)
            for byte, (start, end) in zip(data, frames, strict=True):
                event = Event(
                    EventKind.CHAR,
                    DUT,
                    start,
                    end,
                    wire=byte,
                    uncertainty=self.info.timing_uncertainty,
                )
                self.transcript.add(event)
                self._rx.append(event)
            self._rx_floor = frames[-1][1]
            self._cond.notify_all()

    def _check(self) -> None:
        """Raise if the port failed (called with or without the lock; reads one attribute)."""
        failure = self._failure
        if failure is not None:
            raise PortVanished(
                f"the port {self.name} failed during the run ({type(failure).__name__}: "
                f"{failure}). Check the cable, the adapter's power, or the server at the other "
                "end; the report up to this point was kept."
            ) from failure

    # -- tool side -----------------------------------------------------------------------------
    def wait_until(self, time_s: float) -> None:
        self._check()
        precise_sleep_until(self.now, time_s)

    def write(self, wire: bytes, gap: float = 0.0) -> list[Event]:
        self._check()
        events: list[Event] = []
        if not wire:
            return events
        if gap <= 0:
            start = max(self.now(), self._tx_free)
            self._port_write(wire)
            for k, byte in enumerate(wire):
                s = start + k * CHAR_TIME
                events.append(self._tool_char(byte, s))
        else:
            for byte in wire:
                precise_sleep_until(self.now, self._tx_free + (gap if events else 0.0))
                start = max(self.now(), self._tx_free)
                self._port_write(bytes([byte]))
                events.append(self._tool_char(byte, start))
        self.wait_until(events[-1].end)
        return events

    def _tool_char(self, byte: int, start: float) -> Event:
        event = Event(
            EventKind.CHAR,
            TOOL,
            start,
            start + CHAR_TIME,
            wire=byte,
            uncertainty=self.info.timing_uncertainty,
        )
        with self._cond:
            self.transcript.add(event)
        self._tx_free = event.end
        return event

    def _port_write(self, data: bytes) -> None:
        try:
            self.port.write(data)
        except Exception as exc:
            self._failure = self._failure or exc
            self._check()

    def send_break(self, duration: float) -> Event:
        self._check()
        if self._breaker is None or not self.info.can_break:
            note = f"no break: a {self.info.kind} link cannot hold the line spacing"
            with self._cond:
                self.transcript.note(self.now(), note)
            raise BreakUnsupported(note)
        precise_sleep_until(self.now, self._tx_free)
        try:
            start = self.now()
            self._breaker.on()
            precise_sleep_until(self.now, start + duration)
            end = self.now()
            self._breaker.off()
        except Exception as exc:
            self._failure = self._failure or exc
            self._check()
            raise
        text = (
            f"break asked {duration * 1e3:.2f} ms, held {(end - start) * 1e3:.2f} ms "
            f"({self._breaker.method})"
        )
        event = Event(
            EventKind.BREAK,
            TOOL,
            start,
            end,
            text=text,
            uncertainty=self.info.timing_uncertainty,
        )
        with self._cond:
            self.transcript.add(event)
        self._tx_free = end
        return event

    def receive(
        self, deadline: float, until: StopCondition | None = None, idle: float | None = None
    ) -> list[Event]:
        """As :meth:`Link.receive`. A byte is seen only after its stop bit (and the link's
        latency), so a read whose limit lies ahead waits one frame plus the declared
        uncertainty past it for characters that started in time; one whose limit has
        already passed returns what is queued at once."""
        got: list[Event] = []
        grace = CHAR_TIME + self.info.timing_uncertainty
        waits = deadline > self.now()
        with self._cond:
            while True:
                limit = deadline
                if idle is not None and got:
                    limit = min(limit, got[-1].end + idle)
                while self._rx and self._rx[0].start < limit:
                    got.append(self._rx.popleft())
                    if until is not None and until(got):
                        return got
                    if idle is not None:
                        limit = min(deadline, got[-1].end + idle)
                later_char_queued = bool(self._rx)  # it started after the limit: we are done
                now = self.now()
                if later_char_queued or not waits or now >= limit + grace:
                    return got
                self._check()
                self._cond.wait(min(limit + grace - now, 0.1))

    def close(self) -> None:
        self._closing.set()
        with contextlib.suppress(Exception):  # closing a vanished port must not mask the result
            self.port.close()
        self._reader.join(timeout=1.0)
