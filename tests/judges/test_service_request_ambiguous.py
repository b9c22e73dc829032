"""Which line is the service request, when none is exactly ``a<CR><LF>`` and two are shaped
like one (issue 22, ninth round, seed 4058: chatter-before-service-request beside
service-request-extra-chars took the 'aBUSY' chatter for the request, WARNed R-4.4.5-09 and
PASSed R-4.4.5-08)."""

from __future__ import annotations

from conformance.judges import measurements
from conformance.verdicts import Verdict

from .test_judges import chars, measurement

IDS = ("R-4.4.5-08", "R-4.4.5-09", "R-4.4.6-01", "R-4.4.6-02", "R-4.4.6-04")


def _verdicts(*lines: tuple[str, float]) -> dict[str, Verdict]:
    """aM! announcing ttt = 2 s, the sensor's ``lines`` (text, s after the reply) while the
    recorder waited, and a D0 with its 3 values."""
    m = measurement("00023\r\n", None, [("0D0!", "0+1+2+3\r\n")])
    for text, after in lines:
        m.waited_events += chars(text, m.reply_end + after, "dut")
    found = measurements.judge([m], IDS, "14")
    return {f.requirement: f.verdict for f in found}


def test_two_lines_either_of_which_may_be_the_request_leave_its_timing_undecided():
    got = _verdicts(("0BUSY\r\n", 0.8), ("0SR\r\n", 1.95))
    assert got["R-4.4.6-01"] is Verdict.FAIL  # whichever it is, it is malformed
    assert got["R-4.4.6-02"] is Verdict.PASS
    for rid in ("R-4.4.5-08", "R-4.4.5-09", "R-4.4.6-04"):
        assert got[rid] is Verdict.INCONCLUSIVE, rid


def test_one_malformed_request_is_judged_as_before():
    got = _verdicts(("0SR\r\n", 1.95))
    assert got["R-4.4.6-01"] is Verdict.FAIL
    assert got["R-4.4.5-08"] is got["R-4.4.5-09"] is got["R-4.4.6-04"] is Verdict.PASS


def test_chatter_before_an_exact_request_fails_r_4_4_5_08():
    got = _verdicts(("0BUSY\r\n", 0.8), ("0\r\n", 1.95))
    assert got["R-4.4.5-08"] is Verdict.FAIL
    assert got["R-4.4.6-01"] is got["R-4.4.6-04"] is Verdict.PASS


def _measured(*lines: tuple[str, float]):
    m = measurement("00023\r\n", None, [("0D0!", "0+1+2+3\r\n")])
    for text, after in lines:
        m.waited_events += chars(text, m.reply_end + after, "dut")
    return m


def test_a_line_the_sensor_sent_before_its_exact_request_is_chatter_elsewhere_too():
    """aM!'s wait shows 'aBUSY' before an exact request; a second wait holding only 'aBUSY'
    had no request (R-4.4.6-02), not a malformed one (R-4.4.6-01): chatter-before-service-
    request beside verify-no-service-request, seed 4064."""
    exact = _measured(("0BUSY\r\n", 0.8), ("0\r\n", 1.95))
    none = _measured(("0BUSY\r\n", 0.8))
    got = {f.requirement: f.verdict for f in measurements.judge([exact, none], IDS, "14")}
    assert got["R-4.4.6-02"] is Verdict.FAIL
    assert got["R-4.4.6-01"] is Verdict.PASS
    assert got["R-4.4.5-08"] is Verdict.FAIL
    # judged alone, the lone line is still the only candidate for a malformed request
    alone = {f.requirement: f.verdict for f in measurements.judge([none], IDS, "14")}
    assert alone["R-4.4.6-01"] is Verdict.FAIL
