"""R-7.0-09/-10 time a reply that began after a command whose previous command went
unanswered only where both readings agree: it may answer either (eighteenth round, docs/
kit.md: an Arduino Due sensor, Samch458/SDI12-sensor-and-data-logger, whose every reply
starts 100 ms after the command it answers, `delay(100)` in its SDI12Send). The tool's retry
came 55 ms after the first try; the reply to the first try began 11.35 ms after the retry's
``!`` and was timed as an in-time reply to the retry: 8 such replies were R-7.0-10 PASS
evidence, and a sensor 20 ms slower would have PASSed R-7.0-10 on them alone. The events
are that run's (`sim`-free: the firmware's on the kit), as stamped."""

from __future__ import annotations

from conformance.judges.wire import ResponseStarts, judge_response_start
from conformance.transcript import Event, EventKind, to_wire_7e1
from conformance.verdicts import Verdict
from conformance.view.runs import segments

BIT = 1 / 1200
CHAR = 10 * BIT


def _send(origin: str, start: float, text: str) -> list[tuple[str, float, float, str]]:
    return [(origin, start + k * CHAR, start + (k + 1) * CHAR, c) for k, c in enumerate(text)]


def _events(rows) -> list[Event]:
    return [
        Event(EventKind.CHAR, origin, start, end, to_wire_7e1(ord(c)), "", 0.0)
        for origin, start, end, c in rows
    ]


def _finding(rule: str, findings):
    return next(f for f in findings if f.requirement == rule)


#: 0A9! at 65.7601 s unanswered, its retry 55 ms after it, and the reply to the first try
#: 99.67 ms after it: 11.37 ms after the retry ended
RETRIED = _send("tool", 65.7601, "0A9!") + _send("tool", 65.8484, "0A9!")
RETRIED += _send("dut", 65.8931, "9\r\n")


def test_a_reply_after_a_retry_is_no_in_time_evidence():
    """Before: R-7.0-10 PASS "1 replies, 11.35 ms"; the reply may be the first try's, 99.7 ms
    late: nothing left to judge (the figures are these events', rounded as typed)."""
    found = judge_response_start(segments(_events(RETRIED)), 0.0)
    assert _finding("R-7.0-10", found).verdict is Verdict.INCONCLUSIVE
    # R-7.0-09 (not before 7.93 ms) holds on either reading: still judged
    early = _finding("R-7.0-09", found)
    assert early.verdict is Verdict.PASS
    assert "or to 0A9! before it, 99.67 ms" in " ".join(early.evidence) + early.detail


def test_a_reply_late_on_either_reading_still_fails_r_7_0_10():
    """'$<CR><LF>' began 53.01 ms after the 0! sent after the unanswered 0A$!: late whichever
    it answers (99.68 ms after 0A$!)."""
    rows = _send("tool", 107.3792, "0A$!") + _send("tool", 107.4425, "0!")
    rows += _send("dut", 107.5122, "$\r\n")
    late = _finding("R-7.0-10", judge_response_start(segments(_events(rows)), 0.0))
    assert late.verdict is Verdict.FAIL
    assert late.measured_ms is not None and abs(late.measured_ms - 53.0) < 0.1


def test_a_reply_that_cannot_answer_the_command_before_is_timed_as_before():
    """The unanswered command before was for another address ('9!', a foreign probe): the
    '0<CR><LF>' 9 ms after 0! is its reply, in time."""
    rows = _send("tool", 1.0, "9!") + _send("tool", 1.1, "0!") + _send("dut", 1.1257, "0\r\n")
    late = _finding("R-7.0-10", judge_response_start(segments(_events(rows)), 0.0))
    assert late.verdict is Verdict.PASS


def test_a_window_cut_between_the_unanswered_command_and_its_reply_reads_the_same():
    """Judged a window at a time (``ResponseStarts``, issue 22), the cut may fall after the
    unanswered try: the next window's reply is read against it as in the whole run (before,
    each window started afresh and R-7.0-10 PASSed on the retry's 11.35 ms again)."""
    rows = RETRIED + _send("tool", 66.5, "0!") + _send("dut", 66.5257, "0\r\n")
    segs = segments(_events(rows))
    whole = judge_response_start(segs, 0.0)
    assert _finding("R-7.0-10", whole).verdict is Verdict.PASS  # 0! in time; the retry not
    for cut in range(len(segs) + 1):
        starts = ResponseStarts(0.0)
        starts.add(segs[:cut])
        starts.add(segs[cut:])
        assert starts.findings() == whole, cut
