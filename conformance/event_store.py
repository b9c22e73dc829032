"""A loaded recording's events kept as columns, each :class:`~conformance.transcript.Event`
made only when it is read (issue 22: one hour of a busy 1 MHz capture judged in bounded
memory).

A passive judgement reads a recording a window at a time (the bus pass, each sensor's pass,
the recorder's, :mod:`conformance.offline.sensor_windows`) and its reports read it again as
the events come (:meth:`~conformance.links.base.BusEnd.events_again`); none of them needs
every event as an object at once. Held as objects, an hour's 357,000 events took 162 bytes
each (the objects, their stamps as float objects, the lists of them): 58 MB, 94% of what the
loaded state grew by. Here each event is 18 bytes: its start and end (8 each, exactly the
floats it had), its wire bits (1, widened where a wire does not fit a byte) and which of the
store's distinct (kind, origin, text, uncertainty, duration uncertainty) it has (1, widened
past 256 of them); those fields are kept as the very objects the events held.

An event read back equals the one stored, field for field, and prints the same JSON line
(``tests/test_event_store.py``); it is a new object at each read, so nothing may
take two reads of one event for the same object (what reads a recording compares events by
equality: the reports' positions, :class:`~conformance.reports.evidence.StreamedPositions`).
Events whose stamps are not finite floats, or whose wire is not a whole number that fits 64
bits, are not stored here (:meth:`CompactEvents.of` gives None): a NaN start compares
unequal to itself once made again, which equality could not place.
"""

from __future__ import annotations

from array import array
from collections.abc import Iterable, Iterator, Sequence
from math import copysign, isfinite
from typing import overload

from .transcript import Event, EventKind, full_event

#: (kind, origin, text, uncertainty, duration_uncertainty): what a store keeps once
Fields = tuple[EventKind, str, str, float, float | None]
_WIDE = 2**63  # the widest wire a ``q`` array holds
_INF = float("inf")
#: events a chunk of the columns holds (2**16: 512 KiB a column of stamps)
CHUNK = 1 << 16


class NotCompact(ValueError):
    """An event :class:`CompactEvents` cannot hold (its caller keeps a list instead)."""


