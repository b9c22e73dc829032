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

import os
import tempfile
from array import array
from collections.abc import Iterable, Iterator, Sequence
from math import copysign, isfinite
from typing import IO, overload

from .transcript import Event, EventKind, full_event

#: (kind, origin, text, uncertainty, duration_uncertainty): what a store keeps once
Fields = tuple[EventKind, str, str, float, float | None]
_WIDE = 2**63  # the widest wire a ``q`` array holds
_INF = float("inf")
#: events a chunk of the columns holds (2**16: 512 KiB a column of stamps)
CHUNK = 1 << 16
#: items a read of a spilled chunk brings back at once (and a column keeps, its last read)
BLOCK = 1 << 12


class Spill:
    """A temporary file the full chunks of columns are written to (issue 22's bounded
    memory: an hour's store no longer held in RAM), opened at the first chunk written and
    deleted by the system once closed (the last column holding it let go, or the process
    ended). Read back by position (``os.pread`` where the system has it: a reader in a
    forked process does not move another's place in the file)."""

    __slots__ = ("_file", "_size")

    def __init__(self) -> None:
        self._file: IO[bytes] | None = None
        self._size = 0

    def write(self, data: array) -> int | None:
        """``data`` written after what is there; its place, or None when no temporary file
        can be written (the caller keeps the chunk in RAM)."""
        try:
            if self._file is None:
                self._file = tempfile.TemporaryFile(prefix="sdi12-events-")  # noqa: SIM115 (held)
            at = self._size
            self._file.seek(at)
            self._file.write(data.tobytes())
            self._file.flush()
        except OSError:
            return None
        self._size = at + data.itemsize * len(data)
        return at

    def read(self, typecode: str, at: int, count: int) -> array:
        """``count`` items of ``typecode`` written at ``at``."""
        assert self._file is not None
        out = array(typecode)
        n = out.itemsize * count
        if hasattr(os, "pread"):
            data = os.pread(self._file.fileno(), n, at)
        else:  # pragma: no cover - systems without pread (Windows)
            self._file.seek(at)
            data = self._file.read(n)
        out.frombytes(data)
        return out

    def nbytes(self) -> int:
        """The bytes written (on disk, not in RAM)."""
        return self._size


