"""A sensor pass's exchanges held as columns, each made again when a case reads it (issue 22:
a busy capture judged in bounded memory).

The sensor pass (:func:`~.sensor_windows.sensor_records`) keeps a sensor's exchanges for its
whole run. Held as objects, even with their events as positions into the loaded store
(:mod:`.stored_records`), each took ~1.3 KB (memory21): the ``Exchange`` and ``Attempt`` and
their ``__dict__``, five lists, two ``StoredEvents``, the break ``Event`` and its floats, the
decoded reply text and its cache tuple. An hour of a busy bus is ~1,500 exchanges a sensor
(the first sensor's run's peak grew 2 MB an hour by them), and no case reads most of them:
the passive cases ask for the exchanges of a few kinds (``aI!``, ``a!``, ``aX!``) and for the
measurements, whose own exchanges they read through them.

Here an exchange whose parts are all plain is held as a row of numbers: which distinct
(text, command, binary, expect_reply) it has (4 bytes) and where its attempts begin (4);
each attempt where its break, command and reply are in the store (4 each), how many
characters (2 each), which reason (2), its end (8, exactly the float) and its sequence and
retry (1 each): 36 bytes an exchange of one try (``tests/offline/test_held_exchanges.py``). A case
that reads it gets an ``Exchange`` equal, field for field, to the one the pass made; while
it holds it, reading it again gives the same object (a weak cache), so identity within a
case is kept. Kept as objects: the exchanges a measurement holds while that measurement is
an object (a measurement's start and data are the very exchanges of the list: their rows are
made too, and once the measurement is a row itself, :mod:`.held_measurements`, they are let
go, :meth:`HeldExchanges.release`), and any with a part a row cannot say (a stall of the
tool's host, stray or late characters, events not one run of the store's, a late
neighbour): what reads them gets the pass's objects as before.
"""

from __future__ import annotations

import weakref
from array import array
from collections.abc import Collection, Iterable, Iterator, Sequence
from typing import overload

from ..event_store import CompactEvents, StoredEvents
from ..protocol.commands import Kind
from ..tool_recorder.records import Attempt, Exchange
from ..transcript import Event
from .stored_records import Positions

#: the most characters a row's command or reply holds, and the most tries it counts (its
#: columns' widths: 2 bytes and 1; a longer one is held as the object)
_MOST_CHARS, _MOST_TRIES = 2**16 - 1, 2**8 - 1
#: (text, command, binary, expect_reply): what exchanges of one command share
Shape = tuple[str, object, bool, bool]


