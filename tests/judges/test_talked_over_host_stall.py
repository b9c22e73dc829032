"""A transmission the tool sent right after a stall of its own host, into what the stall
still held back, is read through that stall (truth30; ``host_stall.AFTER``).

The clean emulator behind RFC 2217, the tool paused 80-200 ms every 0.3-0.9 s: a 0D0!
reply was cut by a 111 ms stall; the reader's first turn after it came back empty, the
engine saw a quiet line and sent its retry's break 0.4 ms after the stall's NOTE, into the
rest of the reply; the view read the reply to the retry as the text the break talked over
and its tail, after a 3.4 ms gap, as a line of its own: R-4.3-01 FAILed "later, after
0D0!: reply '5<CR><LF>' starts with '5'" (base-s67). Hand-typed here after that run."""

from __future__ import annotations

from conformance.judges import wire
from conformance.judges.timing import StampUncertainty
from conformance.links import host_stall
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict
from conformance.view.runs import segments
from tests.support.hand_events import chars

U = 0.74e-3  # the run's measured stamps
REPLY = "0-5.00-3.75-2.50-1.25+0.00+1.25+2.50+3.75+5.00+6.25+7.50+8.75+10.00+11.25\r\n"
WHY = "the tool's host stalled 111 ms during this read"


def _talked_over(noted: bool, after: float) -> list[Event]:
    """0D0!, its reply cut after 13 characters by a 110.8 ms stall (NOTE ``noted``), the
    rest arriving late and over the retry's break sent ``after`` s past the NOTE, then the
    reply to the retry with a 3.4 ms gap before its last three characters."""
    events = [Event(EventKind.BREAK, TOOL, 0.0, 0.013, uncertainty=U)]
    cmd = chars(TOOL, "0D0!", 0.0215, uncertainty=U)
    head = chars(DUT, REPLY[:13], cmd[-1].end + 0.009, uncertainty=U)
    note_at = head[-1].end + 0.131
    events += cmd + head + chars(DUT, REPLY[13:16], head[-1].end, uncertainty=U)
    if noted:
        text = host_stall.note_text(0.1108)
        events.append(Event(EventKind.NOTE, TOOL, note_at, note_at, text=text))
    events += chars(DUT, REPLY[16:30], note_at - 0.0143, uncertainty=U)
    brk = Event(EventKind.BREAK, TOOL, note_at + after, note_at + after + 0.014, uncertainty=U)
    retry = chars(TOOL, "0D0!", brk.end + 0.0211, uncertainty=U)
    body = chars(DUT, REPLY[:-3], retry[-1].end, uncertainty=U)
    tail = chars(DUT, REPLY[-3:], body[-1].end + 0.0034, uncertainty=U)
    return sorted([*events, brk, *retry, *body, *tail], key=lambda e: e.start)


def _address_rule(events: list[Event]):
    stalls = host_stall.stalls(events)
    found = wire.judge_framing(segments(events), StampUncertainty(U), own="0", stalls=stalls)
    return {f.requirement: f for f in found}["R-4.3-01"]


def test_a_retry_sent_just_after_a_stall_is_read_through_it():
    found = _address_rule(_talked_over(True, 0.0004))
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "starts with '5'" in found.detail and WHY in found.detail


def test_the_same_reading_outside_any_stall_fails():
    assert _address_rule(_talked_over(False, 0.0004)).verdict is Verdict.FAIL


def test_a_retry_sent_past_the_stall_s_reach_is_judged_as_ever():
    """40 ms after the NOTE (past AFTER) the burst has arrived: a retry sent then is the
    tool's own doing, read as ever (the same reading FAILs)."""
    assert _address_rule(_talked_over(True, 0.04)).verdict is Verdict.FAIL


def test_a_stimulus_begun_just_after_a_note_reads_it():
    """The live marks read the NOTEs from the stimulus's first event on, and those just
    before it (within AFTER): a stimulus sent into the burst a stall still held back."""
    note = Event(EventKind.NOTE, TOOL, 1.0, 1.0, text=host_stall.note_text(0.1))
    cmd = chars(TOOL, "0!", 1.01, uncertainty=U)
    assert [s.ms for s in host_stall.stalls_since([note, *cmd], 1)] == [100.0]
    late = chars(TOOL, "0!", 1.1, uncertainty=U)
    assert host_stall.stalls_since([note, *late], 1) == []