class Column:
    """An append-only column of numbers (``array`` typecodes) in chunks of :data:`CHUNK`
    items; each full chunk is written to a :class:`Spill` and let go, so what a column
    holds in RAM is its last chunk and the last :data:`BLOCK` items read back, whatever
    its length. Read by item, by slice (an ``array``) and in blocks. ``widen`` changes the
    typecode of what comes (the chunks in RAM converted; a spilled chunk keeps its own)."""

    __slots__ = ("typecode", "spill", "_chunks", "_spilled", "_cached")

    def __init__(self, typecode: str, spill: Spill | None = None) -> None:
        self.typecode = typecode
        self.spill = spill if spill is not None else Spill()
        #: the chunks in order: an array in RAM, or None where it was spilled
        self._chunks: list[array | None] = []
        #: per chunk: (typecode, place in the spill, length) where it was spilled
        self._spilled: dict[int, tuple[str, int, int]] = {}
        self._cached: tuple[int, int, array] | None = None  # (chunk, block, items)

    def append(self, x: float) -> None:
        chunks = self._chunks
        if not chunks or chunks[-1] is None or len(chunks[-1]) >= CHUNK:
            self._open_last()
        chunks[-1].append(x)  # type: ignore[union-attr]

    def extend(self, xs: Iterable[float]) -> None:
        """Append ``xs`` in order (a chunk's room filled at a time)."""
        items, i = array(self.typecode, xs), 0
        while i < len(items):
            last = self._open_last()
            room = CHUNK - len(last)
            last.extend(items[i : i + room])
            i += room

    def open_chunk(self) -> int:
        """Room for more in the last chunk (a new one begun, the full one spilled, if it has
        none; a sealed one read back): how many items it takes still."""
        return CHUNK - len(self._open_last())

    def _open_last(self) -> array:
        """The chunk in RAM items are appended to: the last one, read back if :meth:`seal`
        wrote it out before it was full, or a new one where it is full (spilled)."""
        chunks = self._chunks
        if chunks and chunks[-1] is None and self._spilled[len(chunks) - 1][2] < CHUNK:
            self._read_back_last()
        if not chunks or chunks[-1] is None or len(chunks[-1]) >= CHUNK:
            self._new_chunk()
        return chunks[-1]  # type: ignore[return-value]

    def seal(self) -> bool:
        """Write the last chunk out though it is not full (issue 22: what is appended to a
        column ends with it, a recording's store once decoded, a pass's per-window numbers
        once the pass is done; the last chunk, up to :data:`CHUNK` items, was the one part
        of a column held in RAM however long, so a loaded recording held between nothing and
        a chunk of each column by where its length fell). Read as before, a block at a
        time; appending after it reads the chunk back first (:meth:`_open_last`). Whether
        it was written out (False: nothing to write, or no temporary file could be)."""
        chunks = self._chunks
        if not chunks or chunks[-1] is None or not len(chunks[-1]):
            return False
        self._spill_last()
        return chunks[-1] is None

    def _read_back_last(self) -> None:
        """The sealed last chunk in RAM again, of the column's typecode (:meth:`seal`)."""
        c = len(self._chunks) - 1
        typecode, at, n = self._spilled.pop(c)
        items = self.spill.read(typecode, at, n)
        self._chunks[c] = items if typecode == self.typecode else array(self.typecode, items)
        if self._cached is not None and self._cached[0] == c:
            self._cached = None

    def last(self) -> array:
        """The chunk items are appended to (:meth:`open_chunk` first)."""
        return self._chunks[-1]  # type: ignore[return-value]

    def is_spilled(self, c: int) -> bool:
        """Whether chunk ``c`` was written out."""
        return self._chunks[c] is None

    def _new_chunk(self) -> None:
        if self._chunks and self._chunks[-1] is not None:
            self._spill_last()
        self._chunks.append(array(self.typecode))

    def _spill_last(self) -> None:
        c, full = len(self._chunks) - 1, self._chunks[-1]
        assert full is not None
        at = self.spill.write(full)
        if at is not None:
            self._spilled[c] = (full.typecode, at, len(full))
            self._chunks[c] = None

    def widen(self, typecode: str) -> None:
        """What comes is of ``typecode`` (wider): the chunks in RAM converted."""
        self.typecode = typecode
        self._chunks = [c if c is None else array(typecode, c) for c in self._chunks]
        self._cached = None

    def __len__(self) -> int:
        chunks = self._chunks
        if not chunks:
            return 0
        last = chunks[-1]
        n = len(last) if last is not None else self._spilled[len(chunks) - 1][2]
        return (len(chunks) - 1) * CHUNK + n

    def chunk_count(self) -> int:
        return len(self._chunks)

    def spilled(self) -> int:
        """How many chunks were written out."""
        return len(self._spilled)

    def _block(self, c: int, b: int) -> array:
        """Block ``b`` of spilled chunk ``c`` (kept until another is read)."""
        cached = self._cached
        if cached is not None and cached[0] == c and cached[1] == b:
            return cached[2]
        typecode, at, n = self._spilled[c]
        lo = b * BLOCK
        hi = min(n, lo + BLOCK)
        size = array(typecode).itemsize
        items = self.spill.read(typecode, at + lo * size, hi - lo)
        self._cached = (c, b, items)
        return items

    def part(self, c: int, j: int, k: int) -> array:
        """Items ``j:k`` of chunk ``c`` (an array: a slice of a chunk in RAM, read back from
        the spill where it was written, a block at a time)."""
        chunk = self._chunks[c]
        if chunk is not None:
            return chunk[j:k]
        b, hi_b = j // BLOCK, (k - 1) // BLOCK
        if b == hi_b:
            block = self._block(c, b)
            return block[j - b * BLOCK : k - b * BLOCK]
        typecode, at, _ = self._spilled[c]
        size = array(typecode).itemsize
        return self.spill.read(typecode, at + j * size, k - j)

    def item(self, c: int, j: int) -> float:
        chunk = self._chunks[c]
        if chunk is not None:
            return chunk[j]
        b = j // BLOCK
        return self._block(c, b)[j - b * BLOCK]

    @overload
    def __getitem__(self, i: int) -> float: ...
    @overload
    def __getitem__(self, i: slice) -> array: ...
    def __getitem__(self, i: int | slice) -> float | array:
        n = len(self)
        if isinstance(i, slice):
            positions = range(n)[i]
            if positions.step != 1:
                return array(self.typecode, [self[k] for k in positions])
            return self.read(positions.start, positions.stop)
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError("column index out of range")
        c, j = divmod(i, CHUNK)
        return self.item(c, j)

    def read(self, lo: int, hi: int) -> array:
        """Items ``lo:hi`` (0 <= lo, hi <= len) as one array of the column's typecode: the
        one part they lie in where they do (a window's sides, read at every view of it
        again: :class:`~conformance.offline.sensor_windows.BusWindows`), else the parts
        joined."""
        c, j = divmod(lo, CHUNK)
        k = j + hi - lo
        if (
            lo < hi
            and k <= CHUNK
            and (self._chunks[c] is not None or j // BLOCK == (k - 1) // BLOCK)
        ):
            part = self.part(c, j, k)
            if part.typecode == self.typecode:
                return part
        out = array(self.typecode)
        for part in self.parts(lo, hi):
            out.extend(part if part.typecode == out.typecode else array(out.typecode, part))
        return out

    def parts(self, lo: int, hi: int) -> Iterator[array]:
        """Items ``lo:hi`` as arrays in order, none longer than a chunk's or a block's."""
        while lo < hi:
            c, j = divmod(lo, CHUNK)
            k = min(CHUNK, j + hi - lo)
            if self._chunks[c] is None:
                k = min(k, (j // BLOCK + 1) * BLOCK)
            yield self.part(c, j, k)
            lo += k - j

    def __iter__(self) -> Iterator[float]:
        for part in self.parts(0, len(self)):
            yield from part

    def nbytes(self) -> int:
        """The items' size wherever held (RAM and spill)."""
        ram = sum(a.itemsize * len(a) for a in self._chunks if a is not None)
        spilled = sum(array(t).itemsize * n for t, _, n in self._spilled.values())
        return ram + spilled

    def resident_nbytes(self) -> int:
        """The items' size held in RAM (the last chunk, any chunk that could not be
        spilled, the block last read)."""
        ram = sum(a.itemsize * len(a) for a in self._chunks if a is not None)
        cached = self._cached[2] if self._cached is not None else None
        return ram + (cached.itemsize * len(cached) if cached is not None else 0)


class NotCompact(ValueError):
    """An event :class:`CompactEvents` cannot hold (its caller keeps a list instead)."""


class CompactEvents(Sequence[Event]):
    """Events in recorded order as parallel columns (see the module's docstring): a
    read-only sequence; an item or a slice read makes its events again. The columns are
    :class:`Column` s sharing one :class:`Spill`: in chunks of :data:`CHUNK` events (a
    column grown whole by appending was copied each time its block moved), each full chunk
    written to a temporary file and read back a block at a time, so that the store holds
    about one chunk in RAM whatever the recording's length (issue 22: an hour's busy
    capture, 6.4 MB of columns, judged in the memory ten minutes take)."""

    __slots__ = (
        "starts",
        "ends",
        "wires",
        "which",
        "fields",
        "_known",
        "_columns",
        "_room",
        "_put",
    )

    def __init__(self) -> None:
        spill = Spill()
        self.starts = Column("d", spill)
        self.ends = Column("d", spill)
        self.wires = Column("B", spill)  # widened to "q" where a wire does not fit a byte
        self.which = Column("B", spill)  # the index into ``fields``, widened to "I" past 256
        self._columns = (self.which, self.starts, self.ends, self.wires)
        #: appends left before a chunk is full, and the current chunks' ``append`` s (an
        #: event stored without a call of ours a column: the decoder's 357,000 an hour)
        self._room = 0
        self._put: tuple = ()
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
                self.which.widen("I")
                self._room = 0  # as for the wires below
        if self.wires.typecode == "B" and not 0 <= wire < 256:
            self.wires.widen("q")
            self._room = 0  # the appenders of the arrays the widening replaced: made again
        if not self._room:
            self._room = min(column.open_chunk() for column in self._columns)
            self._put = tuple(column.last().append for column in self._columns)
        self._room -= 1
        put_which, put_start, put_end, put_wire = self._put
        put_which(at)
        put_start(start)
        put_end(end)
        put_wire(wire)
        return True

    def __len__(self) -> int:
        return len(self.starts)

    def seal(self) -> bool:
        """A store already written out (longer than a chunk) has its last chunk written out
        too, though not full (:meth:`Column.seal`): a recording once loaded then holds none
        of its events in RAM but the block last read (issue 22: that chunk, up to 1.1 MB of
        columns, was held by where the recording's length fell: an hour's busy capture held
        0.5 MB of it, four hours' 0.9). A store of one chunk stays in RAM (a short
        recording: no temporary file, at most a chunk). Storing more after it reads the last
        chunks back. Whether it was sealed."""
        if not self.spilled():
            return False
        for column in self._columns:
            column.seal()
        self._room, self._put = 0, ()
        return True

    @property
    def spill(self) -> Spill:
        """The temporary file the columns are written to (what else a loaded recording
        writes out shares it: :mod:`conformance.offline.bus_indexes`)."""
        return self.starts.spill

    def typecodes(self) -> tuple[str, str]:
        """The columns' widths: the fields' index and the wires (``array`` typecodes)."""
        return self.which.typecode, self.wires.typecode

    def chunk_count(self) -> int:
        """How many chunks the columns are in."""
        return self.starts.chunk_count()

    def spilled(self) -> int:
        """How many chunks were written out to the temporary file."""
        return self.starts.spilled()

    @overload
    def __getitem__(self, i: int) -> Event: ...
    @overload
    def __getitem__(self, i: slice) -> list[Event]: ...
    def __getitem__(self, i: int | slice) -> Event | list[Event]:
        n = len(self)
        if isinstance(i, slice):
            return list(self.made(range(n)[i]))
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError("event index out of range")
        c, j = divmod(i, CHUNK)
        kind, origin, text, u, du = self.fields[self.which.item(c, j)]  # type: ignore[index]
        return full_event(
            kind, origin, self.starts.item(c, j), self.ends.item(c, j), self.wires.item(c, j),
            text, u, du,
        )  # fmt: skip

    def __iter__(self) -> Iterator[Event]:
        return self.made(range(len(self)))

    def made(self, positions: range) -> Iterator[Event]:
        """The events at ``positions`` (a range), made as they are read: the columns'
        parts read together where the range steps by one."""
        fields, event = self.fields, full_event
        if positions.step != 1:
            for i in positions:
                yield self[i]
            return
        lo, hi = positions.start, positions.stop
        columns, spilled = self._columns, self.starts.is_spilled
        while lo < hi:
            c, j = divmod(lo, CHUNK)
            k = min(CHUNK, j + hi - lo)
            if spilled(c):  # a block at a time
                k = min(k, (j // BLOCK + 1) * BLOCK)
            parts = [column.part(c, j, k) for column in columns]
            for w, start, end, wire in zip(*parts, strict=True):
                kind, origin, text, u, du = fields[w]
                yield event(kind, origin, start, end, wire, text, u, du)
            lo += k - j

    def has_kind(self, kind: EventKind) -> bool:
        """Whether some event is of ``kind`` (no event made)."""
        wanted = {i for i, f in enumerate(self.fields) if f[0] is kind}
        return bool(wanted) and any(w in wanted for w in self.which)

    def in_start_order(self) -> bool:
        """Whether every start is at or after the one before (no event made)."""
        last = -_INF
        for part in self.starts.parts(0, len(self)):
            if part and part[0] < last:
                return False
            if not all(part[i - 1] <= part[i] for i in range(1, len(part))):
                return False
            last = part[-1] if part else last
        return True

    def nbytes(self) -> int:
        """The columns' own size (bytes): what the store holds an event, in RAM or spilled."""
        return sum(c.nbytes() for c in self._columns)

    def resident_nbytes(self) -> int:
        """What of the columns is in RAM (bytes): about a chunk and a block read back,
        whatever the store's length."""
        return sum(c.resident_nbytes() for c in self._columns)


class StoredEvents(Sequence[Event]):
    """Some of a :class:`CompactEvents`' events, by their positions in it, made again at
    each read: what a record's list of events (a command's characters, a reply's) holds
    once its window's events are let go (issue 22: a sensor's run kept its exchanges'
    ~35,000 events of an hour's capture as objects, 4.3 MB, while its cases judged them;
    here a run of positions takes ~90 bytes, whatever its length).

    Read-only (a record's list is not changed once made: the caller keeps a list where it
    may be). Reads as the list it stands for does: by item and slice (a list), in order,
    ``==`` to a list or another sequence of equal events, ``+`` a list. Its events are new
    objects at each read, so nothing may hold one of them for the same as another read's
    (an attempt's reply text is kept with the sequence itself: ``Attempt.reply_text``)."""

    __slots__ = ("store", "lo", "n", "at")

    def __init__(self, store: CompactEvents, positions: Sequence[int]) -> None:
        self.store = store
        n = len(positions)
        lo = positions[0] if n else 0
        # a run of consecutive positions (nearly always) held as its first and length
        runs = (
            n == 0
            or positions[-1] - lo == n - 1
            and all(b - a == 1 for a, b in zip(positions, positions[1:], strict=False))
        )
        self.lo, self.n = lo, n
        self.at: array | None = None
        if not runs:
            self.at = array("I" if max(positions) < 2**32 else "q", positions)

    @classmethod
    def run(cls, store: CompactEvents, lo: int, n: int) -> StoredEvents:
        """The ``n`` events from position ``lo`` on (a run, as one made of ``range(lo, lo +
        n)`` holds it; the positions not walked): a held record's list made again
        (:class:`~conformance.offline.held_exchanges.HeldExchanges`)."""
        made = cls.__new__(cls)
        made.store, made.lo, made.n, made.at = store, lo, n, None
        return made

    def positions(self) -> Sequence[int]:
        """The events' positions in the store, in order."""
        return range(self.lo, self.lo + self.n) if self.at is None else self.at

    def __len__(self) -> int:
        return self.n

    @overload
    def __getitem__(self, i: int) -> Event: ...
    @overload
    def __getitem__(self, i: slice) -> list[Event]: ...
    def __getitem__(self, i: int | slice) -> Event | list[Event]:
        if isinstance(i, slice):
            return list(self._made(self.positions()[i]))
        return self.store[self.positions()[i]]

    def __iter__(self) -> Iterator[Event]:
        return self._made(self.positions())

    def _made(self, positions: Sequence[int]) -> Iterator[Event]:
        if isinstance(positions, range) and positions.step == 1:
            return self.store.made(positions)
        store = self.store
        return (store[k] for k in positions)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, (list, tuple, StoredEvents)):
            return NotImplemented
        return len(self) == len(other) and all(a == b for a, b in zip(self, other, strict=True))

    __hash__ = None  # type: ignore[assignment]  # (a list's is None too)

    def __add__(self, other: Iterable[Event]) -> list[Event]:
        return [*self, *other]

    def __radd__(self, other: Iterable[Event]) -> list[Event]:
        return [*other, *self]

    def __repr__(self) -> str:
        return repr(list(self))


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


__all__ = ["Column", "CompactEvents", "NotCompact", "Spill", "StoredEvents"]
