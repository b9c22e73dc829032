"""The capture half of a fault-matrix row reads its columns without per-item Python objects it
did not need (issue 22, replay27), each pinned here against the reading it replaces:

- the export's wire columns find the breaks by ``list.count``/``list.index`` and read the
  bytes by ``np.fromiter``, where an object array of kinds was compared twice and a list of
  bytes made into an array (:func:`~conformance.capture.levels.wire_columns`);
- the recorded sensor's back-to-back flags are four shared pairs, not a tuple a reply
  (:func:`~conformance.replay.sensor._pairs`), and its tool events' kinds come from the
  decoder's own events alone (:func:`~conformance.replay.sensor._tool_kinds`).
"""

from __future__ import annotations

from itertools import compress

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.capture import decode_capture
from conformance.capture.export import TOOL_CHANNEL, export_events
from conformance.capture.levels import _places, wire_columns
from conformance.replay.sensor import _PAIRS, RecordedSensor, _pairs, _tool_kinds
from conformance.transcript import DUT, TOOL, Event, EventKind
from tests.support.capture_digest import traffic

KINDS = (EventKind.CHAR, EventKind.BREAK, EventKind.NOTE)


def columns_as_before(events: list[Event]) -> tuple[list[Event], list, list, list] | None:
    """What ``wire_columns`` gave before: the sorted wire events, then their bytes and the
    character and break masks read from object arrays (None where it declined)."""
    wire = [e for e in events if e.kind in (EventKind.CHAR, EventKind.BREAK)]
    if (
        not wire
        or {type(e.start) for e in wire} != {float}
        or {type(e.end) for e in wire} != {float}
    ):
        return None
    wire = sorted(wire, key=lambda e: e.start)
    if {type(e.kind) for e in wire} != {EventKind}:
        return None
    kinds = np.array([e.kind for e in wire], dtype=object)
    wires = np.array([e.wire for e in wire], dtype=np.int64) & 0xFF
    is_char, is_break = kinds == EventKind.CHAR, kinds == EventKind.BREAK
    return wire, wires.tolist(), is_char.tolist(), is_break.tolist()


def columns_now(events: list[Event]) -> tuple[list[Event], list, list, list] | None:
    found = wire_columns(events)
    if found is None:
        return None
    return found.events, found.wire.tolist(), found.is_char.tolist(), found.is_break.tolist()


@settings(max_examples=300, deadline=None)
@given(st.lists(st.sampled_from(KINDS), max_size=60), st.sampled_from(KINDS))
def test_places_are_where_the_list_holds_the_value(items, value):
    expected = np.array(items, dtype=object) == value if items else np.zeros(0, dtype=bool)
    assert _places(items, value).tolist() == list(expected)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from(KINDS),
            st.floats(0.0, 2.0, allow_nan=False),
            st.integers(0, 300),
            st.sampled_from([TOOL, DUT]),
        ),
        max_size=40,
    )
)
def test_wire_columns_read_as_the_object_arrays_did(drawn):
    """Characters, breaks and notes in any order, wire values past a byte: the same events,
    bytes and masks as the object-array reading."""
    events = [Event(kind, origin, s, s + 1 / 120, wire) for kind, s, wire, origin in drawn]
    assert columns_now(events) == columns_as_before(events)


def test_wire_columns_of_a_busy_bus_with_breaks():
    events = traffic(3, seconds=5.0)
    now = columns_now(events)
    assert now is not None and any(now[3]) and not all(now[3])
    assert now == columns_as_before(events)


def test_a_kind_that_is_only_equal_to_a_member_is_declined():
    """A kind given as its plain string (EventKind is a StrEnum: ``"break" ==
    EventKind.BREAK``) is declined, as before: ``list.count`` would count it by ``==``."""
    events = traffic(1, seconds=1.0)
    odd = Event("break", TOOL, 0.001, 0.02)  # type: ignore[arg-type]
    assert wire_columns([odd, *events]) is None


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.booleans(), st.booleans()), max_size=50))
def test_pairs_are_the_zipped_flags_shared(flags):
    first = np.array([f for f, _ in flags], dtype=bool)
    second = np.array([s for _, s in flags], dtype=bool)
    made = _pairs(first, second)
    assert made == list(zip(first.tolist(), second.tolist(), strict=True))
    assert all(any(p is q for q in _PAIRS) for p in made)


def test_tool_kinds_of_a_decoded_capture_are_the_compressed_kinds(tmp_path):
    """A capture with the tool's breaks on its TX channel: the tool events' kinds as every
    column's kind compressed to the tool's, and as the events the replay would make."""
    path = tmp_path / "run.sr"
    export_events(traffic(5, seconds=8.0), str(path), "sr", tool_channel=True)
    wire = decode_capture(str(path), tx_channel=TOOL_CHANNEL, columns=True).columns
    assert wire is not None and wire.made
    is_tool = np.array([o == TOOL for o in wire.origin], dtype=bool)
    count = int(is_tool.sum())
    kinds = _tool_kinds(wire, is_tool, count)
    assert kinds == list(compress(wire.kinds(), is_tool.tolist()))
    assert EventKind.BREAK in kinds
    sensor = RecordedSensor.of_columns(wire)
    assert sensor is not None
    assert sensor._tool_kind == [e.kind for e in sensor.tool]
