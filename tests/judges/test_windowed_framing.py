"""The sensors' reply framing and bit rate judged a window at a time (issue 22's windowed
judge): ``wire.Framing`` (R-4.1-02, R-4.2-02, R-4.2-03, R-4.3-01) and ``wire.ReplyBitRate``
(R-4.1-01) given a recording's segments in parts, in order, give the whole recording's
findings, detail for detail, wherever the parts are cut; and over the windows
``view.windows`` cuts, each window's segments read from its own events alone.

The cases a wrong merge gets wrong: a segment whose later characters the next segment's
contention cut (judged only once the next part is known), a line sent unasked judged by the
address of a reply in the part before (the last reply's; the last measurement started), and
spacings too short in two parts (counted together, the least of all quoted), with a NaN
spacing opening a part (the least compared in order, not per part). And a tally keeps the
count and the labels a PASS quotes, not every label (``judges.tally.Seen``)."""

from __future__ import annotations

import math

import pytest

from conformance.judges import wire
from conformance.judges.tally import Seen, Tally
from conformance.judges.timing import StampUncertainty
from conformance.protocol.timing import CHAR_TIME
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.verdicts import Finding, Verdict
from conformance.view.runs import Segment
from conformance.view.segments import read_view
from conformance.view.windows import window_events, window_starts
from tests.support.bus_of_sensors import ADDRESSES, as_heard, bus_of_sensors

LOCAL = StampUncertainty(1e-4, local=lambda _start, _end: 1e-4)


def _chars(origin: str, text: str, start: float, spacing: float = CHAR_TIME) -> list[Event]:
    return [
        Event(EventKind.CHAR, origin, start + k * spacing, start + k * spacing + CHAR_TIME,
              wire=to_wire_7e1(ord(c)))
        for k, c in enumerate(text)
    ]  # fmt: skip


def _exchanges(pairs: list[tuple[str, str]], pause: float = 0.1) -> list[Event]:
    """Commands and their replies (``""``: none), ``pause`` apart."""
    events, at = [], 0.0
    for command, reply in pairs:
        sent = _chars(TOOL, command, at)
        heard = _chars(DUT, reply, sent[-1].end + 9e-3)
        events += sent + heard
        at = (heard or sent)[-1].end + pause
    return events


def _framing(segs: list[Segment], parts: list[list[Segment]], u=0.0) -> None:
    """``parts`` (together ``segs``) added in order give ``segs``' findings."""
    fold = wire.Framing(u)
    for part in parts:
        fold.add(part)
    assert fold.findings() == wire.judge_framing(segs, u)


def _rate(segs: list[Segment], parts: list[list[Segment]], u) -> None:
    fold = wire.ReplyBitRate(u)
    for part in parts:
        fold.add(part)
    assert fold.finding() == wire.judge_reply_bit_rate(segs, u)


def _splits(segs: list[Segment]) -> list[list[list[Segment]]]:
    """``segs`` cut in two at every place, and in as many parts as it has."""
    return [[segs[:k], segs[k:]] for k in range(len(segs) + 1)] + [[[s] for s in segs]]


def _by_rule(findings: list[Finding]) -> dict[str, Finding]:
    return {f.requirement: f for f in findings}


def test_later_characters_cut_by_the_next_part_s_contention_are_not_framed():
    """0M!'s reply, then a stray '0' the sensor sent unasked, then 0D0! talked over by its
    '<CR><LF>': the stray is cut, no line of its own (R-4.2-03 stays PASS). Judging a part's
    last segment as uncut fails it with R-4.2-03 on '0'."""
    first = _exchanges([("0M!", "00012\r\n")])
    stray = _chars(DUT, "0", first[-1].end + 0.5)
    command = _chars(TOOL, "0D0!", stray[-1].end + 3e-3)
    met = _chars(DUT, "\r\n", command[1].start)
    reply = _chars(DUT, "0+1\r\n", command[-1].end + 9e-3)
    segs = wire.segments(first + stray + command + met + reply)
    assert len(segs) == 2 and segs[0].later and segs[1].contention
    whole = _by_rule(wire.judge_framing(segs, 0.0))
    assert whole["R-4.2-03"].verdict is Verdict.PASS, whole["R-4.2-03"]
    for parts in _splits(segs):
        _framing(segs, parts)


def test_a_line_sent_unasked_is_judged_by_the_last_reply_of_the_part_before():
    """'1<CR><LF>' after a command nobody answered, the last reply being sensor 0's: R-4.3-01
    FAILs it as the whole run does, in whichever part the line falls."""
    events = _exchanges([("0I!", "014CONFORM EMU001100\r\n"), ("2M!", "")])
    events += _chars(DUT, "1\r\n", events[-1].end + 1.0)
    segs = wire.segments(events)
    assert len(segs) == 2 and not segs[1].reply and segs[1].later
    assert _by_rule(wire.judge_framing(segs, 0.0))["R-4.3-01"].verdict is Verdict.FAIL
    for parts in _splits(segs):
        _framing(segs, parts)


def test_a_service_request_may_name_the_measurement_started_in_the_part_before():
    """0C! started, zI! answered for 'z', then '0<CR><LF>' unasked: the measurement's service
    request (PASS), which a part forgetting the started measurement FAILs against 'z'."""
    events = _exchanges([("0C!", "000320\r\n"), ("zI!", "z14CONFORM EMU001100SN0001\r\n")])
    events += _chars(DUT, "0\r\n", events[-1].end + 1.9)
    segs = wire.segments(events)
    assert _by_rule(wire.judge_framing(segs, 0.0))["R-4.3-01"].verdict is Verdict.PASS
    for parts in _splits(segs):
        _framing(segs, parts)


