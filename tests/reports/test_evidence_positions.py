"""The locator's positions (``reports.evidence.Positions``): a transcript in time order is
searched by bisection over an array of start times instead of a dict from every event to its
first index (an hour's capture: 32 MB held by every report of a passive judgement). Both
must give every event the same position: the first index of an event equal to it."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from conformance.reports.evidence import Positions
from conformance.transcript import BUS, DUT, TOOL, Event, EventKind

# few distinct stamps and texts: equal events at several indices, and events that share a
# start but differ, are common
stamp = st.sampled_from([0.0, 0.001, 0.001, 0.0125, 0.02, 1.5])
event = st.builds(
    Event,
    st.sampled_from([EventKind.CHAR, EventKind.BREAK, EventKind.NOTE]),
    st.sampled_from([TOOL, DUT, BUS]),
    stamp,
    stamp,
    wire=st.sampled_from([0x30, 0x21, 0x0A]),
)


def first_index(events: list[Event]) -> dict[Event, int]:
    """The dict the positions stood in before: every event to its first index."""
    found: dict[Event, int] = {}
    for i, e in enumerate(events):
        found.setdefault(e, i)
    return found


def asked(events: list[Event], others: list[Event]) -> list[Event]:
    return [*events, *others, *(Event(e.kind, e.origin, e.start, e.end, e.wire) for e in events)]


@given(st.lists(event, max_size=30), st.lists(event, max_size=5), st.booleans())
def test_positions_are_the_first_index_of_an_equal_event(events, others, in_order):
    if in_order:
        events.sort(key=lambda e: e.start)
    positions = Positions(events)
    positions.index()
    reference = first_index(events)
    query = asked(events, others)
    assert list(positions.of(query)) == [reference[e] for e in query if e in reference]
    if in_order:  # searched by bisection, no dict kept
        assert positions.starts is not None and not positions.first


@given(st.lists(event, max_size=20), st.lists(event, max_size=20))
def test_positions_follow_a_growing_transcript(first, then):
    """Indexed as the list grows: in order so far, then perhaps not (the dict from there)."""
    first.sort(key=lambda e: e.start)
    events = list(first)
    positions = Positions(events)
    positions.index()
    events += then
    positions.index()
    reference = first_index(events)
    query = asked(events, [])
    assert list(positions.of(query)) == [reference[e] for e in query if e in reference]


def test_a_time_ordered_transcript_keeps_no_dict():
    events = [Event(EventKind.CHAR, BUS, i * 0.01, i * 0.01 + 0.008, 0x30) for i in range(100)]
    positions = Positions(events)
    positions.index()
    assert positions.starts is not None and not positions.first
    assert list(positions.of([events[57], events[3]])) == [57, 3]


def test_a_start_that_is_no_number_falls_back_to_the_dict():
    nan = float("nan")
    events = [Event(EventKind.CHAR, BUS, 0.0, 0.1), Event(EventKind.CHAR, BUS, nan, nan)]
    positions = Positions(events)
    positions.index()
    assert positions.starts is None
    assert list(positions.of(events)) == [0, 1]
