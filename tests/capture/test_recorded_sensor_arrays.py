"""A recording's replay worked out over arrays (issue 22, the eleventh matrix round):
:class:`RecordedSensor` takes the tool's events, the reply characters, how many tool events
each reply waits for and whether it goes back to back from arrays when the recording is in
order with no NaN stamp. Pinned here against the event-by-event reading it replaces (sorted
by start then end, ``bisect_left`` over the tool's starts, :func:`_touching_each`), on decoded
captures and on awkward event lists: ties, overlaps, unsorted, NaN and infinite stamps.
"""

from __future__ import annotations

import math
from bisect import bisect_left

from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.capture import decode_capture
from conformance.capture.columns import WireColumns
from conformance.capture.export import TOOL_CHANNEL, export_events
from conformance.replay import sensor as sensor_module
from conformance.replay.sensor import _START_END, RecordedSensor, _touching_each, _worked_out
from conformance.sim.bus import SENSOR_BREAK
from conformance.transcript import DUT, TOOL, Event, EventKind
from tests.support.capture_digest import traffic


def played(e: Event) -> bool:
    """A sensor's event the replay plays: a character, or a break of the sensor's (a sim
    bus's, text :data:`SENSOR_BREAK`; a decoded capture's, origin DUT: spacing the
    recorder's TX channel does not show)."""
    return e.kind is EventKind.CHAR or (
        e.kind is EventKind.BREAK and (e.text == SENSOR_BREAK or e.origin == DUT)
    )


def event_by_event(events: list[Event]) -> tuple[list, list, list[int], list, list, list]:
    """What :class:`RecordedSensor` worked out before the arrays, step by step, and what its
    replay reads of each reply (start, byte, length; floats by repr: NaN too)."""
    wire = sorted((e for e in events if e.kind is not EventKind.NOTE), key=_START_END)
    tool = [e for e in wire if e.origin == TOOL]
    replies = [e for e in wire if e.origin != TOOL and played(e)]
    starts = [e.start for e in tool]
    needs = [bisect_left(starts, r.start) for r in replies]
    read = [(repr(r.start), r.wire, repr(r.end - r.start)) for r in replies]
    breaks = [i for i, r in enumerate(replies) if r.kind is EventKind.BREAK]
    return tool, replies, needs, _touching_each(tool, replies, needs), read, breaks


def state(sensor: RecordedSensor) -> tuple[list, list, list[int], list, list, list]:
    starts, wires, lengths = sensor._reply_start, sensor._reply_wire, sensor._reply_length
    read = [(repr(s), w, repr(n)) for s, w, n in zip(starts, wires, lengths, strict=True)]
    breaks = sorted(sensor._breaks)  # which replies it plays as the sensor's breaks
    return sensor.tool, sensor.replies, sensor._needs, sensor._touching, read, breaks


def test_a_decoded_capture_takes_the_arrays_and_gives_the_same(tmp_path):
    """A capture of a busy, hostile bus decoded with its TX channel: in order (the arrays
    are taken, not the fallback) and the same lists, needs and back-to-back flags."""
    path = tmp_path / "run.sr"
    export_events(traffic(5, seconds=20.0), str(path), "sr", tool_channel=True)
    events = decode_capture(str(path), tx_channel=TOOL_CHANNEL).events
    found = _worked_out([e for e in events if e.kind is not EventKind.NOTE])
    assert found is not None
    assert len(found[1]) > 500 and any(t for t, _ in found[3]) and any(p for _, p in found[3])
    assert list(found[:4]) == list(event_by_event(events))[:4]
    assert state(RecordedSensor(events)) == event_by_event(events)


def test_uncertain_stamps_touch_as_before():
    """Stamps with a capture's uncertainty: replies back to back within it."""
    events = [
        Event(e.kind, e.origin, e.start, e.end, e.wire, e.text, u)
        for e, u in zip(traffic(8, seconds=5.0), [0.0, 2e-3, 1e-5] * 10_000, strict=False)
    ]
    events.sort(key=_START_END)
    assert _worked_out(events) is not None
    assert state(RecordedSensor(events)) == event_by_event(events)


STAMPS = st.one_of(
    st.sampled_from([0.0, 0.5, 1.0, 1.0 + 1e-9, 2.0]),
    st.floats(-1.0, 3.0),
    st.sampled_from([math.nan, math.inf, -math.inf]),
)


# The strategies a recording draws from, made once: made inside ``recordings`` (a new
# ``sampled_from`` of a list, a new ``one_of`` per event) hypothesis validated and labelled
# each anew on every draw, which was most of these tests' time (issue 22, ci7: 0.18 s of 0.2 a
# example). The same choices, in the same order, drawn from the same strategies.
#: an event's end: a stamp, or None for one character time (1/120 s) after its start
ENDS = st.one_of(STAMPS, st.none())
KINDS = st.sampled_from([EventKind.CHAR, EventKind.CHAR, EventKind.BREAK])
ORIGINS = st.sampled_from([TOOL, DUT, "bus"])
UNCERTAINTIES = st.sampled_from([0.0, 1e-3, 0.25, math.nan])
WIRES = st.integers(0, 255)


@st.composite
def recordings(draw) -> list[Event]:
    """Characters and breaks of both sides, often tied or overlapping, some NaN or
    infinite, in order or not."""
    out = []
    for _ in range(draw(st.integers(0, 30))):
        start = draw(STAMPS)
        end = draw(ENDS)
        end = start + 1 / 120 if end is None else end
        kind, origin, u = draw(KINDS), draw(ORIGINS), draw(UNCERTAINTIES)
        out.append(Event(kind, origin, start, end, draw(WIRES), "", u))
    if draw(st.booleans()):
        out.sort(key=_START_END)
    if out and draw(st.booleans()):
        out.insert(draw(st.integers(0, len(out))), Event(EventKind.NOTE, TOOL, 0.0, 0.0))
    return out


