"""A recording already in time order is read as it is, not sorted into a copy (issue 22:
loading an hour's busy capture made a key tuple an event to sort it by start and end for the
direction inference, ~25 MB at the peak of the loading, and a copy with a list of keys to sort
it by start for the view). ``direction.by_start_and_end`` and ``segments._by_start`` give the
list itself exactly when the sort would leave it as it is, else the sorted copy as before:
the same events in the same order, for lists with ties, NaN stamps and notes."""

from __future__ import annotations

import math
import tracemalloc

from hypothesis import given
from hypothesis import strategies as st

from conformance.transcript import BUS, DUT, TOOL, Event, EventKind
from conformance.transcript import in_start_order as _by_start
from conformance.view.direction import by_start_and_end, infer_directions, iter_directions
from conformance.view.segments import read_view

stamp = st.sampled_from([0.0, 0.001, 0.001, 0.0125, 0.02, 1.5, math.nan, -0.0])
event = st.builds(
    Event,
    st.sampled_from([EventKind.CHAR, EventKind.CHAR, EventKind.BREAK, EventKind.NOTE]),
    st.sampled_from([TOOL, DUT, BUS]),
    stamp,
    stamp,
    wire=st.sampled_from([0x30, 0x21, 0x0A]),
)


def _sorted_by_start_and_end(events):
    return sorted((e for e in events if e.kind is not EventKind.NOTE),
                  key=lambda e: (e.start, e.end))  # fmt: skip


def _sorted_by_start(events):
    return sorted([e for e in events if e.kind is not EventKind.NOTE], key=lambda e: e.start)


def _same(a: list[Event], b: list[Event]) -> bool:
    return len(a) == len(b) and all(x is y for x, y in zip(a, b, strict=True))


@given(st.lists(event, max_size=25), st.booleans())
def test_the_sorts_order_whether_or_not_a_copy_is_made(events, presort):
    if presort:  # in order (notes aside): read as it is unless a NaN or a note says no
        events = _sorted_by_start_and_end(events) + [e for e in events if e.kind is EventKind.NOTE]
    for mine, reference in ((by_start_and_end, _sorted_by_start_and_end),
                            (_by_start, _sorted_by_start)):  # fmt: skip
        found, expected = mine(events), reference(events)
        assert _same(found, expected)
        if found is events:  # only a list the sort leaves as it is, with no note
            assert all(e.kind is not EventKind.NOTE for e in events)


def test_an_ordered_list_is_its_own_order():
    events = [Event(EventKind.CHAR, BUS, i * 0.01, i * 0.01 + 0.008, 0x30) for i in range(10)]
    assert by_start_and_end(events) is events and _by_start(events) is events
    reversed_ = events[::-1]
    assert by_start_and_end(reversed_) == events and _by_start(reversed_) == events
    tied = [Event(EventKind.CHAR, BUS, 0.0, 0.009, 0x30), Event(EventKind.CHAR, BUS, 0.0, 0.008)]
    assert _by_start(tied) is tied  # by start only: a tie stays
    assert _same(by_start_and_end(tied), tied[::-1])  # by start and end: sorted


def _busy(n: int) -> list[Event]:
    events, t = [], 0.0
    for i in range(n):
        if i % 23 == 0:
            events.append(Event(EventKind.BREAK, BUS, t, t + 0.0125))
            t += 0.0125 + 0.00833
        events.append(Event(EventKind.CHAR, BUS, t, t + 0.00833, 0x30 if i % 23 != 4 else 0x21))
        t += 0.00833 + (0.0095 if i % 23 == 4 else 0.0)
    return events


def test_inferring_the_directions_of_an_ordered_capture_sorts_nothing():
    """50,000 events: ~3.6 MB traced at the peak of the sort's keys and copy before; the
    inference's own state now (a run and a pair at a time)."""
    events = _busy(50_000)
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        count = sum(1 for _ in iter_directions(events))
        peak = tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()
    assert count == len(events)
    assert peak < 500_000, f"{peak / 1e6:.2f} MB traced"


def test_the_view_and_directions_are_those_of_the_sorted_copy():
    events = _busy(3_000)
    shuffled = events[1::2] + events[::2]
    assert [(e, d) for e, d in infer_directions(events)] == infer_directions(shuffled)
    a, b = read_view(events), read_view(shuffled)
    assert [t.text for t in a.transmissions] == [t.text for t in b.transmissions]
    assert _same(a.chars, b.chars) and _same(a.breaks, b.breaks)
