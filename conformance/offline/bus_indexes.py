"""The bus pass's per-window numbers written out with the loaded recording's events (issue 22:
a busy capture judged in memory that does not grow with its length).

The bus pass (:func:`~.sensor_windows.bus_windows`) keeps, to read the windows again, where
each window begins, how many transmissions (and how many with characters) come before it,
whether its sides were inferred, and which windows hold a transmission to each sensor: four
arrays of 4 bytes a window, a byte a window and one array per sensor (~17 bytes a window;
~16,000 windows an hour of a busy bus, so 0.27 MB an hour held to the end of the
judgement, 1.1 MB at four hours), and its events' inferred sides in a
:class:`~conformance.event_store.Column` whose last chunk stayed in RAM. Once the pass is
done none of them changes: here each is written to the recording's own temporary file (the
store's :class:`~conformance.event_store.Spill`) as a sealed column, read back a block at a
time (each column keeps the block it read last: 16 KB at most of 4-byte numbers), and the
sides' last chunk too. A recording whose events are all in RAM (one chunk: a short one, a
test's, a matrix row's) keeps its arrays as they are: no temporary file for it, and its
arrays are no longer than a chunk's worth of windows.

A column reads as the array did (by index, slice, ``len`` and in order, the same numbers:
``tests/offline/test_bus_indexes.py``), so every reader of the windows is unchanged.
"""

from __future__ import annotations

from array import array

from ..event_store import Column, CompactEvents, Spill
from .sensor_windows import BusWindows


def written(numbers: array | bytearray, spill: Spill, typecode: str | None = None) -> Column:
    """``numbers`` as a column written out to ``spill`` whole (sealed: its last chunk too),
    of their own typecode (``typecode`` for a bytearray's bytes)."""
    code = typecode or (numbers.typecode if isinstance(numbers, array) else "B")
    column = Column(code, spill)
    column.extend(numbers)
    column.seal()
    return column


def spill_indexes(bus: BusWindows) -> bool:
    """Write ``bus``'s per-window numbers and the sides' last chunk out (see the module's
    docstring), once; whether they were (False: done before, or the recording's events are
    not written out themselves)."""
    store = bus.events
    if not isinstance(store, CompactEvents) or not store.spilled():
        return False
    if isinstance(bus.bounds, Column):
        return False
    spill = store.spill
    bus.bounds = written(bus.bounds, spill)  # type: ignore[assignment]
    bus.before = written(bus.before, spill)  # type: ignore[assignment]
    bus.chars_before = written(bus.chars_before, spill)  # type: ignore[assignment]
    bus.sided = written(bus.sided, spill)  # type: ignore[assignment]
    bus.windows_of = {a: written(w, spill) for a, w in bus.windows_of.items()}  # type: ignore[misc]
    if bus.codes is not None:
        bus.codes.seal()
    return True


__all__ = ["spill_indexes", "written"]
