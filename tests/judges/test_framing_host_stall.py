"""A reply the tool's own host stalled over is no framing evidence against the sensor
(R-4.1-02, R-4.2-02, R-4.2-03, R-4.3-01): its split into a reply and later lines follows
stamps the host moved
(conformance.links.host_stall, truth26).

Behind RFC 2217 with the tool's process paused 80-200 ms every 0.3-0.9 s, a clean emulator's
whole-run framing FAILed "reply to 0D0! '0-5.00...+8' does not end in CR LF" and "later,
after 0D1!: reply '12.250+12.375...' starts with '1', not the address '0'": the read was
cut by the pause and the rest came in a burst whose stamps show a gap the wire never had.
Here the transcript is that shape: 0D0!'s reply, a gap, its rest, and the link's NOTE of the
stall where its reader came back."""

from __future__ import annotations

from conformance.judges import wire
from conformance.links import host_stall
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict
from conformance.view.runs import segments
from tests.support.hand_events import chars

U = 5e-3
REPLY = "0+1.50+2.25+3.75\r\n"
SHOWN = 8


def _cut_reply(stall_ms: float | None) -> list[Event]:
    """break, 0D0!, the reply's first ``SHOWN`` characters; the engine's read ends there
    (the pause) and it sends 0D0! again; the rest comes in a burst after that retry, and
    (``stall_ms``) the link's NOTE where its reader came back, after the burst."""
    events = [Event(EventKind.BREAK, TOOL, 0.0, 0.013, uncertainty=U)]
    events += (cmd := chars(TOOL, "0D0!", 0.022, uncertainty=U))
    events += (head := chars(DUT, REPLY[:SHOWN], cmd[-1].end + 9e-3, uncertainty=U))
    events += (retry := chars(TOOL, "0D0!", head[-1].end + 0.06, uncertainty=U))
    events += (rest := chars(DUT, REPLY[SHOWN:], retry[-1].end + 0.02, uncertainty=U))
    if stall_ms is not None:
        note = host_stall.note_text(stall_ms / 1e3)
        events.append(Event(EventKind.NOTE, TOOL, rest[-1].end, rest[-1].end, text=note))
    return events


def _framing(events: list[Event]) -> dict[str, wire.Finding]:
    stalls = host_stall.stalls(events)
    found = wire.judge_framing(segments(events), U, stalls=stalls)
    return {f.requirement: f for f in found}


def test_without_a_stall_the_cut_reply_fails_as_ever():
    """The judge's own rule: a reply that ended without CR LF before the next command,
    and a reply that does not begin with the address."""
    found = _framing(_cut_reply(None))
    assert found["R-4.2-03"].verdict is Verdict.FAIL
    assert found["R-4.3-01"].verdict is Verdict.FAIL


def test_a_reply_the_host_stalled_over_is_inconclusive_with_the_stall_named():
    found = _framing(_cut_reply(160.0))
    assert found["R-4.2-03"].verdict is Verdict.INCONCLUSIVE
    assert "the tool's host stalled 160 ms during this read" in found["R-4.2-03"].detail
    assert found["R-4.3-01"].verdict is Verdict.INCONCLUSIVE
    # what conforms is judged as ever
    assert found["R-4.1-02"].verdict is Verdict.PASS
    assert found["R-4.2-02"].verdict is Verdict.PASS


def test_a_stall_long_before_the_reply_changes_nothing():
    events = _cut_reply(None)
    early = Event(EventKind.NOTE, TOOL, -5.0, -5.0, text=host_stall.note_text(0.16))
    found = _framing([early, *events])
    assert found["R-4.2-03"].verdict is Verdict.FAIL
    assert found["R-4.3-01"].verdict is Verdict.FAIL


def test_bytes_after_a_reply_under_a_stall_are_no_parity_fail():
    """Bytes that came after a reply, split off by the stall as 'later' text (under 80-200 ms
    pauses the rest of an aDB7! packet: "2 character(s) with wrong parity, first 0x10" for a
    clean emulator): R-4.1-02 and R-4.2-02 FAIL without the stall's note, not with it."""
    events = [Event(EventKind.BREAK, TOOL, 0.0, 0.013, uncertainty=U)]
    events += (cmd := chars(TOOL, "0D0!", 0.022, uncertainty=U))
    events += (rep := chars(DUT, REPLY, cmd[-1].end + 9e-3, uncertainty=U))
    at = rep[-1].end + 0.2
    for k, byte in enumerate([0x10, 0x00, 0x08, 0x8D, 0x0A]):
        start = at + k * 8.33e-3
        events.append(Event(EventKind.CHAR, DUT, start, start + 8.33e-3, wire=byte, uncertainty=U))
    found = _framing(events)
    stalled = _framing([*events, _note_after(events[-1], 0.18)])
    assert found["R-4.1-02"].verdict is found["R-4.2-02"].verdict is Verdict.FAIL
    assert not any(f.verdict is Verdict.FAIL for f in stalled.values())
    assert stalled["R-4.1-02"].verdict is Verdict.INCONCLUSIVE


def _note_after(last: Event, stall: float) -> Event:
    note = host_stall.note_text(stall)
    return Event(EventKind.NOTE, TOOL, last.end, last.end, text=note)
