"""The measurement and data rules judged a window at a time (issue 22's windowed judge):
``judges.measurements.Measurements`` given a recording's measurements in parts, in order,
gives the whole recording's findings (``measurements.judge``), detail for detail, wherever
the parts are cut; and over the windows of a bus ``view.windows`` cuts, each window's
records rebuilt alone.

The case a wrong merge gets wrong: a rule that reads the whole run. A line shaped like a
service request that a later measurement's wait shows before its exact request is that
sensor's chatter (``known_chatter``), so an earlier measurement whose wait holds only that
line had no request (R-4.4.6-02 FAIL), not a malformed one (R-4.4.6-01 FAIL). Judged with
the chatter known so far, the first part would FAIL R-4.4.6-01; held until the chatter is
known, it does not, and the measurements after it keep the whole run's order."""

from __future__ import annotations

from conformance.judges import measurements
from conformance.judges.measurements import Measurements, UnreadData
from conformance.protocol.commands import parse_command
from conformance.protocol.timing import CHAR_TIME
from conformance.tool_recorder.records import Attempt, Exchange, Measurement
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.verdicts import Finding, Verdict
from conformance.view.rebuilt_records import rebuild_records
from conformance.view.segments import read_view
from conformance.view.windows import rebuild_windowed, window_starts
from tests.support.bus_of_sensors import ADDRESSES, as_heard, bus_of_sensors, concurrent_round

IDS = (
    "R-4.4.5-01", "R-4.4.5-02", "R-4.4.5-08", "R-4.4.5-09", "R-4.4.6-01", "R-4.4.6-02",
    "R-4.4.6-04", "R-4.4.8-01", "R-4.4.8-03", "R-4.2-02", "R-4.2-03",
)  # fmt: skip


def _chars(text: str, start: float, origin: str) -> list[Event]:
    return [
        Event(EventKind.CHAR, origin, start + k * CHAR_TIME, start + (k + 1) * CHAR_TIME,
              wire=to_wire_7e1(ord(c)))
        for k, c in enumerate(text)
    ]  # fmt: skip


def _exchange(command: str, reply: str, t: float) -> Exchange:
    cmd = _chars(command, t, TOOL)
    rep = _chars(reply, cmd[-1].end + 9e-3, DUT)
    return Exchange(parse_command(command), command, [Attempt(None, cmd, rep, "ok", rep[-1].end)])


def _measurement(command: str, t: float, waited: list[str]) -> Measurement:
    """``command`` answered 'a0053' (5 s, 3 values) at ``t``; ``waited``: the lines its wait
    held, a second apart; then aD0! with its 3 values."""
    start = _exchange(command, "00053\r\n", t)
    m = Measurement(start.command, start, ttt=5, count=3)
    m.reply_end = start.reply_events[-1].end
    at = m.reply_end + 1.0
    for line in waited:
        m.waited_events += _chars(line, at, DUT)
        at = m.waited_events[-1].end + 1.0
    if "0\r\n" in waited:
        m.service_request_end = m.waited_events[-1].end
    m.data.append(_exchange("0D0!", "0+3.14+2.718+1.414\r\n", at))
    return m


def _run() -> list[Measurement]:
    """0M! with a proper request; 0M1! whose wait holds only '0BUSY'; 0M2! with a proper
    request; 0M3! whose wait shows '0BUSY' before its exact request (chatter); 0M4!."""
    waits = [["0\r\n"], ["0BUSY\r\n"], ["0\r\n"], ["0BUSY\r\n", "0\r\n"], ["0\r\n"]]
    names = ["0M!", "0M1!", "0M2!", "0M3!", "0M4!"]
    return [_measurement(c, 20.0 * k, w) for k, (c, w) in enumerate(zip(names, waits, strict=True))]


def _parted(ms: list[Measurement], parts: list[list[Measurement]]) -> list[Finding]:
    fold = Measurements(IDS, "14")
    for part in parts:
        fold.add(part)
    return fold.findings()


def _by_rule(findings: list[Finding]) -> dict[str, Finding]:
    return {f.requirement: f for f in findings}


def test_chatter_found_in_a_later_part_decides_an_earlier_measurement_s_request():
    ms = _run()
    whole = _by_rule(measurements.judge(ms, IDS, "14"))
    assert whole["R-4.4.6-01"].verdict is Verdict.PASS, whole["R-4.4.6-01"]
    assert whole["R-4.4.6-02"].verdict is Verdict.FAIL and "0M1!" in whole["R-4.4.6-02"].detail
    splits = [[ms[:k], ms[k:]] for k in range(len(ms) + 1)] + [[[m] for m in ms]]
    for parts in splits:
        assert _parted(ms, parts) == measurements.judge(ms, IDS, "14"), parts


def test_only_what_may_still_change_is_held():
    """After the part with 0M1!, it and what follows wait for chatter; once 0M3! shows
    '0BUSY' is chatter, everything judged and let go."""
    ms = _run()
    fold = Measurements(IDS, "14")
    fold.add(ms[:1])
    assert fold.held == []
    fold.add(ms[1:3])
    assert [m.start.text for m in fold.held] == ["0M1!", "0M2!"]
    fold.add(ms[3:])
    assert fold.held == []


def test_over_the_windows_of_a_bus_the_findings_are_the_whole_recording_s():
    bus, recorder = bus_of_sensors()
    for _ in range(2):
        concurrent_round(recorder, ADDRESSES)
        for a in ADDRESSES:
            recorder.measure(parse_command(f"{a}M!"))
    events = sorted(as_heard(bus), key=lambda e: e.start)
    view = read_view(events)
    whole = rebuild_records(view)
    assert len(window_starts(view, whole)) >= 4
    fold = Measurements(IDS, "14")
    for part in rebuild_windowed(events, view):
        fold.add(part.measurements)
    expected = measurements.judge(whole.measurements, IDS, "14")
    assert _by_rule(expected)["R-4.4.6-02"].verdict is Verdict.PASS
    assert _by_rule(expected)["R-4.4.8-03"].observed == 2 * 2 * len(ADDRESSES)
    assert fold.findings() == expected


def _unread(command: str, t: float) -> Measurement:
    """``command`` answered '0023' (a two-digit ttt: no count to read), no D command."""
    start = _exchange(command, "0023\r\n", t)
    return Measurement(start.command, start, ttt=None, count=None)


def test_unread_start_replies_of_every_part_are_quoted_together():
    ms = [_unread("0M!", 0.0), *_run()[:2], _unread("0M5!", 200.0)]
    whole = measurements.unread_data(ms, ("R-4.4.8-02",))
    assert whole[0].observed == 2 and "0M5!" in whole[0].detail, whole
    for k in range(len(ms) + 1):
        fold = UnreadData()
        fold.add(ms[:k])
        fold.add(ms[k:])
        assert fold.findings(("R-4.4.8-02",)) == whole
    assert UnreadData().findings(("R-4.4.8-02",)) == measurements.unread_data([], ["R-4.4.8-02"])
