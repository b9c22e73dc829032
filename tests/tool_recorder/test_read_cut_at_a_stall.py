"""A reply the engine's read cut at a delivery stall is mended from its rest, which comes late
with stamps inside the read's windows (conformance.tool_recorder.cut_read, truth25).

truth23 saw it behind ``emulate --echo --jitter 2`` on a loaded host: 0IHB_010!'s record was
judged as ``'0,XB, ,sa'``, 9 of its 32 characters, and R-6.2-02 FAILed "does not end with ';'"
for wrong-crc, whose only fault is the CRC; the transcript held the reply whole. The real-time
test plays that on a :class:`SerialLink` (its reader thread and arrival stamps) over a port
whose far end is a half-duplex sensor and whose delivery stalls once; the others check the
rule on hand-made events."""

from __future__ import annotations

import queue
import threading
import time

import pytest

from conformance.judges.metadata import records
from conformance.links.base import LinkInfo
from conformance.links.echo import EchoMode
from conformance.links.host_stall import HOST_STALL_NOTE
from conformance.links.serial_link import SerialLink
from conformance.protocol.crc import ascii_crc
from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder import cut_read
from conformance.tool_recorder.engine import ToolRecorder, framing_for
from conformance.tool_recorder.policy import Policy
from conformance.tool_recorder.records import CONTENTION, IDLE, OK, Attempt
from conformance.transcript import DUT, Event, EventKind, Transcript, to_wire_7e1
from conformance.verdicts import Verdict
from tests.conftest import BUSY
from tests.support.hand_events import chars

BODY = "0,RH,%,relative humidity;"
RECORD = BODY + ascii_crc(BODY) + "\r\n"  # 32 characters, as 0IHB_010!'s was
SHOWN = 9  # characters delivered before the stall ('0,RH,%,re')
REPLY_DELAY = 9e-3
#: a delivery (or the link's reader) later than this (s) is the host's, not the port's stall:
#: the read's windows are then moved by the host and the test cannot say what it checks
LATE = 0.01


class _StallingPort:
    """A pyserial-like port: the far end a half-duplex sensor that answers ``replies``'
    commands ``REPLY_DELAY`` after their last stop bit and hears nothing while it talks; each
    byte reaches the host at its stop bit, except that once, after the ``SHOWN``-th byte of
    the first reply, delivery stalls for ``stall`` s and what ended meanwhile comes at once."""

    def __init__(self, replies: dict[str, str], stall: float) -> None:
        self.port = "stall://"
        self._replies = replies
        self._stall = stall
        self._stalled = False
        self._chunks: queue.Queue[bytes] = queue.Queue()
        self._busy_until = 0.0  # the sensor's last stop bit on the line
        self._timers: list[threading.Thread] = []
        self.late = 0.0  # the most (s) a delivery came after its schedule: the host's doing

    @property
    def in_waiting(self) -> int:
        return 0

    def read(self, size: int = 1) -> bytes:
        try:
            return self._chunks.get(timeout=0.02)
        except queue.Empty:
            return b""

    def write(self, data: bytes) -> int:
        now = time.perf_counter()
        end = now + len(data) * CHAR_TIME
        text = bytes(b & 0x7F for b in data).decode("ascii")
        reply = self._replies.get(text)
        if reply is None or now < self._busy_until:
            return len(data)  # not one of its commands, or it was talking: not heard
        wires = bytes(to_wire_7e1(ord(c)) for c in reply)
        ends = [end + REPLY_DELAY + (k + 1) * CHAR_TIME for k in range(len(wires))]
        self._busy_until = ends[-1]
        arrivals = list(ends)
        if not self._stalled:
            self._stalled = True
            resume = ends[SHOWN - 1] + self._stall
            arrivals[SHOWN:] = [max(at, resume) for at in ends[SHOWN:]]
        thread = threading.Thread(target=self._deliver, args=(wires, arrivals), daemon=True)
        self._timers.append(thread)
        thread.start()
        return len(data)

    def _deliver(self, wires: bytes, arrivals: list[float]) -> None:
        k = 0
        while k < len(wires):
            at = arrivals[k]
            n = 1
            while k + n < len(wires) and arrivals[k + n] == at:
                n += 1
            while time.perf_counter() < at:
                time.sleep(max(0.0, min(at - time.perf_counter(), 0.001)))
            self._chunks.put(wires[k : k + n])
            self.late = max(self.late, time.perf_counter() - at)
            k += n

    def close(self) -> None:
        for thread in self._timers:
            thread.join(timeout=1.0)


def _engine(stall: float) -> ToolRecorder:
    port = _StallingPort({"0IHB_010!": RECORD}, stall)
    info = LinkInfo(kind="serial", can_break=False, timing_uncertainty=2.5e-3)
    link = SerialLink(port, info, None, echo=EchoMode.OFF)  # type: ignore[arg-type]
    return ToolRecorder(link, Policy(sequences=1, retries_per_sequence=0))


