"""The locator's positions (``reports.evidence.Positions``): a transcript in time order is
searched by bisection over the events by their start times instead of a dict from every event to its
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
        assert positions.ordered and not positions.first


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
    assert positions.ordered and not positions.first
    assert list(positions.of([events[57], events[3]])) == [57, 3]


def test_a_start_that_is_no_number_falls_back_to_the_dict():
    nan = float("nan")
    events = [Event(EventKind.CHAR, BUS, 0.0, 0.1), Event(EventKind.CHAR, BUS, nan, nan)]
    positions = Positions(events)
    positions.index()
    assert not positions.ordered
    assert list(positions.of(events)) == [0, 1]


def test_indexing_a_time_ordered_transcript_holds_nothing_an_event():
    """Issue 22: the index of an hour's capture (357,000 events) was an array of every start
    (2.9 MB) filled from two lists of them (5.7 MB more at its peak); the events are their own
    index now. 100,000 events: ~1.6 MB traced at the peak before, a few hundred bytes now."""
    import tracemalloc

    events = [Event(EventKind.CHAR, BUS, i * 0.01, i * 0.01 + 0.008, 0x30) for i in range(100_000)]
    positions = Positions(events)
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        positions.index()
        held, peak = (m - before for m in tracemalloc.get_traced_memory())
    finally:
        tracemalloc.stop()
    assert positions.ordered and not positions.first
    assert peak < 20_000 and held < 20_000, (held, peak)
    assert list(positions.of([events[99_999], events[0], events[41_234]])) == [99_999, 0, 41_234]
