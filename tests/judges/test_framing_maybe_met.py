"""A sensor character the tool's next transmission may have met is no framing evidence
(R-4.1-02, R-4.2-03, R-4.3-01): the segment view's side of the ninth truth round's "maybe
collided" (be80803), where the engine NOTEs such a meeting and sets the attempt aside.

The view places a character by its start: one that began before the tool's break is the
previous segment's, never the next one's contention, even where it ended after the break
began, or within the stamps' uncertainty of it (±5 ms over RFC 2217, fault
stray-after-line-end: the break began 0.1..1.2 ms before the stray '#' ended 106 of 267
times). ``wire.Framing`` judged it as the sensor's text: a parity error the break may have
made FAILed R-4.1-02."""

from __future__ import annotations

import pytest

from conformance.judges import wire
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict
from conformance.view.runs import segments
from tests.support.hand_events import chars

U = 5e-3  # the stamps' uncertainty (RFC 2217)


def _two_polls(stray_end_after_break: float, u: float = U) -> list[Event]:
    """break, 0!, '0<CR><LF>', a stray '#' with a parity error 2 ms after the LF, and the
    tool's next break beginning ``stray_end_after_break`` before the '#' ended (negative:
    after), then 0! and its reply again."""
    events = [Event(EventKind.BREAK, TOOL, 0.0, 0.013, uncertainty=u)]
    events += (cmd := chars(TOOL, "0!", 0.022, uncertainty=u))
    events += (rep := chars(DUT, "0\r\n", cmd[-1].end + 9e-3, uncertainty=u))
    events += (stray := chars(DUT, "#", rep[-1].end + 2e-3, parity=False, uncertainty=u))
    at = stray[-1].end - stray_end_after_break
    events.append(Event(EventKind.BREAK, TOOL, at, at + 0.013, uncertainty=u))
    events += (cmd := chars(TOOL, "0!", at + 0.022, uncertainty=u))
    events += chars(DUT, "0\r\n", cmd[-1].end + 9e-3, uncertainty=u)
    return events


def _framing(events: list[Event], u: float = U) -> dict[str, Verdict]:
    return {f.requirement: f.verdict for f in wire.judge_framing(segments(events), u)}


@pytest.mark.parametrize("met_by", [1.0e-3, 0.1e-3, -4.0e-3])
def test_a_stray_the_next_break_maybe_met_is_no_framing_evidence(met_by):
    """The '#' ended 1 ms / 0.1 ms after the break began, or 4 ms before it (inside ±5 ms):
    R-4.1-02, R-4.2-03 and R-4.3-01 FAILed on it; the replies alone now, all PASS."""
    found = _framing(_two_polls(met_by))
    assert found == dict.fromkeys(("R-4.1-02", "R-4.2-02", "R-4.2-03", "R-4.3-01"), Verdict.PASS), (
        found
    )


def test_a_stray_clear_of_the_next_break_is_still_judged():
    """The same '#' 6 ms before the break (beyond ±5 ms), or met by nothing on exact stamps
    1 ms before it: the sensor's own text, the three FAILs stand."""
    for events, u in ((_two_polls(-6e-3), U), (_two_polls(-1e-3, u=0.0), 0.0)):
        found = _framing(events, u)
        for rid in ("R-4.1-02", "R-4.2-03", "R-4.3-01"):
            assert found[rid] is Verdict.FAIL, (rid, found)


def test_the_window_fold_agrees_with_the_whole():
    """``Framing.add`` a segment at a time gives the whole recording's findings."""
    segs = segments(_two_polls(1e-3))
    fold = wire.Framing(U)
    for seg in segs:
        fold.add([seg])
    assert fold.findings() == wire.judge_framing(segs, U)