class HeldExchanges(Sequence[Exchange]):
    """A sensor pass's exchanges in order (see the module's docstring): read by index, slice
    and in order like the list it stands for, and by kind (:meth:`of_kinds`) without making
    those of other kinds. Appended to by the pass (:meth:`add`), read-only after."""

    def __init__(self, store: CompactEvents | None) -> None:
        self.store = store
        code = "I" if store is None or len(store) < 2**32 - 1 else "q"
        self.shapes: list[Shape] = []
        self._shape_of: dict[tuple[str, bool, bool], int] = {}
        self.reasons: list[str] = []
        self._reason_of: dict[str, int] = {}
        self.shape = array("I")  # per exchange: its index in ``shapes``
        self.first = array("I", [0])  # per exchange: its first attempt's row (and the end)
        # per attempt: break position + 1 (0: none), command and reply runs, reason, end,
        # sequence and retry
        self.brk, self.cmd, self.rep = array(code), array(code), array(code)
        self.cmd_n, self.rep_n = array("H"), array("H")
        self.reason, self.end = array("H"), array("d")
        self.sequence, self.retry = array("B"), array("B")
        self.kept: dict[int, Exchange] = {}  # by index: held as the object
        #: by index: a measurement's, its rows made too, held as the object until that
        #: measurement is held as a row (:meth:`release`) or for good where it cannot be
        self.held_for: dict[int, Exchange] = {}
        self._index_of: dict[int, int] = {}  # id of each of ``held_for`` -> its index
        self._made: weakref.WeakValueDictionary[int, Exchange] = weakref.WeakValueDictionary()

    # -- held by the pass --------------------------------------------------------------
    def add(
        self, positions: Positions | None, exchanges: Iterable[Exchange], keep: Collection[int]
    ) -> None:
        """A window's exchanges, in order, after :func:`~.stored_records.store_records`;
        those whose ``id`` is in ``keep`` (a measurement's) also held as the objects while
        their measurement is (:meth:`release`)."""
        for x in exchanges:
            i = len(self.shape)
            shape = self._shape(x)
            rows = None
            if positions is not None and shape is not None:
                rows = self._rows(positions, x)
            if shape is None or rows is None:
                self.kept[i] = x
                shape = self._loose_shape(x)
            else:
                self._append_rows(rows)
                if id(x) in keep:
                    self.held_for[i] = x
                    self._index_of[id(x)] = i
            self.shape.append(shape)
            self.first.append(len(self.end))

    def _shape(self, x: Exchange) -> int | None:
        """``x``'s shape index (made once per distinct one); None where an exchange of its
        text, binary and expect_reply had another command (not expected: held as is)."""
        key = (x.text, x.binary, x.expect_reply)
        at = self._shape_of.get(key)
        if at is None:
            at = self._shape_of[key] = len(self.shapes)
            self.shapes.append((x.text, x.command, x.binary, x.expect_reply))
            return at
        return at if self.shapes[at][1] == x.command else None

    def _loose_shape(self, x: Exchange) -> int:
        """A shape for an exchange held as the object (its command's kind is all it is
        asked): its own entry where the shared one's command differs."""
        at = self._shape(x)
        if at is None:
            at = len(self.shapes)
            self.shapes.append((x.text, x.command, x.binary, x.expect_reply))
        return at

    def _rows(self, positions: Positions, x: Exchange) -> list[tuple] | None:
        """``x``'s attempts as rows, None where a part of it is not plain (see the module's
        docstring)."""
        if x.heard_late or x.late_before is not None or x.next_sent or x.sent_before is not None:
            return None
        if not _EXCHANGE_FIELDS.issuperset(x.__dict__):
            return None
        rows = []
        for a in x.attempts:
            if a.stall is not None or a.stray_events or not _ATTEMPT_FIELDS.issuperset(a.__dict__):
                return None
            cmd, rep = _run(positions, a.command_events), _run(positions, a.reply_events)
            brk = 0
            if a.break_event is not None:
                at = positions.at.get(id(a.break_event))
                if at is None:
                    return None
                brk = at + 1
            if cmd is None or rep is None or max(cmd[1], rep[1]) > _MOST_CHARS:
                return None
            if max(a.sequence, a.retry) > _MOST_TRIES or len(self.reasons) > _MOST_CHARS:
                return None
            rows.append((brk, cmd, rep, self._reason(a.reason), a.end, a.sequence, a.retry))
        return rows

    def _reason(self, reason: str) -> int:
        at = self._reason_of.get(reason)
        if at is None:
            at = self._reason_of[reason] = len(self.reasons)
            self.reasons.append(reason)
        return at

    def _append_rows(self, rows: list[tuple]) -> None:
        for brk, cmd, rep, reason, end, sequence, retry in rows:
            self.brk.append(brk)
            self.cmd.append(cmd[0])
            self.cmd_n.append(cmd[1])
            self.rep.append(rep[0])
            self.rep_n.append(rep[1])
            self.reason.append(reason)
            self.end.append(end)
            self.sequence.append(sequence)
            self.retry.append(retry)

    def index_of(self, x: Exchange) -> int | None:
        """The index of ``x``, a measurement's exchange held as the object with its rows
        made (None: held for good as the object, or not one of these)."""
        return self._index_of.get(id(x))

    def release(self, i: int) -> None:
        """Exchange ``i`` (a measurement's, :meth:`index_of`) no longer held as the object:
        its measurement is now a row pointing at it. Read again, it is the same object while
        anything holds it (the weak cache), else made again of its rows."""
        x = self.held_for.pop(i, None)
        if x is not None:
            del self._index_of[id(x)]
            self._made[i] = x

    # -- read by the cases -------------------------------------------------------------
    def __len__(self) -> int:
        return len(self.shape)

    @overload
    def __getitem__(self, i: int) -> Exchange: ...
    @overload
    def __getitem__(self, i: slice) -> list[Exchange]: ...
    def __getitem__(self, i: int | slice) -> Exchange | list[Exchange]:
        if isinstance(i, slice):
            return [self._exchange(k) for k in range(len(self))[i]]
        n = len(self)
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError("exchange index out of range")
        return self._exchange(i)

    def __iter__(self) -> Iterator[Exchange]:
        return map(self._exchange, range(len(self)))

    def of_kinds(self, kinds: Collection[Kind]) -> list[Exchange]:
        """The exchanges whose command is of ``kinds``, in order (no other one made)."""
        wanted = {
            k
            for k, s in enumerate(self.shapes)
            if s[1] is not None and s[1].kind in kinds  # type: ignore[attr-defined]
        }
        if not wanted:
            return []
        return [self._exchange(i) for i, s in enumerate(self.shape) if s in wanted]

    def resident_nbytes(self) -> int:
        """The rows' bytes (the shapes, reasons and kept objects apart)."""
        columns = (self.shape, self.first, self.brk, self.cmd, self.rep, self.cmd_n)
        columns += (self.rep_n, self.reason, self.end, self.sequence, self.retry)
        return sum(c.itemsize * len(c) for c in columns)

    def _exchange(self, i: int) -> Exchange:
        kept = self.kept.get(i)
        if kept is not None:
            return kept
        kept = self.held_for.get(i)
        if kept is not None:
            return kept
        made = self._made.get(i)
        if made is None:
            made = self._make(i)
            self._made[i] = made
        return made

    def _make(self, i: int) -> Exchange:
        text, command, binary, expect_reply = self.shapes[self.shape[i]]
        attempts = [self._attempt(r) for r in range(self.first[i], self.first[i + 1])]
        return Exchange(
            command,  # type: ignore[arg-type]
            text,
            attempts,
            binary=binary,
            expect_reply=expect_reply,
        )

    def _attempt(self, r: int) -> Attempt:
        store = self.store
        assert store is not None
        brk = self.brk[r]
        return Attempt(
            store[brk - 1] if brk else None,
            _events(store, self.cmd[r], self.cmd_n[r]),
            _events(store, self.rep[r], self.rep_n[r]),
            self.reasons[self.reason[r]],
            self.end[r],
            sequence=self.sequence[r],
            retry=self.retry[r],
        )


#: what an exchange's and an attempt's ``__dict__`` may hold for a row to stand for it:
#: their fields and the caches their properties make again (``_judged``, ``_text``)
_EXCHANGE_FIELDS = frozenset(
    ("command", "text", "attempts", "binary", "expect_reply", "heard_late", "late_before")
) | {"next_sent", "_judged", "sent_before"}
_ATTEMPT_FIELDS = frozenset(
    ("break_event", "command_events", "reply_events", "reason", "end", "sequence", "retry")
) | {"stray_events", "stall", "_text"}


def _run(positions: Positions, events: Sequence[Event]) -> tuple[int, int] | None:
    """``events`` (a record's list, as :mod:`.stored_records` left it) as (first position,
    count): an empty list, or a run of consecutive positions of the store; None else."""
    if type(events) is list and not events:
        return (0, 0)
    if isinstance(events, StoredEvents) and events.at is None and events.store is positions.store:
        return (events.lo, events.n)
    return None


def _events(store: CompactEvents, lo: int, n: int) -> Sequence[Event]:
    """A record's list of events again: an empty list, else the store's run (as
    :func:`~.stored_records.store_records` made it)."""
    return StoredEvents.run(store, lo, n) if n else []
