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


#: The sixteenth outside round's lagopus sketch at '5' (docs/kit.md): it kept the tool's ?!s
#: through its boot and answered them, '5<CR><LF>' twice, 1.50 ms after the tool's first 0!;
#: then a 5! answered 9 ms after it. The stamps are that run's (r6), the last exchange made up.
BOOT_ANSWERS = [
    ("tool", 1.4903333, 1.4986667, "0"),
    ("tool", 1.4986667, 1.5070000, "!"),
    ("dut", 1.508501, 1.516799, "5"),
    ("dut", 1.516801, 1.525121, "\r"),
    ("dut", 1.525121, 1.533441, "\n"),
    ("dut", 1.541941, 1.550203, "5"),
    ("dut", 1.550209, 1.558529, "\r"),
    ("dut", 1.558529, 1.566849, "\n"),
    ("tool", 1.700000, 1.708333, "5"),
    ("tool", 1.708333, 1.716667, "!"),
    ("dut", 1.725667, 1.734000, "5"),
    ("dut", 1.734000, 1.742333, "\r"),
    ("dut", 1.742333, 1.750667, "\n"),
]


def test_an_answer_naming_another_address_sooner_than_any_reply_is_not_timed():
    """R-7.0-09 counted '5<CR><LF>' 1.50 ms after 0! as a reply to it ("477 replies,
    1.50..7.67 ms"): an answer to the ?!s kept through the boot, begun before 0! could have
    been heard. Only 5!'s reply is timed now (it FAILed on the 1.50 ms before)."""
    findings = judge_response_start(segments(_events(BOOT_ANSWERS)), 0.0)
    early = next(f for f in findings if f.requirement == "R-7.0-09")
    assert early.verdict is Verdict.PASS, early.detail
    assert "1 reply" in early.detail and "1.50" not in early.detail, early.detail


def test_a_reply_naming_another_address_in_the_reply_window_is_still_timed():
    """A reply in the window that names another address (wrong-reply-address's D replies)
    is timed as before: R-4.3-01 judges its address, R-7.0-10 its start."""
    rows = [
        ("tool", 1.000, 1.00833, "0"),
        ("tool", 1.00833, 1.01667, "!"),
        ("dut", 1.03667, 1.045, "1"),
        ("dut", 1.045, 1.05333, "\r"),
        ("dut", 1.05333, 1.06167, "\n"),
    ]
    findings = judge_response_start(segments(_events(rows)), 0.0)
    assert _verdict("R-7.0-10", findings) is Verdict.FAIL  # 20.00 ms


def test_a_run_under_way_when_the_command_ended_is_not_timed_as_its_reply():
    """A sensor already talking when the command ended, two lines back to back: the first
    met the command (every character of it started before the end: contention), the second
    follows its LF with no marking, so it was under way then, no reply begun 0.67 ms after
    the command (R-7.0-09 FAILed on it)."""
    rows = [
        ("tool", 1.000, 1.00833, "0"),
        ("tool", 1.00833, 1.01667, "D"),
        ("tool", 1.01667, 1.025, "0"),
        ("tool", 1.025, 1.03333, "!"),
        ("dut", 1.00833, 1.01667, "0"),
        ("dut", 1.01667, 1.025, "\r"),
        ("dut", 1.025, 1.03333, "\n"),
        ("dut", 1.034, 1.04233, "0"),
        ("dut", 1.04233, 1.05067, "\r"),
        ("dut", 1.05067, 1.059, "\n"),
    ]
    (seg,) = segments(_events(rows))
    assert "".join(chr(e.wire & 0x7F) for e in seg.reply) == "0\r\n"  # the premise
    findings = judge_response_start([seg], 0.0)
    assert _verdict("R-7.0-09", findings) is not Verdict.FAIL
