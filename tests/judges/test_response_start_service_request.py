"""R-7.0-09 does not time a service request as a reply (``judges.wire._request_not_reply``).

A sensor sends its request when it is ready; one due while the tool's command is on the
line follows it at once (the sim bus holds a sensor frame due under the tool's command to
its end). service-request-after-ttt-zero beside inter-char-gap put '0<CR><LF>' 0.00 ms after
0D0!, whose values followed 8 ms later; beside replies-after-retry, 0.00 ms after 0MC1!'s
retry: R-7.0-09 FAILed "0.00 ms" (truth19). Words that are the command's own reply (a!, an
empty D reply) with no reply of its shape after them are still timed.
"""

from __future__ import annotations

from conformance.judges.wire import judge_response_start
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import Event, EventKind, to_wire_7e1
from conformance.verdicts import Verdict
from conformance.view.runs import segments


def _line(origin: str, start: float, text: str) -> list[Event]:
    return [
        Event(EventKind.CHAR, origin, t, t + CHAR_TIME, to_wire_7e1(ord(c)), "", 0.0)
        for t, c in ((start + i * CHAR_TIME, c) for i, c in enumerate(text))
    ]


def _early(command: str, lead: float, *after: str) -> Verdict:
    """R-7.0-09's verdict over ``command`` at 1 s, '0<CR><LF>' ``lead`` s after it, then each
    line of ``after`` 9 ms after the one before."""
    events = _line("tool", 1.0, command)
    t = events[-1].end + lead
    for text in ("0\r\n", *after):
        events += _line("dut", t, text)
        t = events[-1].end + 9e-3
    findings = judge_response_start(segments(events), 0.0)
    return next(f.verdict for f in findings if f.requirement == "R-7.0-09")


def test_a_request_right_after_a_d_command_whose_values_follow_is_no_reply():
    assert _early("0D0!", 0.0, "0+12.61+3.3\r\n") is not Verdict.FAIL  # FAIL before


def test_a_request_right_after_a_measurement_command_is_no_reply():
    """'0<CR><LF>' is no shape of 0MC1!'s reply (atttn): nothing timed, no FAIL."""
    assert _early("0MC1!", 0.0) is not Verdict.FAIL  # FAIL before


def test_an_empty_d_reply_too_soon_is_still_timed():
    assert _early("0D0!", 2e-3) is Verdict.FAIL


def test_an_acknowledge_too_soon_is_still_timed():
    assert _early("0!", 2e-3) is Verdict.FAIL


def test_a_request_in_the_window_is_timed_as_before():
    assert _early("0D0!", 9e-3, "0+12.61+3.3\r\n") is Verdict.PASS
