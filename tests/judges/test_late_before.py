"""A reply that began after the tool's next command may be the command before's (truth15).

The replies-after-retry sensor (every reply 80 ms after its command, deaf until then) answers
a try the tool gave up on while the tool sends its next command, which it never hears: the
reply lands in that command's window. Beside wrong-crc, 0D0!'s retry went unanswered and its
data reply, 80 ms later, was read as 0MC1!'s: R-4.4.5-01 FAILed "does not have the form
atttn". A D whose reply met the retry FAILed R-4.4.8-01 "no reply" and R-4.4.8-03 "60 values
for 99". A one-shot probe's late characters naming another address counted as its answer
for every reader of ``heard_late`` but R-7.0-14. Hand-typed wire events, each test failing
on the tree before (3cd7ee8).
"""

from __future__ import annotations

from conformance.judges import exchanges as xjudge
from conformance.judges import measurements as mjudge
from conformance.judges import wire
from conformance.judges.extended import extended_replies
from conformance.judges.late_before import earlier_reply, heard_late, late_elsewhere, late_reply
from conformance.judges.metadata import identify_matches
from conformance.protocol import commands as cmds
from conformance.tool_recorder.records import NO_REPLY, OK, Attempt, Exchange, Measurement
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict
from conformance.view.runs import segments
from tests.support.hand_events import chars

LATE = 0.080  # the sensor's reply start after the command it heard


def _exchange(text: str, t: float, reply: str | None = None, delay: float = 0.009) -> Exchange:
    """``text`` sent once at ``t``, answered ``reply`` ``delay`` s after it (None: not)."""
    sent = chars(TOOL, text, t)
    got = chars(DUT, reply, sent[-1].end + delay) if reply else []
    end = got[-1].end if got else sent[-1].end + 0.03
    attempt = Attempt(None, sent, got, OK if got else NO_REPLY, end)
    return Exchange(cmds.parse_command(text), text, [attempt])


def _after_unanswered(before_text: str, text: str, reply: str) -> Exchange:
    """``before_text`` unanswered at 0 s; ``text`` 30 ms after its window, taking ``reply``,
    which began 80 ms after ``before_text`` ended; linked as the session's engine links."""
    before = _exchange(before_text, 0.0)
    end = before.last.command_end
    assert end is not None
    ex = _exchange(text, end + 0.030)
    ex.attempts[0].reply_events = chars(DUT, reply, end + LATE)
    ex.attempts[0].reason = OK
    ex.late_before = before
    return ex


DATA = "0+22.15+1013.2+45.7DOm\r\n"  # a D reply, its CRC wrong (wrong-crc)


def test_r_4_4_5_01_a_d_reply_taken_by_amc1_is_the_d_before_s() -> None:
    ex = _after_unanswered("0D0!", "0MC1!", DATA)
    assert "is 0D0!'s late reply (80.00 ms after it)" in earlier_reply(ex)
    m = Measurement(ex.command, ex)
    found = {f.requirement: f for f in mjudge.judge([m], ["R-4.4.5-01"], "14")}
    assert found["R-4.4.5-01"].verdict is Verdict.INCONCLUSIVE, found  # FAIL before
    assert "0D0!'s late reply" in found["R-4.4.5-01"].detail


def test_a_reply_shaped_as_this_command_s_only_is_its_own() -> None:
    """'00012' answers 0M1!, not the 0D0! before it: judged as 0M1!'s, here a PASS."""
    ex = _after_unanswered("0D0!", "0M1!", "00012\r\n")
    assert earlier_reply(ex) == ""
    m = Measurement(ex.command, ex)
    found = {f.requirement: f for f in mjudge.judge([m], ["R-4.4.5-01"], "14")}
    assert found["R-4.4.5-01"].verdict is Verdict.PASS


def test_a_reply_both_could_take_is_undecided() -> None:
    """'00011' after an unanswered 0M! and to 0M1!: the wire cannot tell which it answers."""
    assert "may be 0M!'s late reply" in earlier_reply(_after_unanswered("0M!", "0M1!", "00011\r\n"))


def test_no_link_no_doubt() -> None:
    """A sensor never seen late links nothing (the engine): the reply is the command's."""
    ex = _after_unanswered("0D0!", "0MC1!", DATA)
    ex.late_before = None
    assert earlier_reply(ex) == ""


def test_a_reply_naming_another_address_is_not_the_command_before_s() -> None:
    assert earlier_reply(_after_unanswered("1D0!", "0MC1!", DATA)) == ""


