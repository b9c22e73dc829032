"""A record's events as positions into a compact store (issue 22, memory19:
``conformance.event_store.StoredEvents``): it must read as the list of events it stands for,
item by item, by slice, in order, by equality, joined with ``+``, whether its positions are
consecutive or not, and hold no event made."""

from __future__ import annotations

import gc

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.event_store import CompactEvents, StoredEvents
from conformance.transcript import DUT, Event, EventKind, decode_7e1

EVENTS = [Event(EventKind.CHAR, DUT, 0.01 * i, 0.01 * i + 0.008, 0x30 + i % 10) for i in range(300)]
STORE = CompactEvents.of(EVENTS)


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.integers(0, len(EVENTS) - 1), max_size=30)
    | st.tuples(st.integers(0, 280), st.integers(0, 19)).map(
        lambda t: list(range(t[0], t[0] + t[1]))
    ),
    st.integers(-35, 35),
    st.integers(-35, 35),
)
def test_positions_read_as_the_list_they_stand_for(positions: list[int], i: int, j: int):
    assert STORE is not None
    listed = [EVENTS[k] for k in positions]
    stored = StoredEvents(STORE, positions)
    assert len(stored) == len(listed) and bool(stored) == bool(listed)
    assert list(stored) == listed and stored == listed and listed == stored
    assert stored == tuple(listed) and stored == StoredEvents(STORE, positions)
    assert stored != [*listed, EVENTS[0]]
    assert stored[i:j] == listed[i:j] and stored[::-1] == listed[::-1]
    assert list(reversed(stored)) == listed[::-1]
    if -len(listed) <= i < len(listed):
        assert stored[i] == listed[i]
    else:
        with pytest.raises(IndexError):
            stored[i]
    assert stored + listed[:2] == listed + listed[:2]
    assert listed[:2] + stored == listed[:2] + listed
    joined: list[Event] = []
    joined += stored
    assert joined == listed
    assert decode_7e1(stored) == decode_7e1(listed)
    assert repr(stored) == repr(listed)
    assert all(e in stored for e in listed)


def test_a_run_of_positions_is_held_as_its_first_and_length():
    assert STORE is not None
    run = StoredEvents(STORE, list(range(40, 65)))
    assert run.at is None and (run.lo, run.n) == (40, 25)
    assert list(run.positions()) == list(range(40, 65))
    scattered = StoredEvents(STORE, [3, 4, 9])
    assert scattered.at is not None and list(scattered.positions()) == [3, 4, 9]


def test_no_event_is_held():
    """The events are made at each read, none kept (what the records held is the point)."""
    assert STORE is not None
    gc.collect()
    stored = [StoredEvents(STORE, list(range(k, k + 20))) for k in range(0, 280, 20)]
    assert stored[3][0] == EVENTS[60] and stored[3][0] is not stored[3][0]
    referents = [r for s in stored for r in gc.get_referents(s)]
    assert not any(isinstance(r, Event) for r in referents)


def test_not_hashable_as_a_list_is_not():
    assert STORE is not None
    with pytest.raises(TypeError):
        hash(StoredEvents(STORE, [1, 2]))
