"""``Segment.of`` places a one-line 7E1 reply's characters in one slice (``runs._place_all``)
instead of one by one (``runs._place``): the same reply, later and contention, for every
shape of what a sensor sent after a command, its LF found in the wire bytes where each wire
is one (``runs._first_lf``, matrix14) and character by character where one is not."""

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
from tests.support.hand_events import chars

CHARS = "a0+1\r\n\x02\x03"  # the ones that steer placing: LF, STX, ETX; and some others
COMMAND = [Event(EventKind.CHAR, TOOL, 0.0, 0.008, to_wire_7e1(ord("!")))]


@st.composite
def heard(draw, wide: bool = False):
    """Characters after a command ending at 8 ms: replies, late lines, runs far later."""
    out = []
    t = 0.008 + draw(st.sampled_from([0.009, 0.2]))
    for _ in range(draw(st.integers(0, 30))):
        c = draw(st.sampled_from(CHARS))
        wire = to_wire_7e1(ord(c))
        if wide and draw(st.integers(0, 9)) == 0:
            wire |= 0x100  # no byte (a made-up event): the reply's LF found without bytes
        out.append(Event(EventKind.CHAR, DUT, t, t + 0.008333, wire))
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


@settings(max_examples=300, deadline=None)
@given(heard(wide=True))
def test_placed_in_slices_as_one_by_one_where_a_wire_is_no_byte(events):
    """(a 7E1 reply: an 8N1 packet's bytes are read by ``decode_8n1``, which takes bytes)"""
    seg = Segment(None, list(COMMAND))
    _place_all(seg, events)
    assert seg == _one_by_one(False, events)


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


def _old_of(t) -> Segment:
    """``Segment.of`` before matrix14 (is_command asked twice, a set of the contention made
    even when it was empty), word for word."""
    cmd = t.command if t.is_command else None
    seg = Segment(
        t.break_event,
        list(t.chars),
        text=t.text,
        binary_reply=cmd is not None and cmd.kind is runs.Kind.BINARY_DATA,
    )
    heard = t.heard
    if not t.is_command:
        seg.contention.extend(heard)
        return seg
    clash = {id(e) for e in t.contention}
    if not clash:
        _place_all(seg, heard)
        return seg
    for e in heard:
        if id(e) in clash:
            seg.contention.append(e)
        else:
            runs._place(seg, e)
    return seg


@pytest.mark.parametrize(
    "faults", ["", "response-too-early", "chatter-before-service-request", "stray-after-line-end"]
)
def test_segments_as_before(faults):
    """Every transmission of a session's run (contention, raw probes that are no command,
    binary packets) makes the segment the old ``Segment.of`` made."""
    opened = open_sim(parse_sim(f"sim://?faults={faults}" if faults else "sim"))
    session = SensorSession(opened.link, declaration=opened.declaration)
    session.discover()
    for code in ("M", "C", "HB"):
        session.measurement(code)
    session.exchange("I")
    session.master.raw("0I", break_first=True)  # no "!": not a command
    session.master.raw("0I!", break_first=True, gap=10e-3)
    transmissions = read_view(opened.link.transcript.events).transmissions
    made = [Segment.of(t) for t in transmissions]
    assert made == [_old_of(t) for t in transmissions]
    assert any(not t.is_command for t in transmissions)


def test_segment_with_contention_as_before():
    """A reply begun while the command went out: its characters are contention, as before."""
    events = chars(TOOL, "0M!", 0.0)
    events += chars(DUT, "00011\r\n", events[1].start)  # met the command's second frame
    events.sort(key=lambda e: e.start)
    events += chars(TOOL, "0D0!", events[-1].end + 0.02)
    events += chars(DUT, "0+1\r\n", events[-1].end + 0.009)
    transmissions = read_view(events).transmissions
    made = [Segment.of(t) for t in transmissions]
    assert made == [_old_of(t) for t in transmissions]
    assert made[0].contention and not made[1].contention and made[1].reply