def _measurement_with_late_d(count: int = 20) -> Measurement:
    """0C! announcing ``count`` values, D0 answered with 10, D1 unanswered in its windows
    with its reply met by the retry (the retry's stray characters)."""
    start = _exchange("0C!", 0.0, f"0000{count:02d}\r\n")
    d0 = _exchange("0D0!", 1.0, "0" + "+1.0" * 10 + "\r\n")
    d1 = _exchange("0D1!", 2.0)
    retry_sent = chars(TOOL, "0D1!", 2.1)
    stray = chars(DUT, "0+2.0+2.0\r\n", retry_sent[-1].end)
    d1.attempts.append(Attempt(None, retry_sent, [], NO_REPLY, 2.2, retry=1, stray_events=stray))
    m = Measurement(start.command, start)
    m.ttt, m.count, m.data = 0, count, [d0, d1]
    return m


def test_r_4_4_8_01_and_03_a_d_reply_met_by_the_retry_is_no_silence() -> None:
    m = _measurement_with_late_d()
    found = {f.requirement: f for f in mjudge.judge([m], ["R-4.4.8-01", "R-4.4.8-03"], "14")}
    for rid in ("R-4.4.8-01", "R-4.4.8-03"):  # both FAILed before
        assert found[rid].verdict is Verdict.INCONCLUSIVE, found[rid]
        assert "0D1! -> late '0+2.0+2.0<CR><LF>'" in found[rid].detail


def test_r_4_4_8_01_a_silent_d_still_fails() -> None:
    m = _measurement_with_late_d()
    m.data[1].attempts[1].stray_events = []
    found = {f.requirement: f for f in mjudge.judge([m], ["R-4.4.8-01", "R-4.4.8-03"], "14")}
    assert found["R-4.4.8-01"].verdict is Verdict.FAIL
    assert found["R-4.4.8-03"].verdict is Verdict.FAIL


def _probe_heard_late(late: str) -> Exchange:
    ex = _exchange("0!", 0.0)
    ex.expect_reply = False
    ex.heard_late = chars(DUT, late, 0.1)
    return ex


def test_a_late_reply_naming_another_address_is_no_answer_for_any_reader() -> None:
    """answers-foreign-address + replies-after-retry: 'z<CR><LF>' to z! came over 0!."""
    ex = _probe_heard_late("z\r\n")
    assert not heard_late(ex) and late_elsewhere(ex) == "z\r\n"
    control = _exchange("0!", 1.0, "0\r\n")
    found = xjudge.silent("R-7.0-15", [ex], "in standby", baseline=control)
    # FAILed "answered although ..." before; silence it may not have heard is no PASS either
    assert found.verdict is Verdict.INCONCLUSIVE, found.detail
    assert "may not have been heard" in found.detail


def test_a_late_reply_with_the_probe_s_address_is_its_answer() -> None:
    ex = _probe_heard_late("0\r\n")
    assert heard_late(ex) and late_elsewhere(ex) == ""
    control = _exchange("0!", 1.0, "0\r\n")
    assert xjudge.silent("R-7.0-15", [ex], "in standby", baseline=control).verdict is Verdict.FAIL


def _foreign_then_own(reply: str) -> list[Event]:
    """z! unanswered at 0 s, then 0! 30 ms after it, and ``reply`` 80 ms after z! ended (33 ms
    after 0!): answers-foreign-address + replies-after-retry's R-7.0-14 probe on the wire."""
    events = [Event(EventKind.BREAK, TOOL, 0.0, 0.013)]
    events += (z := chars(TOOL, "z!", 0.022))
    events += chars(TOOL, "0!", z[-1].end + 0.030)
    events += chars(DUT, reply, z[-1].end + LATE)
    return events


def test_r_4_3_01_a_reply_naming_the_unanswered_command_before_is_not_judged_as_this_one_s():
    found = {f.requirement: f for f in wire.judge_framing(segments(_foreign_then_own("z\r\n")))}
    assert found["R-4.3-01"].verdict is Verdict.INCONCLUSIVE, found["R-4.3-01"]  # FAIL before
    assert "may be z!'s late reply" in found["R-4.3-01"].detail
    # a reply naming neither command is still a wrong address
    found = {f.requirement: f for f in wire.judge_framing(segments(_foreign_then_own("5\r\n")))}
    assert found["R-4.3-01"].verdict is Verdict.FAIL


def test_r_6_1_02_an_identify_reply_that_may_be_the_command_before_s_is_not_compared() -> None:
    ident = _after_unanswered("0M!", "0IM1!", "00019\r\n")  # 0M!'s count, late
    start = _exchange("0M1!", 1.0, "00012\r\n")
    m = Measurement(start.command, start)
    (found,) = identify_matches([(ident, m)])
    assert found.verdict is Verdict.INCONCLUSIVE, found  # FAIL "announces 9 values" before
    assert "may be 0M!'s late reply" in found.detail


