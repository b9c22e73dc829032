"""The tool's own host stalling is measured by the link and said in the transcript
(conformance.links.host_stall, truth26).

truth25 paused the tool's process (SIGSTOP 80-200 ms every 0.3-0.9 s) while it judged a clean
emulator over RFC 2217: reads cut by the pause, the late burst's stamps showing a gap the wire
never had, 6 FAIL + 1 WARN. A paused process's reader thread comes back from its read much
later than the read's timeout allows; the fake port here plays that: one read returns
``stall`` s late with what arrived meanwhile."""

from __future__ import annotations

import threading
import time

import pytest

from conformance.links import host_stall
from conformance.links.base import LinkInfo
from conformance.links.echo import EchoMode
from conformance.links.serial_link import READ_POLL, SerialLink
from conformance.transcript import DUT, Event, EventKind, to_wire_7e1


class _PausedPort:
    """A pyserial-like port whose reads time out after ``READ_POLL`` as a port's do, except
    one: after ``release`` is set it holds the reader for ``stall`` s (the process paused),
    then hands back ``burst``, the bytes that arrived meanwhile, all at once."""

    def __init__(self, burst: bytes, stall: float) -> None:
        self.port = "paused://"
        self.in_waiting = 0
        self.release = threading.Event()
        self.served = threading.Event()
        self._burst = burst
        self._stall = stall

    def read(self, size: int = 1) -> bytes:
        if self.release.is_set() and not self.served.is_set():
            time.sleep(READ_POLL + self._stall)
            self.served.set()
            return self._burst
        time.sleep(READ_POLL)
        return b""

    def write(self, data: bytes) -> int:
        return len(data)

    def close(self) -> None:
        pass


def _run(stall: float) -> SerialLink:
    burst = bytes(to_wire_7e1(ord(c)) for c in "0+1.5\r\n")
    port = _PausedPort(burst, stall)
    info = LinkInfo(kind="serial", can_break=False, timing_uncertainty=2.5e-3)
    link = SerialLink(port, info, None, echo=EchoMode.OFF)  # type: ignore[arg-type]
    try:
        time.sleep(3 * READ_POLL)  # a few reads on time first
        port.release.set()
        assert port.served.wait(2.0)
        link.wait(3 * READ_POLL)
    finally:
        link.close()
    return link


def _longest(link: SerialLink) -> float:
    """The longest host stall (ms) the link noted; 0.0 where none."""
    return max((s.ms for s in host_stall.stalls(link.transcript.events)), default=0.0)


def _notes(link: SerialLink) -> list[Event]:
    return [e for e in link.transcript.events if e.kind is EventKind.NOTE]


@pytest.mark.realtime  # the reader's read returns late by wall-clock time
def test_a_reader_back_late_by_a_pause_notes_the_host_stall_after_its_burst():
    link = _run(stall=0.12)
    stalls = [e for e in _notes(link) if e.text.startswith(host_stall.HOST_STALL_NOTE)]
    assert stalls, _notes(link)
    chars = [e for e in link.transcript.events if e.origin == DUT and e.kind is EventKind.CHAR]
    assert len(chars) == 7
    # said after the characters it held back, where the last of them ended
    events = link.transcript.events
    assert events.index(stalls[0]) > events.index(chars[-1])
    assert stalls[0].start == pytest.approx(chars[-1].end, abs=1e-9)
    # the reader may be scheduled late besides: at least the pause, not much more
    assert 110 <= _longest(link) < 400


@pytest.mark.realtime
def test_reads_on_time_note_no_pause_s_stall():
    """A burst handed back without a pause is no stall of the host (the stamps' business,
    :mod:`conformance.links.meter`): no note of one anywhere near the other test's pause."""
    link = _run(stall=0.0)
    assert _longest(link) < 100


def test_the_stalls_are_read_back_from_the_notes_alone():
    events = [
        Event(EventKind.NOTE, "tool", 1.0, 1.0, text=host_stall.note_text(0.0831)),
        Event(EventKind.NOTE, "tool", 2.0, 2.0, text="something else: 900.0 ms"),
        Event(EventKind.NOTE, "tool", 3.0, 3.0, text=host_stall.note_text(0.1502)),
    ]
    found = host_stall.stalls(events)
    assert [s.ms for s in found] == [pytest.approx(83.1), pytest.approx(150.2)]
    # each reaches back over its length and the read's reach, to its note
    assert found[1].end == 3.0 + host_stall.AFTER  # and on past it (truth30)
    assert found[1].start == pytest.approx(3.0 - 0.1502 - host_stall.REACH)
    assert found[1].overlaps(2.8, 2.9) and not found[1].overlaps(2.0, 2.5)
    assert host_stall.stalled_over(found, 2.8, 2.9) is found[1]
    assert host_stall.stalls(events[1:2]) == []


@pytest.mark.realtime  # the reader is held up by wall-clock time
def test_a_stimulus_waits_for_an_overdue_reader_to_note_its_stall():
    """After a pause every thread resumes together: the engine may hand over a record its
    read cut before the reader has said the host stalled (truth27). ``reader_caught_up``
    waits for an overdue reader (here held 150 ms in its read), so the note is in the
    transcript when the stimulus's records are marked from it; a reader on time costs
    nothing."""
    burst = bytes(to_wire_7e1(ord(c)) for c in "0+1.5\r\n")
    port = _PausedPort(burst, 0.15)
    info = LinkInfo(kind="serial", can_break=False, timing_uncertainty=2.5e-3)
    link = SerialLink(port, info, None, echo=EchoMode.OFF)  # type: ignore[arg-type]
    try:
        time.sleep(3 * READ_POLL)
        begun = time.perf_counter()
        link.reader_caught_up()  # on time: at once
        assert time.perf_counter() - begun < 0.01
        port.release.set()
        time.sleep(READ_POLL + 0.08)  # the reader is overdue now, its note not written
        assert not host_stall.stalls(link.transcript.events)
        link.reader_caught_up()
        assert host_stall.stalls(link.transcript.events)
    finally:
        link.close()
