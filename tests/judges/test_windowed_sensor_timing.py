"""The sensors' reply timing judged a window at a time (issue 22's windowed judge): each
window's segments, cut from a view of its own events alone (``view.windows``), added in
order to ``wire.ResponseStarts`` (R-7.0-09, R-7.0-10) and ``wire.ReplyGaps`` (R-7.0-12,
R-7.0-01) give the findings of the whole recording's segments, detail for detail, for a
capture's flat stamp uncertainty and for a host-stamped recording's local one.

The cases a wrong merge gets wrong: a late reply in the first window among timely ones in
the others (the worst value and the count of replies over all windows), gaps leaning on the
tolerance in two windows (R-7.0-01 quotes both and counts two) and the count of every gap."""

from __future__ import annotations

from dataclasses import replace

import pytest

from conformance.judges.timing import StampUncertainty
from conformance.judges.wire import ReplyGaps, ResponseStarts, judge_gaps, judge_response_start
from conformance.transcript import Event
from conformance.verdicts import Finding, Verdict
from conformance.view.runs import Segment, Segments
from conformance.view.segments import read_view
from conformance.view.windows import window_events, window_starts
from tests.support.bus_of_sensors import ADDRESSES, as_heard, bus_of_sensors

FLAT = 1e-6  # a 1 MHz capture's stamps
#: a host-stamped transcript's: the stamps' own doubt and a (flat) local figure
LOCAL = StampUncertainty(1e-4, local=lambda _start, _end: 1e-4)


def _segments(events: list[Event]) -> list[Segment]:
    return [Segment.of(t) for t in read_view(events).transmissions]


def _whole(events: list[Event], u) -> list[Finding]:
    segs = Segments(_segments(events))  # judge_gaps' one pass (a plain list is cut in parts)
    return [*judge_response_start(segs, u), *judge_gaps(segs, u)]


def _windowed(events: list[Event], u) -> list[Finding]:
    whole = read_view(events)
    windows = list(window_events(events, whole, window_starts(whole)))
    assert len(windows) >= 6
    starts, gaps = ResponseStarts(u), ReplyGaps(u)
    for window in windows:
        segs = _segments(window)
        starts.add(segs)
        gaps.add(segs)
    return [*starts.findings(), *gaps.findings()]


def _by_rule(findings: list[Finding]) -> dict[str, Finding]:
    return {f.requirement: f for f in findings}


def _identified_twice() -> tuple[list[Event], list]:
    """Each sensor identified twice (a window each); the events and their view's
    transmissions."""
    bus, recorder = bus_of_sensors()
    for a in ADDRESSES * 2:
        recorder.identify(a)
    events = sorted(as_heard(bus), key=lambda e: e.start)
    return events, read_view(events).transmissions


def _later(events: list[Event], moved: list[Event], by: float) -> list[Event]:
    ids = {id(e) for e in moved}
    return [replace(e, start=e.start + by, end=e.end + by) if id(e) in ids else e for e in events]


@pytest.mark.parametrize("u", [FLAT, LOCAL], ids=["capture", "host-stamped"])
def test_a_late_reply_in_the_first_window_is_the_whole_runs(u):
    events, sent = _identified_twice()
    events = _later(events, sent[0].heard, 0.007)  # 9 ms -> 16 ms: past 15.40 ms
    expected = _by_rule(_whole(events, u))
    assert expected["R-7.0-10"].verdict is not Verdict.PASS
    assert "6 replies" in expected["R-7.0-10"].detail, expected["R-7.0-10"].detail
    assert _windowed(events, u) == _whole(events, u)


@pytest.mark.parametrize("u", [FLAT, LOCAL], ids=["capture", "host-stamped"])
def test_gaps_leaning_on_the_tolerance_in_two_windows_are_counted_together(u):
    """A 1.80 ms gap before the last 5 characters of the first and the last reply."""
    events, sent = _identified_twice()
    events = _later(events, sent[0].heard[-5:] + sent[-1].heard[-5:], 0.0018)
    whole = _by_rule(_whole(events, u))
    if u is FLAT:
        assert whole["R-7.0-01"].verdict is Verdict.FAIL
        assert "(2 such gap(s))" in whole["R-7.0-01"].detail
    assert _windowed(events, u) == _whole(events, u)


@pytest.mark.parametrize("u", [FLAT, LOCAL], ids=["capture", "host-stamped"])
def test_every_gap_of_every_window_is_counted(u):
    events, _sent = _identified_twice()
    expected = _by_rule(_whole(events, u))
    assert expected["R-7.0-01"].verdict is Verdict.PASS
    assert _windowed(events, u) == _whole(events, u)