@settings(max_examples=400, deadline=None)
@given(recordings())
def test_any_recording_is_worked_out_as_event_by_event(events):
    assert state(RecordedSensor(events)) == event_by_event(events)


def test_the_arrays_refuse_what_they_could_read_apart():
    """Out of order or a NaN stamp: None (the event-by-event reading is taken)."""
    a = Event(EventKind.CHAR, TOOL, 1.0, 1.1, 0x30)
    b = Event(EventKind.CHAR, DUT, 0.5, 0.6, 0x31)
    assert _worked_out([a, b]) is None
    assert _worked_out([b, a]) is not None
    assert _worked_out([Event(EventKind.CHAR, DUT, math.nan, 0.6, 0x31), a]) is None
    tie = Event(EventKind.CHAR, DUT, 1.0, 1.05, 0x31)
    assert _worked_out([a, tie]) is None  # same start, the later end first
    assert _worked_out([tie, a]) is not None


def test_the_module_sorts_only_when_it_must(monkeypatch):
    """A recording in order is not sorted (the arrays read it as it is)."""
    sorts = []
    monkeypatch.setattr(sensor_module, "_START_END", lambda e: sorts.append(e) or (e.start, e.end))
    events = sorted(traffic(3, seconds=2.0), key=_START_END)
    RecordedSensor(events)
    assert sorts == []
    RecordedSensor(events[::-1])
    assert len(sorts) == len(events)


def test_a_reply_starting_with_the_one_before_does_not_follow_it():
    """Two reply characters starting together: the second does not go back to back from
    the first (only a reply that started before counts), as event by event."""
    events = [
        Event(EventKind.CHAR, TOOL, 0.0, 0.4, 0x30),
        Event(EventKind.CHAR, DUT, 0.5, 0.5, 0x31),
        Event(EventKind.CHAR, DUT, 0.5, 0.6, 0x32),
    ]
    assert _worked_out(events) is not None
    assert state(RecordedSensor(events)) == event_by_event(events)
    assert RecordedSensor(events)._touching == [(False, False), (False, False)]


def as_columns(events: list[Event]) -> WireColumns:
    """``events`` (notes left out) as a decoder keeps them in columns: a character with no
    text, no duration uncertainty and the common uncertainty as four entries, anything
    else whole."""
    wire = [e for e in events if e.kind is not EventKind.NOTE]
    common = wire[0].uncertainty if wire else 0.0
    cols = WireColumns(common)
    for e in wire:
        if (
            e.kind is EventKind.CHAR
            and e.text == ""
            and e.duration_uncertainty is None
            and e.uncertainty is common
        ):
            cols.start.append(e.start)
            cols.end.append(e.end)
            cols.wire.append(e.wire)
            cols.origin.append(e.origin)
        else:
            cols.add_made(e)
    return cols


@settings(max_examples=400, deadline=None)
@given(recordings())
def test_columns_give_the_recorded_sensor_of_the_events(events):
    """The thirteenth matrix round: a decoded capture's columns give the sensor its events
    give (the same tool events, reply characters, needs, back-to-back flags and what the
    replay reads of each reply), or None exactly where the events are not read as arrays."""
    cols = as_columns(events)
    assert cols.events() == [e for e in events if e.kind is not EventKind.NOTE]
    sensor = RecordedSensor.of_columns(cols)
    wire = [e for e in events if e.kind is not EventKind.NOTE]
    assert (sensor is None) == (_worked_out(wire) is None)
    if sensor is not None:
        assert state(sensor) == event_by_event(events) == state(RecordedSensor(events))


def test_a_decoded_captures_columns_give_its_sensor(tmp_path):
    """A hostile bus's capture decoded into columns: the sensor its events give, the
    reply characters never made (until asked for)."""
    path = tmp_path / "run.sr"
    export_events(traffic(7, seconds=20.0), str(path), "sr", tool_channel=True)
    decoded = decode_capture(str(path), tx_channel=TOOL_CHANNEL, columns=True)
    assert decoded.columns is not None
    sensor = RecordedSensor.of_columns(decoded.columns)
    assert sensor is not None and sensor._replies is None
    events = decoded.columns.events()
    assert len(sensor._reply_start) > 500
    assert state(sensor) == event_by_event(events) == state(RecordedSensor(events))


def listed_columns(cols: WireColumns) -> tuple[list, list, list[int]]:
    """What ``of_columns`` read before matrix24: every column's uncertainty and kind listed
    (:meth:`WireColumns.uncertainties`, :meth:`WireColumns.kinds`), a character or a break
    the replay plays, the breaks among the decoder's own events."""
    kinds = cols.kinds()
    is_char = [k is EventKind.CHAR for k in kinds]
    breaks = [i for i, m in cols.made.items() if m.kind is not EventKind.CHAR and played(m)]
    for i in breaks:
        is_char[i] = True
    return [repr(u) for u in cols.uncertainties()], is_char, breaks


@settings(max_examples=300, deadline=None)
@given(recordings())
def test_made_columns_are_the_listed_ones(events):
    """matrix24: the columns' uncertainties, characters and breaks worked out from the
    decoder's own events alone are those listed column by column (NaN by repr)."""
    cols = as_columns(events)
    u, is_char, breaks = sensor_module._made_columns(cols, len(cols))
    assert ([repr(x) for x in u.tolist()], is_char.tolist(), breaks) == listed_columns(cols)
