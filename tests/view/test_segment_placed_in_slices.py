"""``Segment.of`` places a one-line 7E1 reply's characters in one slice (``runs._place_all``)
instead of one by one (``runs._place``): the same reply, later and contention, for every
shape of what a sensor sent after a command."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.ports import open_sim, parse_sim
from conformance.sensor.session import SensorSession
from conformance.transcript import DUT, TOOL, Event, EventKind, to_wire_7e1
from conformance.view import runs
from conformance.view.runs import Segment, _place, _place_all
from conformance.view.segments import read_view

CHARS = "a0+1\r\n\x02\x03"  # the ones that steer placing: LF, STX, ETX; and some others
COMMAND = [Event(EventKind.CHAR, TOOL, 0.0, 0.008, to_wire_7e1(ord("!")))]


@st.composite
def heard(draw):
    """Characters after a command ending at 8 ms: replies, late lines, runs far later."""
    out = []
    t = 0.008 + draw(st.sampled_from([0.009, 0.2]))
    for _ in range(draw(st.integers(0, 30))):
        c = draw(st.sampled_from(CHARS))
        out.append(Event(EventKind.CHAR, DUT, t, t + 0.008333, to_wire_7e1(ord(c))))
        t += 0.008333 + draw(st.sampled_from([0.0, 0.0, 0.0, 0.001, 0.3, 1.5]))
    return out


def _one_by_one(binary: bool, events: list[Event]) -> Segment:
    seg = Segment(None, list(COMMAND), binary_reply=binary)
    for e in events:
        _place(seg, e)
    return seg


@settings(max_examples=400, deadline=None)
@given(heard(), st.booleans())
def test_placed_in_slices_as_one_by_one(events, binary):
    seg = Segment(None, list(COMMAND), binary_reply=binary)
    _place_all(seg, events)
    assert seg == _one_by_one(binary, events)


@pytest.mark.parametrize("port", ["sim", "sim://?faults=missing-crlf", "sim://?faults=wrong-crc"])
def test_a_runs_segments_as_one_by_one(port, monkeypatch):
    """The segments of a session's transcript (replies, service requests, contention) are
    the ones placing each character alone gives."""
    opened = open_sim(parse_sim(port))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    session.measurement("M")
    session.measurement("C")
    session.exchange("I")
    session.master.raw("0I!", break_first=False, gap=10e-3)
    transmissions = read_view(opened.link.transcript.events).transmissions
    sliced = [Segment.of(t) for t in transmissions]

    def each(seg, heard):
        for e in heard:
            _place(seg, e)

    monkeypatch.setattr(runs, "_place_all", each)
    assert sliced == [Segment.of(t) for t in transmissions]
    assert sum(len(s.reply) for s in sliced) > 100
