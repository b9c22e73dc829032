"""R-7.0-10 is not timed from what is left of a reply the view set aside as contention
(eff12, fault ``stray-after-line-end`` over RFC 2217 with ``--echo --usb-latency 16``): the
sensor's ``0<CR><LF>`` to ``0D7!``, stamped between the echoes of the command by the
latency timer's batches, was set aside as two talkers, and the stray ``#`` it sent 2 ms
after its LF was timed as the reply: 39.83 ms ± 15.46, a false FAIL (the emulator replies
9 ms after every command). The events are that run's, as stamped."""

from __future__ import annotations

from conformance.judges.wire import judge_response_start
from conformance.transcript import Event, EventKind, to_wire_7e1
from conformance.verdicts import Verdict
from conformance.view.runs import segments

U = 0.015460922333375038  # the run's stamp uncertainty (s)

#: (origin, start, end, character) of the 0D7! exchange at t=314.8875 s and the one before
#: it (the re-probe sent it 10 times), whose stray '#' the view reads the next one after
EXCHANGE = [
    ("tool", 314.75052, 314.75885, "0"),
    ("tool", 314.75885, 314.76719, "D"),
    ("tool", 314.76719, 314.77552, "7"),
    ("tool", 314.77552, 314.78385, "!"),
    ("dut", 314.79852, 314.80686, "0"),
    ("dut", 314.80686, 314.81519, "\r"),
    ("dut", 314.81519, 314.82352, "\n"),
    ("dut", 314.82352, 314.83186, "#"),
    ("tool", 314.84652, 314.85485, "0"),
    ("tool", 314.86250, 314.87083, "D"),
    ("tool", 314.87083, 314.87917, "7"),
    ("tool", 314.87917, 314.88750, "!"),
    ("dut", 314.89447, 314.90281, "0"),
    ("dut", 314.91066, 314.91899, "\r"),
    ("dut", 314.91899, 314.92733, "\n"),
    ("dut", 314.92733, 314.93566, "#"),
]


def _events(rows) -> list[Event]:
    return [
        Event(EventKind.CHAR, origin, start, end, to_wire_7e1(ord(c)), "", U)
        for origin, start, end, c in rows
    ]


def _verdict(rule: str, findings) -> Verdict:
    return next(f.verdict for f in findings if f.requirement == rule)


def test_the_view_sets_the_reply_aside_and_leaves_the_stray_char():
    """The premise: the cut this judge reads (if the view changes, this test says so)."""
    _, seg = segments(_events(EXCHANGE))
    assert "".join(chr(e.wire & 0x7F) for e in seg.contention) == "0\r\n"
    assert [chr(e.wire & 0x7F) for e in seg.reply] == ["#"]


def test_a_stray_char_after_a_reply_set_aside_is_not_timed_as_the_reply():
    """R-7.0-10: no FAIL at 39.83 ms (it did); nothing else timed: INCONCLUSIVE."""
    findings = judge_response_start(segments(_events(EXCHANGE)), U)
    assert _verdict("R-7.0-10", findings) is not Verdict.FAIL
    assert _verdict("R-7.0-09", findings) is not Verdict.PASS


def test_a_reply_after_a_service_request_that_met_the_command_is_still_timed():
    """A sensor character that started before the command ended is no reply to it: the
    reply after it is timed as before (the sim's service-request-after-ttt-zero run)."""
    rows = [
        ("tool", 1.000, 1.00833, "0"),
        ("dut", 1.004, 1.01233, "0"),
        ("tool", 1.00833, 1.01667, "D"),
        ("dut", 1.01233, 1.02067, "\r"),
        ("tool", 1.01667, 1.025, "0"),
        ("dut", 1.02067, 1.029, "\n"),
        ("tool", 1.025, 1.03333, "!"),
        ("dut", 1.04233, 1.05067, "0"),
        ("dut", 1.05067, 1.059, "\r"),
        ("dut", 1.059, 1.06733, "\n"),
    ]
    (seg,) = segments(_events(rows))
    assert seg.contention and all(e.start < seg.command_end for e in seg.contention)
    findings = judge_response_start([seg], 0.0)
    assert _verdict("R-7.0-10", findings) is Verdict.PASS
