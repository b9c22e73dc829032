"""The bus time of a transcript already in start order reads it as it is (issue 22: a sorted
copy and its sort's keys were two lists of every event, ~6 MB at the first report of an hour's
busy capture); one out of order or holding notes is sorted as before, the same figures."""

from __future__ import annotations

import random
import tracemalloc

from conformance.links.bus_time import bus_time
from conformance.transcript import BUS, DUT, TOOL, Event, EventKind
from conformance.transcript import in_start_order as _in_start_order


def _events(n: int) -> list[Event]:
    events = []
    t = 0.0
    for i in range(n):
        if i % 20 == 0:
            events.append(Event(EventKind.BREAK, TOOL, t, t + 0.0125))
            t += 0.0125 + 0.009
        events.append(Event(EventKind.CHAR, DUT if i % 20 > 5 else TOOL, t, t + 0.00833, 0x30))
        t += 0.00833 + (0.009 if i % 20 == 5 else 0.0)
    return events


def test_an_ordered_list_is_read_as_it_is():
    events = _events(100_000)
    assert _in_start_order(events) is events
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        found = bus_time(events)
        peak = tracemalloc.get_traced_memory()[1] - before
    finally:
        tracemalloc.stop()
    assert found.frames == 100_000 and found.breaks == 5_000
    assert peak < 200_000, f"{peak / 1e6:.2f} MB traced"  # ~1.7 MB with the copy


def test_out_of_order_or_with_notes_is_sorted_as_before():
    rng = random.Random(7)
    events = _events(2_000)
    shuffled = list(events)
    rng.shuffle(shuffled)
    noted = [*events[:100], Event(EventKind.NOTE, BUS, 0.5, 0.5, text="n"), *events[100:]]
    for given in (shuffled, noted, tuple(events)):
        wire = _in_start_order(given)
        assert wire is not given
        assert wire == sorted((e for e in given if e.kind is not EventKind.NOTE),
                              key=lambda e: e.start)  # fmt: skip
        assert bus_time(given) == bus_time(events)
