"""A late reply the tool's own character held back, and one heard after the last try (truth20).

The replies-after-retry sensor (every reply 80 ms after its command, deaf until then) beside
slow-wake (110 ms after a break before it hears a start bit) is heard only on the third try
of each sequence. 0C9!'s 0D0! reply, due 80 ms after the last try, met 0IMC_001! on the sim's
one wire, which sent it at the end of the tool's seventh character, 88.33 ms after the try:
past the 87 ms a late start is believed, "no reply to 0D0!" FAILed R-4.4.8-01. ``?!``'s
'0<CR><LF>' came 80 ms after the last try, heard only by a listen past it, and "?!: no
reply" FAILed R-4.4.3-01. Hand-typed wire events; each test marked "before" fails on the
tree before (base-s60).
"""

from __future__ import annotations

from conformance.judges import exchanges as xjudge
from conformance.judges.late_before import late_among, late_reply
from conformance.protocol import commands as cmds
from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder.records import NO_REPLY, OK, Attempt, Exchange
from conformance.transcript import DUT, TOOL
from conformance.verdicts import Verdict
from tests.support.hand_events import chars

DATA = "0+22.15+1013.2+45.7\r\n"


def _unanswered(text: str, t: float) -> Exchange:
    sent = chars(TOOL, text, t)
    attempt = Attempt(None, sent, [], NO_REPLY, sent[-1].end + 0.03)
    return Exchange(cmds.parse_command(text), text, [attempt])


def _next_with_reply(before: Exchange, text: str, lead: float, reply_at: float) -> Exchange:
    """``text`` sent ``lead`` s after ``before``'s last try, whose reply met it at
    ``reply_at`` s after that try (collided: kept as the attempt's stray characters)."""
    end = before.last.command_end
    assert end is not None
    after = _unanswered(text, end + lead)
    after.attempts[0].stray_events = chars(DUT, DATA, end + reply_at)
    before.next_sent[:] = [after]
    return after


def test_a_late_start_the_tool_s_character_held_back_counts_from_when_it_was_due() -> None:
    """0IMC_001! began 30 ms after 0D0!'s last try; its seventh character ended 88.33 ms
    after it, where the D reply began: 0D0!'s late reply, not silence."""
    before = _unanswered("0D0!", 0.0)
    _next_with_reply(before, "0IMC_001!", 0.030, 0.030 + 7 * CHAR_TIME)
    assert late_reply(before) == DATA  # '' before: 88.33 ms is past the 87 ms


def test_a_start_past_87_ms_with_no_tool_character_ending_there_is_no_late_reply() -> None:
    """The same start with the next command sent later (nothing of the tool's on the line
    then): past the 87 ms a late start is believed, no late reply."""
    before = _unanswered("0D0!", 0.0)
    _next_with_reply(before, "0IMC_001!", 0.095, 0.030 + 7 * CHAR_TIME)
    assert late_reply(before) == ""


def test_late_among_reads_what_came_after_the_last_try() -> None:
    """What the listen past the last try heard: '0<CR><LF>' 80 ms after ?! is its reply;
    one naming another address, or begun after 87 ms, is not."""
    ex = _unanswered("?!", 0.0)
    end = ex.last.command_end
    assert end is not None
    assert late_among(ex, chars(DUT, "0\r\n", end + 0.080))
    assert not late_among(ex, chars(DUT, "0\r\n", end + 0.090))
    acked = _unanswered("0!", 0.0)
    assert not late_among(acked, chars(DUT, "1\r\n", end + 0.080))


def test_query_answered_only_after_its_windows_is_undecided_not_failed() -> None:
    """R-4.4.3-01 on ?! whose '0<CR><LF>' the listen past the last try heard."""
    ex = _unanswered("?!", 0.0)
    end = ex.last.command_end
    assert end is not None
    ex.heard_late = chars(DUT, "0\r\n", end + 0.080)
    found = xjudge.reply_only_address(ex, "0", "R-4.4.3-01", "?!")
    assert found.verdict is Verdict.INCONCLUSIVE, found  # FAIL before: "?!: no reply"
    assert "?! -> late '0<CR><LF>'" in found.detail


def test_query_unanswered_and_unheard_still_fails() -> None:
    found = xjudge.reply_only_address(_unanswered("?!", 0.0), "0", "R-4.4.3-01", "?!")
    assert found.verdict is Verdict.FAIL and "no reply" in found.detail


def test_an_answered_query_is_judged_as_before() -> None:
    ex = _unanswered("?!", 0.0)
    end = ex.last.command_end
    assert end is not None
    ex.attempts[0].reply_events = chars(DUT, "0\r\n", end + 0.010)
    ex.attempts[0].reason = OK
    assert xjudge.reply_only_address(ex, "0", "R-4.4.3-01", "?!").verdict is Verdict.PASS
