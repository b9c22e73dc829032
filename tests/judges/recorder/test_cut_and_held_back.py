"""Two false FAILs of the twenty-fourth outside round (docs/kit.md: frankyn/SDI-12-ATTiny84a,
an ATtiny84 logger that restarts at the first edge of every reply and breaks again over it).

- R-7.0-02 on a break the line held back: the logger began its 12.1 ms break inside a
  sensor's character; the line began it when the character ended and ended it where the
  logger did, 3.77 ms on the line. Its own length is not known: INCONCLUSIVE, as R-7.0-06
  is after such a break (tests/recorder/test_held_back_break.py).
- R-4.4-04 on a command the tool's job budget cut while it was being sent: '0XM=G', its
  'H!' still to come. Not a command the recorder ended: its '!' is not judged.
"""

from __future__ import annotations

from conformance.judges.recorder.breaks import judge_breaks
from conformance.judges.recorder.commands import judge_command_text
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import HELD_BACK, TOOL, Event, EventKind, to_wire_7e1
from conformance.verdicts import Verdict
from conformance.view.segments import read_view


def _command(text: str, at: float, brk: float = 0.0121, held: bool = False) -> list[Event]:
    """A break of ``brk`` s at ``at``, 8.4 ms of marking, then ``text`` back to back."""
    events = [Event(EventKind.BREAK, TOOL, at, at + brk, text=HELD_BACK if held else "")]
    t = at + brk + 0.0084
    for c in text:
        events.append(Event(EventKind.CHAR, TOOL, t, t + CHAR_TIME, to_wire_7e1(ord(c))))
        t += CHAR_TIME
    return events


def _rule(findings, rid: str):
    return next(f for f in findings if f.requirement == rid)


def test_a_held_back_break_short_of_12_ms_is_inconclusive_r_7_0_02():
    """FAILed 'break length: 3.77 ms' on the tree before."""
    events = _command("0M!", 0.0) + _command("0XM=GH!", 1.0, brk=0.00377, held=True)
    found = _rule(judge_breaks(read_view(events), 0.0), "R-7.0-02")
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "held back" in found.detail


def test_a_held_back_break_that_holds_still_passes_and_a_short_one_not_held_fails_r_7_0_02():
    held = _command("0M!", 0.0) + _command("0XM=GH!", 1.0, held=True)
    assert _rule(judge_breaks(read_view(held), 0.0), "R-7.0-02").verdict is Verdict.PASS
    short = held + _command("0M!", 2.0, brk=0.005)
    assert _rule(judge_breaks(read_view(short), 0.0), "R-7.0-02").verdict is Verdict.FAIL
    both = short + _command("0M!", 3.0, brk=0.00377, held=True)
    assert _rule(judge_breaks(read_view(both), 0.0), "R-7.0-02").verdict is Verdict.FAIL


def _cut_view(text: str, cut_after: float):
    events = _command("0M!", 0.0) + _command(text, 1.0)
    view = read_view(events)
    view.cut_parts = {0: events[-1].end + cut_after}
    return view


def test_a_command_the_tool_cut_while_it_was_sent_is_no_r_4_4_04_fail():
    """FAILed "0XM=G: '!' is not exactly the last character" on the tree before: the job's
    budget ran out as the logger sent its next character."""
    found = _rule(judge_command_text(_cut_view("0XM=G", 0.0)), "R-4.4-04")
    assert found.verdict is Verdict.PASS, found.detail
    assert "1 checked" in found.detail  # the complete 0M! only


def test_an_unterminated_command_long_before_the_cut_still_fails_r_4_4_04():
    """Sent and left 20 ms before the cut: a sensor has dropped it by then (App. B), so it
    is the recorder's unterminated command, not one the cut interrupted."""
    found = _rule(judge_command_text(_cut_view("0XM=G", 0.020)), "R-4.4-04")
    assert found.verdict is Verdict.FAIL
    uncut = read_view(_command("0M!", 0.0) + _command("0XM=G", 1.0))
    assert _rule(judge_command_text(uncut), "R-4.4-04").verdict is Verdict.FAIL
