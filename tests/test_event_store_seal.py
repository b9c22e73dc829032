"""A column's (and a store's) last chunk written out though not full (``Column.seal``,
``CompactEvents.seal``: issue 22, branch memory25): what reads it back is what was appended,
by item, slice, range and in order, whatever was appended, widened and sealed in between;
appending after a seal reads the chunk back first; a sealed column holds in RAM no more than
the block it read last."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conformance import event_store
from conformance.event_store import Column, CompactEvents
from conformance.transcript import BUS, Event, EventKind

CHUNK, BLOCK = 6, 4

#: what is done to a column: append some numbers, widen it, seal it
steps = st.lists(
    st.one_of(
        st.tuples(st.just("extend"), st.lists(st.integers(0, 255), max_size=15)),
        st.tuples(st.just("append"), st.integers(0, 255)),
        st.tuples(st.just("wide"), st.lists(st.integers(0, 2**31), max_size=5)),
        st.tuples(st.just("seal"), st.none()),
    ),
    max_size=14,
)


def _check_reads(column: Column, values: list[int]) -> None:
    n = len(values)
    assert len(column) == n
    assert list(column) == values
    assert [column[i] for i in range(n)] == values
    assert [column[i] for i in range(-n, 0)] == values
    for lo in range(n + 1):
        for hi in range(lo, min(n, lo + 9) + 1):
            assert list(column.read(lo, hi)) == values[lo:hi], (lo, hi)
            assert list(column[lo:hi]) == values[lo:hi]
            assert [x for part in column.parts(lo, hi) for x in part] == values[lo:hi]
    with pytest.raises(IndexError):
        column[n]


@settings(max_examples=150, deadline=None)
@given(steps)
def test_a_column_reads_back_what_was_appended_whatever_was_sealed(todo):
    with pytest.MonkeyPatch.context() as m:
        m.setattr(event_store, "CHUNK", CHUNK)
        m.setattr(event_store, "BLOCK", BLOCK)
        column, values = Column("B"), []
        for what, arg in todo:
            if what == "extend":
                column.extend(arg)
                values += arg
            elif what == "append":
                column.append(arg)
                values.append(arg)
            elif what == "wide":
                if column.typecode == "B":
                    column.widen("I")
                column.extend(arg)
                values += arg
            else:
                in_ram = column.chunk_count() > column.spilled()  # its last chunk
                assert column.seal() == in_ram
                if values:  # every chunk written out: a block read back at most in RAM
                    assert column.spilled() == column.chunk_count()
            _check_reads(column, values)
            if column.chunk_count() and column.spilled() == column.chunk_count():
                assert column.resident_nbytes() <= BLOCK * column_itemsize(column)


def column_itemsize(column: Column) -> int:
    from array import array

    return max(array("I").itemsize, array(column.typecode).itemsize)


def test_a_sealed_column_holds_a_block_at_most(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(event_store, "CHUNK", 64)
    monkeypatch.setattr(event_store, "BLOCK", 8)
    column = Column("d")
    column.extend(float(i) for i in range(150))
    assert column.resident_nbytes() == 22 * 8  # the last chunk: 150 - 2 * 64
    assert column.seal() and column.spilled() == 3
    assert column.resident_nbytes() == 0
    assert column[149] == 149.0 and column.resident_nbytes() == 6 * 8  # its last block
    assert not column.seal()  # nothing more to write
    column.append(150.0)  # the chunk read back, appended to
    assert column.spilled() == 2 and list(column) == [float(i) for i in range(151)]


def _event(i: int) -> Event:
    kind = EventKind.BREAK if i % 9 == 0 else EventKind.CHAR
    return Event(kind, BUS, i / 100, i / 100 + 0.001, i % 200 + (300 if i == 40 else 0))


def test_a_store_sealed_reads_back_and_stores_more(monkeypatch: pytest.MonkeyPatch):
    """A store longer than a chunk sealed (a loaded recording's): every event the same, and
    events stored after it (a wire past a byte among them) read back too."""
    monkeypatch.setattr(event_store, "CHUNK", 16)
    monkeypatch.setattr(event_store, "BLOCK", 4)
    stored = [_event(i) for i in range(37)]
    store = CompactEvents.of(stored)
    assert store is not None and store.spilled() == 2
    assert store.seal() and store.spilled() == 3 and store.resident_nbytes() == 0
    assert list(store) == stored and store[36] == stored[36] and store[3:20] == stored[3:20]
    more = [_event(i) for i in range(37, 60)]
    for e in more:
        store.append(e)
    assert list(store) == stored + more and len(store) == 60
    assert store.seal() and list(store.made(range(10, 59))) == (stored + more)[10:59]


def test_a_store_of_one_chunk_is_not_sealed(monkeypatch: pytest.MonkeyPatch):
    """No temporary file for a short recording: its one chunk stays in RAM."""
    monkeypatch.setattr(event_store, "CHUNK", 64)
    store = CompactEvents.of([_event(i) for i in range(30)])
    assert store is not None
    assert not store.seal() and store.spilled() == 0 and store.spill.nbytes() == 0
    assert list(store) == [_event(i) for i in range(30)]