@pytest.mark.realtime  # the stall and the read's windows are wall-clock times
def test_a_record_cut_at_a_delivery_stall_is_judged_whole():
    """The read of 0IHB_010!'s record ends 50 ms (and the latency bound) after its 9th
    character; the rest comes 100 ms after it, back to back behind it by its stamps, while
    the next command (0I!, which the talking sensor does not hear) is going out. The record
    is mended, whole and valid, and R-6.2-02 PASSes; base-s64 judged '0,RH,%,re' and FAILed
    it. The rest ran on into 0I!: that try stays met (contention), as it was."""
    engine = _engine(stall=0.1)
    try:
        ex = engine.transact("0IHB_010!")
        nxt = engine.transact("0I!")
        engine.link.wait(0.2)  # the rest of the record's characters into the transcript
    finally:
        engine.link.close()
    port = engine.link.port
    events = engine.link.transcript.events
    stalled = [e for e in events if e.kind is EventKind.NOTE and HOST_STALL_NOTE in e.text]
    if port.late > LATE or stalled:  # CI saw '' for the reply at a load of 4 workers on 2 cores
        pytest.skip(
            f"{BUSY}: the port's deliveries came up to {port.late * 1e3:.0f} ms after their "
            f"schedule; host stalls noted: {len(stalled)}"
        )
    transcript = "".join(
        chr(e.char7)
        for e in engine.link.transcript.events
        if e.origin == DUT and e.kind is EventKind.CHAR
    )
    assert transcript == RECORD  # the wire, as the link stamped it
    assert ex.reply_text == RECORD
    assert ex.attempts[0].reason == OK
    assert nxt.attempts[0].reason.startswith(CONTENTION)
    notes = [e.text for e in engine.link.transcript.events if e.kind is EventKind.NOTE]
    assert f"{cut_read.STALL_NOTE}{len(RECORD) - SHOWN}" in notes
    findings = {f.requirement: f for f in records([(ex, True, True)], ("R-6.2-02",))}
    assert findings["R-6.2-02"].verdict is Verdict.PASS


def _record(gap: float = 0.0) -> list[Event]:
    """RECORD's characters from t = 1 s, back to back but for ``gap`` s of marking after
    the ``SHOWN``-th."""
    head = chars(DUT, RECORD[:SHOWN], 1.0)
    return head + chars(DUT, RECORD[SHOWN:], head[-1].end + gap)


class _Quiet:
    """A link that delivers nothing more (the rule's tests hand it the characters)."""

    def __init__(self, virtual_time: bool = False) -> None:
        self.info = LinkInfo(kind="serial", virtual_time=virtual_time)
        self.transcript = Transcript()

    def receive(self, deadline, until=None, idle=None) -> list[Event]:
        return []


def _cut(reply: list[Event]) -> cut_read.CutRead:
    attempt = Attempt(None, [], reply, IDLE, reply[-1].end + 0.06)
    framing = framing_for(Policy(), False, False)
    made = cut_read.cut(attempt, framing, _Quiet(), judge=lambda chars, text: OK)
    assert made is not None
    return made


def test_the_rest_inside_the_windows_is_taken_and_the_reply_judged_again():
    whole = _record()
    cut = _cut(whole[:SHOWN])
    assert cut.mend(whole[SHOWN:]) == []
    assert cut.attempt.reply_events == whole
    assert cut.attempt.reason == OK


def test_a_reply_that_paused_past_the_idle_window_stays_cut():
    """The rule is the read's own: a sensor that really stopped for 60 ms mid-reply (more
    than the 50 ms idle) is not joined to what it sent after, nor to a later reply."""
    paused = _record(0.06)
    cut = _cut(paused[:SHOWN])
    rest = paused[SHOWN:]
    assert cut.mend(rest) is rest
    assert cut.attempt.reason == IDLE and len(cut.attempt.reply_events) == SHOWN


def test_what_follows_the_rest_stays_the_next_tries():
    """Only the reply's rest, up to its CR LF, is taken; a character after it (the next
    reply's, a stray) stays where it was read."""
    whole = _record() + chars(DUT, "0", _record()[-1].end)
    cut = _cut(whole[:SHOWN])
    assert cut.mend(whole[SHOWN:]) == whole[-1:]


def test_the_rest_that_ran_into_the_next_try_keeps_that_try_met():
    whole = _record()
    cut = _cut(whole[:SHOWN])
    rest = whole[SHOWN:]
    command = Event(EventKind.CHAR, "tool", rest[3].start, rest[3].end, wire=0x30)
    assert cut.mend_met(rest, command) is rest  # the try met it: judged as met
    assert cut.attempt.reply_events == whole  # and the reply is whole all the same
    before = Event(EventKind.CHAR, "tool", whole[-1].end + 0.02, whole[-1].end + 0.03, wire=0x30)
    again = _cut(whole[:SHOWN])
    assert again.mend_met(rest, before) == []


def test_a_virtual_clock_is_never_mended():
    reply = chars(DUT, RECORD[:SHOWN], 1.0)
    attempt = Attempt(None, [], reply, IDLE, reply[-1].end + 0.06)
    framing = framing_for(Policy(), False, False)
    assert cut_read.cut(attempt, framing, _Quiet(True), judge=lambda c, t: OK) is None
