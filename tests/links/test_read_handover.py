"""A read that runs to its limit ends once nothing the reader thread has yet to hand over can
be stamped as started before it, not a declared floor later (issue 22, usb13).

The link stamps each byte itself, when the port's read returns it, and places the first of a
chunk of k bytes k frames before that stamp (:func:`conformance.links.stamps.chunk_frames`).
So with the reader thread blocked in its read a frame more than the widest chunk's frames
past the limit, every byte still to come is stamped later and starts after the limit (in
chunks up to one byte wider than any seen, what the whole grace covers where its floor is a
frame or less): the declared floor that :meth:`SerialLink.read_grace` adds (for a stamp
taken but not handed over yet) is waited out only while the reader is handing a read over.
Where that floor is longer than a frame (a USB serial device without low latency: 16 ms)
every read that ran to its deadline (a command nobody answered, a wait for a service
request, a window for silence) waited the rest. With a kernel tape the stamps are older than
the read that returns them, and the floor stays."""

from __future__ import annotations

import threading
import time

import pytest

from conformance.links.base import LinkInfo
from conformance.links.echo import EchoMode
from conformance.links.serial_link import READ_POLL, SerialLink
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, EventKind, to_wire_7e1

#: a declared floor far above a frame, so waiting it out shows on a busy machine
FLOOR = 40e-3


class _TimedPort:
    """A pyserial-like port: reads block up to ``READ_POLL``; a byte set with :meth:`send_at`
    is returned by the first read once the link's clock reaches that time."""

    def __init__(self, *, kernel_stamps: object = None) -> None:
        self.port = "timed://"
        self.in_waiting = 0
        self.clock = time.perf_counter
        self._due: tuple[float, bytes] | None = None
        self._lock = threading.Lock()
        if kernel_stamps is not None:
            self.kernel_stamps = kernel_stamps

    def send_at(self, at: float, data: bytes) -> None:
        with self._lock:
            self._due = (at, data)

    def read(self, size: int = 1) -> bytes:
        until = self.clock() + READ_POLL
        while self.clock() < until:
            with self._lock:
                due = self._due
                if due is not None and self.clock() >= due[0]:
                    self._due = None
                    return due[1]
            time.sleep(0.2e-3)
        return b""

    def write(self, data: bytes) -> int:
        return len(data)

    def close(self) -> None:
        pass


def _open(port: _TimedPort) -> SerialLink:
    info = LinkInfo(kind="serial", can_break=False, timing_uncertainty=FLOOR)
    link = SerialLink(port, info, None, echo=EchoMode.OFF)  # type: ignore[arg-type]
    port.clock = lambda: link.now()
    time.sleep(2 * READ_POLL)  # the reader is in its reads
    return link


def _past(link: SerialLink, deadline: float) -> float:
    link.receive(deadline)
    return link.now() - deadline


def test_an_idle_read_does_not_wait_out_the_declared_floor():
    link = _open(_TimedPort())
    try:
        assert link.read_grace() == pytest.approx(CHAR_TIME + FLOOR)
        overrun = min(_past(link, link.now() + 20e-3) for _ in range(3))
    finally:
        link.close()
    assert overrun >= 2 * CHAR_TIME  # one byte wider than the widest chunk seen (one)
    assert overrun < CHAR_TIME + FLOOR / 2  # the floor (40 ms) was not waited out


def test_with_a_kernel_tape_the_floor_stays():
    link = _open(_TimedPort(kernel_stamps=object()))  # never asked: nothing arrives
    try:
        overrun = _past(link, link.now() + 20e-3)
    finally:
        link.close()
    assert overrun >= CHAR_TIME + FLOOR - 1e-3


@pytest.mark.parametrize("tape", [None, object()])
def test_a_floor_under_a_frame_still_ends_the_read_at_its_grace(tape):
    """Where the declared floor is less than a frame (2 ms: a low-latency serial device) the
    whole grace ends sooner than the frames the hand-over waits for: the read ends at the
    grace, with or without a kernel tape (a first version slept to the frames first: 3.3 ms
    more on every read that ran to its deadline over RFC 2217)."""
    port = _TimedPort(kernel_stamps=tape)
    info = LinkInfo(kind="serial", can_break=False, timing_uncertainty=2e-3)
    link = SerialLink(port, info, None, echo=EchoMode.OFF)  # type: ignore[arg-type]
    port.clock = lambda: link.now()
    time.sleep(2 * READ_POLL)
    try:
        grace = link.read_grace()
        overrun = min(_past(link, link.now() + 20e-3) for _ in range(3))
    finally:
        link.close()
    assert grace == pytest.approx(CHAR_TIME + 2e-3)
    assert grace - 1e-4 <= overrun < (grace + 2 * CHAR_TIME) / 2


@pytest.mark.parametrize("count", [1, 2])
@pytest.mark.parametrize("handover", [0.0, 3e-3, 12e-3])
@pytest.mark.parametrize("early", [1e-3, 4e-3])
def test_every_character_stamped_before_the_limit_is_taken(count, handover, early):
    """Bytes that arrive together just under their frames past the limit start before it
    and must be taken (``count`` 2: one wider than any chunk seen before), however long the
    reader thread takes to hand them over (``handover``, the time between the read's stamp
    and the lock): the read waits while the reader is not back in its read. What the read
    left is only what its stamps put after the limit."""
    port = _TimedPort()
    link = _open(port)
    arrived = link._arrived

    def slow(data: bytes, arrival: float, stamps: list[float] | None = None) -> None:
        time.sleep(handover)
        arrived(data, arrival, stamps)

    link._arrived = slow  # type: ignore[method-assign]
    try:
        limit = link.now() + 20e-3
        data = bytes(to_wire_7e1(ord(c)) for c in "0\r"[:count])
        port.send_at(limit + count * CHAR_TIME - early, data)
        got = link.receive(limit)
        time.sleep(2 * READ_POLL + handover)  # whatever was still coming is in by now
    finally:
        link.close()
    chars = [e for e in link.transcript.events if e.kind is EventKind.CHAR and e.origin == DUT]
    assert len(chars) == count
    before = [e for e in chars if e.start < limit]
    assert got == before