class CompactEvents(Sequence[Event]):
    """Events in recorded order as parallel columns (see the module's docstring): a
    read-only sequence; an item or a slice read makes its events again. The columns are
    kept in chunks of :data:`CHUNK` events: a column grown whole by appending was copied
    each time its block moved (both copies held at that moment: the decode of an hour's
    capture peaked ~6 MB higher), a chunk is at most one chunk's copy."""

    __slots__ = ("starts", "ends", "wires", "which", "fields", "_known", "_wire", "_which")

    def __init__(self) -> None:
        self.starts: list[array] = []
        self.ends: list[array] = []
        self.wires: list[array] = []
        self.which: list[array] = []
        self._wire = "B"  # widened to "q" where a wire does not fit a byte
        self._which = "B"  # the index into ``fields``, widened to "I" past 256
        self.fields: list[Fields] = []
        self._known: dict[Fields, int] = {}

    @classmethod
    def of(cls, events: Iterable[Event]) -> CompactEvents | None:
        """``events`` stored, or None when one of them cannot be (see the module's
        docstring): the caller keeps its list then."""
        store = cls()
        for e in events:
            if not store._add(e):
                return None
        return store

    def append(self, e: Event) -> None:
        """Store ``e`` after the others (:class:`NotCompact` if it cannot be): a capture's
        decoder adds its events here as it makes them, none held beyond the one."""
        if not self._add(e):
            raise NotCompact(f"an event the store cannot hold: {e!r}")

    def _add(self, e: Event) -> bool:
        start, end, wire = e.start, e.end, e.wire
        if type(start) is not float or type(end) is not float or type(wire) is not int:
            return False
        if not (isfinite(start) and isfinite(end) and -_WIDE <= wire < _WIDE):
            return False
        key = (e.kind, e.origin, e.text, e.uncertainty, e.duration_uncertainty)
        try:
            at = self._known.get(key)
        except TypeError:  # a field that is no value (unhashable): not for a store
            return False
        if at is not None and not _exact(self.fields[at], key):
            return False  # equal but not the same (0 and 0.0, -0.0 and 0.0): not for a store
        if at is None:
            at = self._known[key] = len(self.fields)
            self.fields.append(key)
            if at == 256:
                self._which = "I"
                self.which = [array("I", c) for c in self.which]
        if self._wire == "B" and not 0 <= wire < 256:
            self._wire = "q"
            self.wires = [array("q", c) for c in self.wires]
        if not self.starts or len(self.starts[-1]) == CHUNK:
            self.starts.append(array("d"))
            self.ends.append(array("d"))
            self.wires.append(array(self._wire))
            self.which.append(array(self._which))
        self.starts[-1].append(start)
        self.ends[-1].append(end)
        self.wires[-1].append(wire)
        self.which[-1].append(at)
        return True

    def __len__(self) -> int:
        return (len(self.starts) - 1) * CHUNK + len(self.starts[-1]) if self.starts else 0

    def typecodes(self) -> tuple[str, str]:
        """The columns' widths: the fields' index and the wires (``array`` typecodes)."""
        return self._which, self._wire

    @overload
    def __getitem__(self, i: int) -> Event: ...
    @overload
    def __getitem__(self, i: slice) -> list[Event]: ...
    def __getitem__(self, i: int | slice) -> Event | list[Event]:
        n = len(self)
        if isinstance(i, slice):
            return list(self._made(range(n)[i]))
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError("event index out of range")
        c, j = divmod(i, CHUNK)
        kind, origin, text, u, du = self.fields[self.which[c][j]]
        return full_event(
            kind, origin, self.starts[c][j], self.ends[c][j], self.wires[c][j], text, u, du
        )

    def __iter__(self) -> Iterator[Event]:
        return self._made(range(len(self)))

    def _made(self, positions: range) -> Iterator[Event]:
        """The events at ``positions`` (a range), made as they are read: a chunk's columns
        read together where the range steps by one."""
        fields, event = self.fields, full_event
        if positions.step != 1:
            for i in positions:
                yield self[i]
            return
        lo, hi = positions.start, positions.stop
        while lo < hi:
            c, j = divmod(lo, CHUNK)
            k = min(CHUNK, j + hi - lo)
            columns = (self.which[c][j:k], self.starts[c][j:k], self.ends[c][j:k])
            for w, start, end, wire in zip(*columns, self.wires[c][j:k], strict=True):
                kind, origin, text, u, du = fields[w]
                yield event(kind, origin, start, end, wire, text, u, du)
            lo += k - j

    def has_kind(self, kind: EventKind) -> bool:
        """Whether some event is of ``kind`` (no event made)."""
        wanted = {i for i, f in enumerate(self.fields) if f[0] is kind}
        return bool(wanted) and any(w in wanted for c in self.which for w in c)

    def in_start_order(self) -> bool:
        """Whether every start is at or after the one before (no event made)."""
        last = -_INF
        for chunk in self.starts:
            if chunk and chunk[0] < last:
                return False
            if not all(chunk[i - 1] <= chunk[i] for i in range(1, len(chunk))):
                return False
            last = chunk[-1] if chunk else last
        return True

    def nbytes(self) -> int:
        """The columns' own size (bytes): what the store holds an event."""
        columns = (*self.starts, *self.ends, *self.wires, *self.which)
        return sum(a.itemsize * len(a) for a in columns)


def _exact(a: Fields, b: Fields) -> bool:
    """Whether the equal fields ``a`` and ``b`` are also of one type and sign each, so that
    an event made with ``a`` prints as one made with ``b`` (``0`` and ``0.0`` are equal and
    hash alike, and print apart)."""
    for x, y in zip(a, b, strict=True):
        if x is y:
            continue
        if type(x) is not type(y) or (type(x) is float and copysign(1.0, x) != copysign(1.0, y)):
            return False
    return True


__all__ = ["CompactEvents", "NotCompact"]
