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
    """A store of several chunks (:data:`~conformance.event_store.CHUNK` and the blocks read
    back, :data:`~conformance.event_store.BLOCK`, made small here) reads back the same events
    whole, item by item and in slices across chunks and blocks, every full chunk spilled to
    the temporary file (the last one in RAM)."""
    import conformance.event_store as event_store

    monkeypatch.setattr(event_store, "CHUNK", 7)
    monkeypatch.setattr(event_store, "BLOCK", 3)
    stored = [
        Event(EventKind.CHAR, BUS, i * 0.01, i * 0.01 + 0.008, wire=i % 256) for i in range(50)
    ]
    stored[33] = Event(EventKind.BREAK, TOOL, 0.33, 0.34, text="held back")
    store = CompactEvents.of(stored)
    assert store is not None and store.chunk_count() == 8 and store.spilled() == 7
    assert store.resident_nbytes() <= 18 * (7 + 3)  # the last chunk and one block of each
    assert list(store) == stored and len(store) == 50
    assert [store[i] for i in range(50)] == stored
    assert [store[i] for i in reversed(range(50))] == stored[::-1]
    for lo, hi, step in ((0, 50, 1), (5, 23, 1), (6, 8, 1), (13, 14, 1), (3, 40, 3), (40, 2, -4)):
        assert store[lo:hi:step] == stored[lo:hi:step]
    assert store.in_start_order() and not store.has_kind(EventKind.NOTE)
    stored[21] = Event(EventKind.CHAR, BUS, 0.0, 0.001)  # back in time, a chunk's first
    shuffled = CompactEvents.of(stored)
    assert shuffled is not None and not shuffled.in_start_order()
    assert store.nbytes() == 18 * 50


def test_spilled_chunks_read_back_after_the_columns_widen(monkeypatch: pytest.MonkeyPatch):
    """Chunks written out before a wire wider than a byte or the 257th distinct fields
    read back with their own widths beside the wider chunks after them."""
    import conformance.event_store as event_store

    monkeypatch.setattr(event_store, "CHUNK", 5)
    monkeypatch.setattr(event_store, "BLOCK", 2)
    stored = [Event(EventKind.CHAR, BUS, i * 0.01, i * 0.01 + 0.008, wire=i) for i in range(12)]
    stored += [Event(EventKind.NOTE, TOOL, 1.0 + i, 1.0 + i, text=f"n{i}") for i in range(300)]
    stored.append(Event(EventKind.CHAR, DUT, 400.0, 401.0, wire=70000))
    store = CompactEvents.of(stored)
    assert store is not None and store.typecodes() == ("I", "q") and store.spilled() == 62
    assert list(store) == stored
    assert [store[i] for i in range(len(stored))] == stored
    assert store[3:40] == stored[3:40] and store[-9:] == stored[-9:]
    assert store.has_kind(EventKind.NOTE) and store.in_start_order()


def test_a_column_reads_back_what_was_appended(monkeypatch: pytest.MonkeyPatch):
    """:class:`~conformance.event_store.Column` (a decode's bit-rate errors): items,
    slices and iteration across spilled chunks and blocks; NaN kept."""
    import conformance.event_store as event_store

    monkeypatch.setattr(event_store, "CHUNK", 6)
    monkeypatch.setattr(event_store, "BLOCK", 4)
    column = event_store.Column("f")
    values = [float("nan") if i % 7 == 3 else i / 8 for i in range(40)]
    column.extend(values)
    same = [repr(v) for v in values]
    assert len(column) == 40 and column.spilled() == 6
    assert [repr(v) for v in column] == same
    assert [repr(column[i]) for i in range(-40, 0)] == same
    for lo, hi, step in ((0, 40, 1), (5, 23, 1), (11, 13, 1), (3, 3, 1), (2, 39, 5)):
        assert [repr(v) for v in column[lo:hi:step]] == same[lo:hi:step]
    with pytest.raises(IndexError):
        column[40]


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


def test_a_capture_decoded_compact_writes_out_its_events_and_rates(tmp_path, monkeypatch):
    """A compact decode's store and bit-rate errors (:class:`~conformance.event_store.Column`)
    spilled chunk by chunk (chunks made small here) read back as the list decode's."""
    import conformance.event_store as event_store
    from conformance.capture import decode_capture
    from tests.offline.test_judge_memory import busy_capture

    monkeypatch.setattr(event_store, "CHUNK", 500)
    monkeypatch.setattr(event_store, "BLOCK", 64)
    path = tmp_path / "busy.sr"
    busy_capture(path, 0.2)
    listed = decode_capture(str(path), keep=False)
    compact = decode_capture(str(path), keep=False, compact=True)
    events, rates = compact.events, compact.baud_error_pct
    assert isinstance(events, CompactEvents) and events.spilled() >= 2
    assert isinstance(rates, event_store.Column) and rates.spilled() >= 2
    assert list(events) == listed.events and len(rates) == len(listed.baud_error_pct)
    assert [repr(x) for x in rates] == [repr(x) for x in listed.baud_error_pct]
    assert compact.baud_error_summary() == listed.baud_error_summary()


def test_a_column_reads_every_range_as_appended_across_a_widening(
    monkeypatch: pytest.MonkeyPatch,
):
    """:meth:`~conformance.event_store.Column.read` of every range: those inside one block
    or one chunk in RAM (given as that part) and those across several (joined) alike, in the
    column's typecode even where a chunk was spilled before it widened."""
    import conformance.event_store as event_store

    monkeypatch.setattr(event_store, "CHUNK", 6)
    monkeypatch.setattr(event_store, "BLOCK", 4)
    column = event_store.Column("B")
    column.extend(range(14))
    column.widen("I")
    column.extend(range(300, 310))
    values = [*range(14), *range(300, 310)]
    assert column.spilled() == 3
    for lo in range(len(values) + 1):
        for hi in range(lo, len(values) + 1):
            got = column.read(lo, hi)
            assert got.typecode == "I" and list(got) == values[lo:hi], (lo, hi)