def test_r_4_4_8_1_02_a_continuous_reply_that_is_an_identification_is_not_r1_s() -> None:
    """ident-bad-version + replies-after-retry: aI!'s late reply taken by aR1! FAILed "R1
    without the lower indices first gave no values: 0R1! -> '0V4CONFORM...'"."""
    ex = _after_unanswered("0I!", "0R1!", "0V4CONFORM EMU001100SN0001\r\n")
    found = xjudge.late_only("R-4.4.8.1-02", ex, "R1 without the lower indices first")
    assert found is not None and found.verdict is Verdict.INCONCLUSIVE  # None before: FAIL
    assert "may be 0I!'s late reply" in found.detail


def test_r_4_4_13_01_an_extended_reply_that_may_be_the_command_before_s_is_not_judged() -> None:
    """answers-foreign-address + replies-after-retry: 0XSN!'s reply '0EMU-0001', 80 ms after
    its retry, was taken by 0XHELP!: R-4.4.13-01/-02 PASSed "conforms (1 checked: 0XHELP!)"
    on another command's words."""
    ex = _after_unanswered("0XSN!", "0XHELP!", "0EMU-0001\r\n")
    found = {f.requirement: f for f in extended_replies([ex], "0")}
    for rid in ("R-4.4.13-01", "R-4.4.13-02"):  # PASS before
        assert found[rid].verdict is Verdict.INCONCLUSIVE, found[rid]
        assert "may be 0XSN!'s late reply" in found[rid].detail


def test_r_4_4_5_01_a_late_reply_naming_neither_address_is_still_doubted() -> None:
    """wrong-reply-address + replies-after-retry: 0D0!'s late reply from '1' taken by 0MC1!
    FAILed R-4.4.5-01 "reply '1+22.15...' does not have the form atttn"."""
    ex = _after_unanswered("0D0!", "0MC1!", "1+22.15+1013.2+45.7K\x7fQ\r\n")
    assert "0D0!'s late reply" in earlier_reply(ex)
    m = Measurement(ex.command, ex)
    found = {f.requirement: f for f in mjudge.judge([m], ["R-4.4.5-01"], "14")}
    assert found["R-4.4.5-01"].verdict is Verdict.INCONCLUSIVE, found  # FAIL before


def _unanswered_then(text: str, next_text: str, reply: str, before_next: bool = False):
    """``text`` unanswered at 0 s, then ``next_text`` 30 ms after its window (or, with
    ``before_next``, 120 ms after it), and ``reply`` 80 ms after ``text`` ended: taken by
    ``next_text``'s first try, or queued before it; linked as the session's engine links."""
    ex = _exchange(text, 0.0)
    end = ex.last.command_end
    assert end is not None
    after = _exchange(next_text, end + (0.120 if before_next else 0.030))
    got = chars(DUT, reply, end + LATE)
    if before_next:
        after.attempts[0].stray_events = got
    else:
        after.attempts[0].reply_events = got
        after.attempts[0].reason = OK
    ex.next_sent[:] = [after]
    return ex


def test_r_4_4_8_01_a_d_reply_taken_by_the_next_start_is_the_d_s_late_reply() -> None:
    """replies-after-retry + slow-wake (truth18): 0D0!'s tries were met only after each
    break's 110 ms wake-up, its reply to the last came 80 ms later, in 0C1!'s window:
    "0C! 0D0!: no reply to 0D0!" FAILed R-4.4.8-01 and "0 values for 20" R-4.4.8-03."""
    d0 = _unanswered_then("0D0!", "0C1!", "0-5.00-3.75\r\n")
    assert late_reply(d0) == "0-5.00-3.75\r\n"
    start = _exchange("0C!", -3.0, "000320\r\n")
    m = Measurement(start.command, start, data=[d0], count=20, ttt=3)
    found = {f.requirement: f for f in mjudge.judge([m], ["R-4.4.8-01", "R-4.4.8-03"], "14")}
    for rid in ("R-4.4.8-01", "R-4.4.8-03"):
        assert found[rid].verdict is Verdict.INCONCLUSIVE, found[rid]  # FAIL before
        assert "answered only after the reply window" in found[rid].detail


def test_a_reply_shaped_as_the_next_command_s_is_its_own() -> None:
    """A reply the next command took in its window, shaped as its answer and not as the
    unanswered command's, is the next command's: the silence before it stays silence."""
    d0 = _unanswered_then("0D0!", "0C1!", "000320\r\n")
    assert late_reply(d0) == ""
    # an ack shaped as both is the next a!'s own answer; one queued before it went out is
    # no answer to it, whatever its shape
    assert late_reply(_unanswered_then("?!", "0!", "0\r\n")) == ""
    assert late_reply(_unanswered_then("?!", "0!", "0\r\n", before_next=True)) == "0\r\n"
