"""The bus cases' judges on hand-made events and records (conformance/judges/bus.py)."""

from __future__ import annotations

from conformance.judges.bus import kept_through_bus, sensor_lines, silent_among_others
from conformance.protocol.commands import parse_command
from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder.records import Attempt, Exchange, Measurement
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.verdicts import Verdict


def chars(text: str, origin: str, start: float) -> list[Event]:
    return [
        Event(EventKind.CHAR, origin, start + i * CHAR_TIME, start + (i + 1) * CHAR_TIME,
              wire=to_wire_7e1(ord(c)))
        for i, c in enumerate(text)
    ]  # fmt: skip


def exchange(command: str, reply: str, start: float) -> Exchange:
    sent = chars(command, TOOL, start)
    back = chars(reply, DUT, sent[-1].end + 0.01)
    attempt = Attempt(None, sent, back, "ok", back[-1].end if back else sent[-1].end)
    return Exchange(parse_command(command), command, [attempt])


def window_with(*extra: list[Event]) -> tuple[list[Event], list[Exchange]]:
    """The DUT (0) waiting while sensor 1 is asked aC! and answers; ``extra`` after it."""
    other = exchange("1C!", "100320\r\n", 1.0)
    events = [*other.attempts[0].command_events, *other.attempts[0].reply_events]
    for more in extra:
        events += more
    return events, [other]


def test_lines_are_cut_at_lf_and_at_the_tool():
    events = [*chars("1\r\n0\r", DUT, 0.0), *chars("2!", TOOL, 1.0), *chars("3", DUT, 2.0)]
    assert ["".join(chr(e.char7) for e in line) for line in sensor_lines(events)] == [
        "1\r\n", "0\r", "3"
    ]  # fmt: skip


def test_silence_among_others_passes_on_what_was_heard():
    events, others = window_with()
    (finding,) = silent_among_others("0", events, others)
    assert finding.verdict is Verdict.PASS and finding.observed == 1


def test_a_line_with_the_dut_address_after_another_reply_fails():
    events, others = window_with(chars("0\r\n", DUT, 1.3))
    (finding,) = silent_among_others("0", events, others)
    assert finding.verdict is Verdict.FAIL and "0<CR><LF>" in finding.evidence[0]
    # another sensor's line is not the DUT's
    events, others = window_with(chars("3\r\n", DUT, 1.3))
    assert silent_among_others("0", events, others)[0].verdict is Verdict.PASS


def test_a_measurement_kept_through_the_bus_passes_and_a_lost_one_fails():
    _events, others = window_with()
    m = Measurement(parse_command("0C!"), exchange("0C!", "000320\r\n", 0.5))
    m.count = 20
    m.values = [f"+{i}" for i in range(20)]
    assert kept_through_bus(m, 20, others)[0].verdict is Verdict.PASS
    m.values = []
    lost = kept_through_bus(m, 20, others)[0]
    assert lost.verdict is Verdict.FAIL and "aborted it" in lost.detail


def test_a_cut_line_with_the_dut_address_is_undecided_not_a_fail():
    """The tool's break cut another sensor's reply: its remainder may start with any digit."""
    brk = Event(EventKind.BREAK, TOOL, 1.3, 1.313)
    events, others = window_with(chars("1+", DUT, 1.25), [brk], chars("0.5\r\n", DUT, 1.4))
    (finding,) = silent_among_others("0", events, others)
    assert finding.verdict is Verdict.INCONCLUSIVE and "cut" in finding.detail
