"""A loaded recording's events in columns (issue 22, ``conformance.event_store``): every event
read back equals the one stored and prints the same JSON line; what cannot be stored so
(stamps that are not finite floats, equal fields of another type or sign) is refused, never
stored changed; and a capture loaded for judging keeps its events so, the same as its decode's
list."""

from __future__ import annotations

import math
from itertools import pairwise

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance.event_store import CompactEvents, NotCompact
from conformance.transcript import BUS, DUT, TOOL, Event, EventKind, json_line

finite = st.floats(allow_nan=False, allow_infinity=False, width=64)
events = st.builds(
    Event,
    kind=st.sampled_from(list(EventKind)),
    origin=st.sampled_from([TOOL, DUT, BUS, "collision"]),
    start=finite,
    end=finite,
    wire=st.integers(-(2**40), 2**40) | st.integers(0, 255),
    text=st.sampled_from(["", "held back", "a note"]),
    uncertainty=st.sampled_from([0.0, 1e-6, 0.0156, -0.0]),
    duration_uncertainty=st.none() | st.sampled_from([0.0, 0.002]),
)


@settings(max_examples=200, deadline=None)
@given(st.lists(events, max_size=40))
def test_events_read_back_are_the_stored_ones(stored: list[Event]):
    store = CompactEvents.of(stored)
    if store is None:  # only a field equal to another of another sign: -0.0 beside 0.0
        keys = {(e.kind, e.origin, e.text, e.uncertainty, e.duration_uncertainty) for e in stored}
        assert len(keys) < len(
            {
                (
                    e.kind,
                    e.origin,
                    e.text,
                    math.copysign(1, e.uncertainty),
                    e.uncertainty,
                    e.duration_uncertainty,
                )  # fmt: skip
                for e in stored
            }
        )
        return
    assert len(store) == len(stored)
    assert list(store) == stored
    assert [json_line(e) for e in store] == [json_line(e) for e in stored]
    assert [store[i] for i in range(-len(stored), len(stored))] == stored + stored
    assert store[3:17:2] == stored[3:17:2]
    assert store.has_kind(EventKind.NOTE) == any(e.kind is EventKind.NOTE for e in stored)
    assert store.in_start_order() == all(a.start <= b.start for a, b in pairwise(stored))


def test_what_would_not_read_back_the_same_is_refused():
    good = Event(EventKind.CHAR, BUS, 1.0, 1.5, wire=0x30, uncertainty=0.0)
    assert CompactEvents.of([good]) is not None
    for bad in (
        Event(EventKind.CHAR, BUS, float("nan"), 1.5),  # NaN: unequal to itself made again
        Event(EventKind.CHAR, BUS, 1, 1.5),  # an int stamp would print as 1.0
        Event(EventKind.CHAR, BUS, 1.0, math.inf),
        Event(EventKind.CHAR, BUS, 1.0, 1.5, wire=2**70),
        Event(EventKind.CHAR, BUS, 1.0, 1.5, wire=0x30, uncertainty=0),  # 0 beside 0.0
        Event(EventKind.CHAR, BUS, 1.0, 1.5, wire=0x30, uncertainty=-0.0),
    ):
        assert CompactEvents.of([good, bad]) is None, bad
        store = CompactEvents.of([good])
        assert store is not None
        with pytest.raises(NotCompact):
            store.append(bad)
        assert list(store) == [good]


def test_wide_wires_and_many_kinds_of_fields():
    stored = [Event(EventKind.NOTE, TOOL, float(i), float(i), text=f"note {i}") for i in range(300)]
    stored.append(Event(EventKind.CHAR, DUT, 400.0, 401.0, wire=1000))
    store = CompactEvents.of(stored)
    assert store is not None
    assert store.typecodes() == ("I", "q")
    assert list(store) == stored
    with pytest.raises(IndexError):
        store[len(stored)]


def test_events_across_chunks(monkeypatch: pytest.MonkeyPatch):
    """A store of several chunks (:data:`~conformance.event_store.CHUNK` made small here)
    reads back the same events whole, item by item and in slices across chunks."""
    import conformance.event_store as event_store

    monkeypatch.setattr(event_store, "CHUNK", 7)
    stored = [
        Event(EventKind.CHAR, BUS, i * 0.01, i * 0.01 + 0.008, wire=i % 256) for i in range(50)
    ]
    stored[33] = Event(EventKind.BREAK, TOOL, 0.33, 0.34, text="held back")
    store = CompactEvents.of(stored)
    assert store is not None and len(store.starts) == 8
    assert list(store) == stored and len(store) == 50
    assert [store[i] for i in range(50)] == stored
    for lo, hi, step in ((0, 50, 1), (5, 23, 1), (6, 8, 1), (13, 14, 1), (3, 40, 3), (40, 2, -4)):
        assert store[lo:hi:step] == stored[lo:hi:step]
    assert store.in_start_order() and not store.has_kind(EventKind.NOTE)
    stored[21] = Event(EventKind.CHAR, BUS, 0.0, 0.001)  # back in time, a chunk's first
    shuffled = CompactEvents.of(stored)
    assert shuffled is not None and not shuffled.in_start_order()
    assert store.nbytes() == 18 * 50


def test_a_loaded_capture_keeps_its_decode_s_events_compact(tmp_path):
    from conformance.capture import decode_capture
    from conformance.replay.recording_link import load_recording, parse_recording, recording_port
    from tests.offline.test_judge_memory import busy_capture

    path = tmp_path / "busy.sr"
    busy_capture(path, 0.2)
    listed = decode_capture(str(path), keep=False).events
    link = load_recording(parse_recording(recording_port(str(path), "sr")))
    assert isinstance(link.transcript.events, CompactEvents)
    assert list(link.transcript.events) == listed
    assert list(link.events_again()) == listed
    assert link.transcript.events.nbytes() == 18 * len(listed)
