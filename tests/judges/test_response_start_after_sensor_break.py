"""R-7.0-09 where the sensor held the line spacing (a break: a harness's ``brk``) between the
command and its reply: the sensor's 8.33 ms of marking ended where its spacing began, not at
its reply's first start bit. The twenty-fourth round's AgriApps sketch (docs/kit.md) on the
2013 Arduino-SDI-12 library "wakes the sensors" before every reply (12.1 ms of spacing at
the command's end), marks 8.4 ms and replies 20.06 ms after the command: R-7.0-09 PASSed
"946 replies, 20.06..20.06 ms" although a recorder's UART reads a start bit at 0.00 ms.
R-7.0-10 still times the reply's first character (a break is no character of it)."""

from __future__ import annotations

from conformance.judges.wire import judge_response_start
from conformance.sim.bus import SENSOR_BREAK
from conformance.transcript import DUT, TOOL, Event, EventKind
from conformance.verdicts import Verdict
from conformance.view.runs import segments
from tests.support.hand_events import chars

COMMAND_END = 0.1 + 2 * 10 / 1200  # "0!" from 100 ms


def _run(spacing_from: float | None) -> list[Event]:
    """``0!`` and its reply ``0<CR><LF>`` 20.5 ms after it; with a 12.1 ms sensor break
    ``spacing_from`` after the command when given."""
    events = chars(TOOL, "0!", 0.1)
    if spacing_from is not None:
        start = COMMAND_END + spacing_from
        events.append(Event(EventKind.BREAK, DUT, start, start + 0.0121, text=SENSOR_BREAK))
    return events + chars(DUT, "0\r\n", COMMAND_END + 0.0205)


def _found(events: list[Event], rule: str):
    return next(f for f in judge_response_start(segments(events), 0.0) if f.requirement == rule)


def test_a_break_the_sensor_holds_before_its_reply_fails_r_7_0_09():
    early = _found(_run(0.0), "R-7.0-09")
    assert early.verdict is Verdict.FAIL
    assert early.measured_ms == 0.0
    said = early.detail + " ".join(early.evidence)
    assert "held the line spacing from 0.00 ms after the command, 12.10 ms" in said
    late = _found(_run(0.0), "R-7.0-10")  # its reply's first character: late
    assert late.verdict is Verdict.FAIL and abs(late.measured_ms - 20.5) < 0.01


def test_a_break_after_the_marking_is_timed_there():
    """Spacing 9 ms after the command kept the 8.33 ms of marking: R-7.0-09 holds (9.00)."""
    early = _found(_run(0.009), "R-7.0-09")
    assert early.verdict is Verdict.PASS and early.measured_ms == 9.0


def test_without_a_break_the_reply_is_timed_as_before():
    early = _found(_run(None), "R-7.0-09")
    assert early.verdict is Verdict.PASS and abs(early.measured_ms - 20.5) < 0.01
