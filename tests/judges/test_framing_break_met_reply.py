"""A reply the tool's break met while it was still coming is no framing evidence
(R-4.2-03), whatever gap the stamps show before the break (truth22).

slow-wake behind ``emulate --echo --jitter 2`` with two CPU burners beside: the reply to
0IHA_107! reached the tool as '0,X', 74 ms of nothing (a delivery stall), then the rest in a
burst. The tool took the reply as ended and retried after a break, which met 'H,mV,chann'
on the line (the engine NOTEd the collision); the view put those characters in no segment
(heard after the break, before any command character), and R-4.2-03 FAILed "reply '0,X'
does not end with CR LF". The view now marks such a reply cut by the break
(``Transmission.met_by``, ``Segment.met_by``) and ``wire.Framing`` leaves it unjudged, as it
does a reply the next transmission's contention met. Hand-typed wire events; the first test
fails on base-s61.
"""

from __future__ import annotations

from conformance.judges import wire
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict
from conformance.view.runs import segments
from tests.support.hand_events import chars

U = 2e-3  # the run's stamps (echo, 0..2 ms jitter)


def _stalled(rest_at: float | None) -> list[Event]:
    """0I!, '0,X' 9 ms after it, then 74 ms of nothing and the tool's break; the rest of the
    reply heard ``rest_at`` s after the break began (None: never); then 0I! and a whole
    reply."""
    events = list(cmd := chars(TOOL, "0I!", 0.0, uncertainty=U))
    events += (head := chars(DUT, "0,X", cmd[-1].end + 9e-3, uncertainty=U))
    at = head[-1].end + 0.074
    events.append(Event(EventKind.BREAK, TOOL, at, at + 0.031, uncertainty=U))
    if rest_at is not None:
        events += chars(DUT, "H,mV", at + rest_at, uncertainty=U)
    events += (cmd := chars(TOOL, "0I!", at + 0.056, uncertainty=U))
    events += chars(DUT, "013CONFORM EMU001\r\n", cmd[-1].end + 9e-3, uncertainty=U)
    return sorted(events, key=lambda e: e.start)


def _framing(events: list[Event]) -> dict[str, Verdict]:
    return {f.requirement: f.verdict for f in wire.judge_framing(segments(events), U, own="0")}


def test_a_reply_the_break_met_still_coming_is_not_judged() -> None:
    found = _framing(_stalled(rest_at=0.016))
    assert found["R-4.2-03"] is Verdict.PASS, found  # FAIL "does not end with CR LF" before
    assert segments(_stalled(rest_at=0.016))[0].met_by is not None


def test_a_reply_cut_short_with_nothing_after_it_still_fails() -> None:
    """The same '0,X' with nothing after it: the sensor's own short reply, the FAIL stands."""
    found = _framing(_stalled(rest_at=None))
    assert found["R-4.2-03"] is Verdict.FAIL, found


def test_the_window_fold_agrees_with_the_whole() -> None:
    segs = segments(_stalled(rest_at=0.016))
    fold = wire.Framing(U, "0")
    for seg in segs:
        fold.add([seg])
    assert fold.findings() == wire.judge_framing(segs, U, own="0")