def _fast_replies() -> list[Segment]:
    """Four replies; the first and the third sent fast (7.9 ms and 7.8 ms a character)."""
    events, at = [], 0.0
    for command, spacing in (("0D0!", 7.9e-3), ("0D1!", CHAR_TIME), ("0D2!", 7.8e-3)) * 2:
        sent = _chars(TOOL, command, at)
        heard = _chars(DUT, "0+1.25+3.5\r\n", sent[-1].end + 9e-3, spacing)
        events += sent + heard
        at = heard[-1].end + 0.1
    return wire.segments(events)


@pytest.mark.parametrize("u", [1e-6, LOCAL], ids=["capture", "host-stamped"])
def test_too_short_spacings_in_two_parts_are_counted_together(u):
    segs = _fast_replies()
    whole = wire.judge_reply_bit_rate(segs, u)
    assert whole.verdict is Verdict.FAIL, whole
    assert "0D2!" in " ".join(whole.evidence)  # the least of both parts
    for parts in _splits(segs):
        _rate(segs, parts, u)


def _replies(spacings: list[tuple[str, float]]) -> list[Segment]:
    """One reply a command, its characters ``spacing`` apart."""
    events, at = [], 0.0
    for command, spacing in spacings:
        sent = _chars(TOOL, command, at)
        heard = _chars(DUT, "0+1.25+3.5\r\n", sent[-1].end + 9e-3, spacing)
        events += sent + heard
        at = heard[-1].end + 0.1
    return wire.segments(events)


def test_a_part_opening_with_a_nan_spacing_is_compared_with_the_least_before():
    """A stamp no clock gives (NaN) opening the second reply, whose other characters come
    7.7 ms apart: they are compared with the first reply's least (7.9 ms), as one pass over
    the whole run compares them, and are the least; a part's own least would start at the
    NaN and never move, and the merge keep 7.9 ms."""
    segs = _replies([("0D0!", 7.9e-3), ("0D1!", 7.7e-3)])
    reply = segs[1].reply
    reply[0] = Event(EventKind.CHAR, DUT, math.nan, math.nan, wire=reply[0].wire)
    whole = wire.judge_reply_bit_rate(segs, 1e-6)
    assert "0D1!" in " ".join(whole.evidence), whole
    for u in (1e-6, LOCAL):
        for parts in _splits(segs):
            _rate(segs, parts, u)


def test_the_least_spacing_surely_too_short_is_the_least_of_every_part():
    """Host-stamped: 0D0! at 7.8 ms and 0D1! at 7.9 ms a character are surely too fast;
    0D9!'s 7.0 ms is the least spacing but falls where the stamps are irregular (5 ms),
    so not surely fast. The FAIL quotes 0D0!, the least of those surely too short over
    all parts, not the last part's."""
    segs = _replies([("0D0!", 7.8e-3), ("0D1!", 7.9e-3), ("0D9!", 7.0e-3)])
    irregular = segs[2].reply[0].start
    stamps = StampUncertainty(1e-4, local=lambda s, _e: 5e-3 if s >= irregular else 1e-4)
    whole = wire.judge_reply_bit_rate(segs, stamps)
    assert whole.verdict is Verdict.FAIL and "0D0!" in " ".join(whole.evidence), whole
    for parts in _splits(segs):
        _rate(segs, parts, stamps)


def _segments(events: list[Event]) -> list[Segment]:
    return [Segment.of(t) for t in read_view(events).transmissions]


def test_over_the_windows_of_a_bus_the_findings_are_the_whole_recording_s():
    bus, recorder = bus_of_sensors()
    for a in ADDRESSES * 2:
        recorder.identify(a)
    events = sorted(as_heard(bus), key=lambda e: e.start)
    whole = read_view(events)
    windows = list(window_events(events, whole, window_starts(whole)))
    assert len(windows) >= 6
    framing, rate = wire.Framing(1e-6), wire.ReplyBitRate(1e-6)
    for window in windows:
        segs = _segments(window)
        framing.add(segs)
        rate.add(segs)
    segs = _segments(events)
    assert framing.findings() == wire.judge_framing(segs, 1e-6)
    assert rate.finding() == wire.judge_reply_bit_rate(segs, 1e-6)


def test_a_tally_keeps_the_count_and_the_labels_a_pass_quotes():
    """10,000 observations of 1,000 distinct labels: the PASS detail is the one every label
    made (each distinct once, in first-seen order, cut at 160 characters), from a few."""
    labels = [f"reply to {k}D0!" for k in range(1000)] * 10
    tally = Tally(("R-4.2-03",))
    for where in labels:
        tally.observe(where)
    (found,) = tally.findings()
    checked = ", ".join(dict.fromkeys(labels))
    assert found.detail == f"conforms (10000 checked: {checked[:157]}...)"
    assert found.observed == 10000
    seen = tally.observed["R-4.2-03"]
    assert isinstance(seen, Seen) and len(seen.labels) < 20


@pytest.mark.parametrize("n", [1, 2, 7, 8, 9, 40])
def test_a_short_list_of_labels_is_quoted_whole_or_cut_as_before(n):
    labels = [f"r{k:05d}!!!!!!!!!!" for k in range(n)]  # 16 characters, 18 with ', '
    tally = Tally(("R-4.2-03",))
    for where in labels + labels[:1]:
        tally.observe(where)
    checked = ", ".join(dict.fromkeys(labels))
    if len(checked) > 160:
        checked = checked[:157] + "..."
    assert tally.findings()[0].detail == f"conforms ({n + 1} checked: {checked})"
