"""A reply that may be the next line of a talk set aside is no command's answer (truth37).

outside34's ENG20009 Due sketch sends ``aDn!``-style replies as three lines 100 ms apart
('NO DATA @n', 'FINAL DATA @2', '0'), its receiver off meanwhile. The tool read the first
line, sent its next command, set aside the second (it met that command's try) and took the
third, '0<CR><LF>' 27 ms after 0R5!, as 0R5!'s empty reply: R-4.4.8.1-01 PASSed "conforms
(8 checked: 0R0!, 0R2!, 0R5!, 0R8!)". Hand-typed wire events; each test fails on base-s69b
(no ``continued_talk`` there: the reply counted for the PASS, its start for R-7.0-09).
"""

from __future__ import annotations

from dataclasses import replace

from conformance.judges import exchanges as xjudge
from conformance.judges import wire
from conformance.judges.continued_talk import continued_talk, next_line_of, segment_continues
from conformance.protocol import commands as cmds
from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder.records import CONTENTION, NO_REPLY, OK, Attempt, Exchange
from conformance.transcript import COLLISION, DUT, TOOL
from conformance.verdicts import Verdict
from conformance.view.runs import segments
from tests.support.hand_events import chars


def _talk_then(reply: str, gap: float, aside: str = "FINAL DATA @2\r\n") -> Exchange:
    """0R4! whose try met the line ``aside`` (set aside as contention, no reply), then 0R5!
    answered ``reply`` beginning ``gap`` s after that line's LF (the sketch: 69 ms)."""
    r4 = chars(TOOL, "0R4!", 1.0)
    met = chars(DUT, aside, r4[-1].end)
    r4_try = Attempt(None, r4, [], f"{CONTENTION} (1 characters during the command)",
                     met[-1].end, stray_events=met)  # fmt: skip
    before = Exchange(cmds.parse_command("0R4!"), "0R4!", [r4_try])
    r5 = chars(TOOL, "0R5!", met[-1].end + 0.009)
    got = chars(DUT, reply, met[-1].end + gap)
    assert got[0].start > r5[-1].end  # after the command: the live read takes it
    ex = Exchange(cmds.parse_command("0R5!"), "0R5!", [Attempt(None, r5, got, OK, got[-1].end)])
    ex.sent_before = before
    return ex


def test_a_line_after_a_talk_set_aside_is_no_answer_for_r_4_4_8_1_01():
    ex = _talk_then("0\r\n", 0.069)
    said = continued_talk(ex)
    assert "may be the next line of a talk" in said and "'FINAL DATA @2<CR><LF>'" in said
    found = {f.requirement: f for f in xjudge.continuous({5: (ex, ex)}, ["R-4.4.8.1-01"])}
    assert found["R-4.4.8.1-01"].verdict is Verdict.INCONCLUSIVE  # PASS on base-s69b
    assert "(R-7.0-10 judges its timing)" not in found["R-4.4.8.1-01"].detail  # not late


def test_a_reply_past_the_150_ms_a_next_line_may_take_is_the_commands():
    ex = _talk_then("0\r\n", 0.151 + CHAR_TIME)
    assert continued_talk(ex) == ""
    found = {f.requirement: f for f in xjudge.continuous({5: (ex, ex)}, ["R-4.4.8.1-01"])}
    assert found["R-4.4.8.1-01"].verdict is Verdict.PASS


def test_a_late_reply_to_the_command_it_met_is_left_to_late_before():
    """replies-after-retry: a values line shaped as the reply to the try it met is that
    try's late reply (:mod:`.late_before`), not a multi-line talk going on."""
    assert continued_talk(_talk_then("0+1.5\r\n", 0.069, aside="0+1.5\r\n")) == ""


def test_a_service_request_set_aside_is_a_line_of_its_own():
    assert continued_talk(_talk_then("0\r\n", 0.069, aside="0\r\n")) == ""


def test_a_talk_cut_before_its_lf_is_no_line_gone_by():
    line = chars(DUT, "FINAL DATA", 1.0)
    assert next_line_of(line, cmds.parse_command("0R4!"), chars(DUT, "0", 1.1)[0]) is None


def test_r_7_0_09_does_not_time_a_talks_next_line():
    """The same shape on the wire: '0<CR><LF>' 5 ms after 0R4!'s next try, the line before
    it set aside over the try before, FAILed R-7.0-09 (5.00 ms < 7.93 ms)."""
    r4 = chars(TOOL, "0R4!", 1.0)
    met = chars(DUT, "FINAL DATA @2\r\n", r4[-1].end)
    met[0] = replace(met[0], text=COLLISION)  # held behind the try it wanted the line during
    again = chars(TOOL, "0R4!", met[-1].end + 0.009)
    reply = chars(DUT, "0\r\n", again[-1].end + 0.005)
    segs = segments(r4 + met + again + reply)
    assert [s.text for s in segs] == ["0R4!", "0R4!"]
    assert segs[0].contention and segment_continues(segs[0], segs[1])
    early = wire.judge_response_start(segs, 0.0)[0]
    assert early.requirement == "R-7.0-09"
    assert early.verdict is not Verdict.FAIL, early.detail  # FAIL "5.00 ms" on base-s69b


def test_a_reply_after_a_clean_command_is_timed_as_ever():
    r0 = chars(TOOL, "0R0!", 1.0)
    reply = chars(DUT, "0+1\r\n", r0[-1].end + 0.009)
    segs = segments(r0 + reply)
    assert not segment_continues(None, segs[0])
    early = wire.judge_response_start(segs, 0.0)[0]
    assert early.verdict is Verdict.PASS, early.detail


def test_no_talk_before_no_hold():
    ex = _talk_then("0\r\n", 0.069)
    ex.sent_before = None
    assert continued_talk(ex) == ""
    silent = Attempt(None, chars(TOOL, "0R6!", 5.0), [], NO_REPLY, 5.1)
    assert continued_talk(Exchange(cmds.parse_command("0R6!"), "0R6!", [silent])) == ""
