"""A sensor pass's measurements held as rows, each made again when a case reads it (issue 22:
a busy capture judged in bounded memory), as :mod:`.held_exchanges` holds its exchanges.

The sensor pass (:func:`~.sensor_windows.sensor_records`) kept a sensor's ``Measurement``
objects for its whole run and, through them, their start and data ``Exchange`` objects
(~1.4 KB an exchange: 2.6 MB at an hour of a measuring bus for its first sensor, the last
thing a passive judgement held that grew with the capture's length). Here a measurement
whose parts are all plain is a row once what decides its ``aborted_by`` has come
(:class:`~.sensor_windows.Disturbances`): where its start and data are among the held
exchanges (their indices: 4 bytes each, the exchanges then rows of their own), its ttt,
count, value count and stamps (8 bytes each, the floats exactly), the run of the store its
wait's characters are (4 + 4), its values' text (its bytes and 8 + 2), its binary
packets (their bytes, 8 each and 8) and its
``aborted_by`` (2: which distinct one). A case that reads it gets a ``Measurement`` equal,
field for field, to the one the pass made, whose start and data are the very exchanges the
held exchanges give while anything holds them (their weak cache); reading it again while
it is held gives the same object (a weak cache too).

Kept as objects: a measurement not yet decided (until it is), and one a row cannot say
exactly (a stall of the tool's host over its wait, a wait's characters not
one run of the store, an exchange held as the object, any other field), with its exchanges:
what reads them gets the pass's objects as before.
"""

from __future__ import annotations

import weakref
from array import array
from collections.abc import Collection, Iterable, Iterator, Sequence
from typing import overload

from ..event_store import StoredEvents
from ..protocol.commands import Kind
from ..tool_recorder.records import Measurement
from .held_exchanges import HeldExchanges, _events

#: the fields a measurement's ``__dict__`` may hold for a row to stand for it
_FIELDS = frozenset(
    ("command", "start", "ttt", "count", "reply_end", "waited_events", "service_request_end")
) | {"data", "values", "packets", "binary_value_count", "aborted_by", "wait_stall"}
#: flags: which of the optional fields is None
_NO_TTT, _NO_COUNT, _NO_REPLY_END, _NO_SR_END = 1, 2, 4, 8
_MOST_INT = 2**62
_SEP = "\x00"  # between a measurement's values in its text (a value holding one: the object)


class HeldMeasurements(Sequence[Measurement]):
    """A sensor pass's measurements in order (see the module's docstring): read by index,
    slice and in order like the list it stands for, and by kind (:meth:`of_kinds`) without
    making those of other kinds. Appended to by the pass (:meth:`add`, :meth:`settle`),
    read-only after."""

    def __init__(self, exchanges: HeldExchanges) -> None:
        self.exchanges = exchanges
        store = exchanges.store
        code = "I" if store is None or len(store) < 2**32 - 1 else "q"
        self.row = array("i")  # per measurement: its row (-1: held as the object)
        self.kept: dict[int, Measurement] = {}  # by index: held as the object
        self.pending: dict[int, Measurement] = {}  # by index: not yet decided (kept too)
        self.aborts: list[str | None] = [None]
        self._abort_of: dict[str | None, int] = {None: 0}
        # per row
        self.start, self.data_first, self.data = array("I"), array("I", [0]), array("I")
        self.ttt, self.count, self.binary_count = array("q"), array("q"), array("q")
        self.reply_end, self.sr_end = array("d"), array("d")
        self.waited, self.waited_n = array(code), array("I")
        self.values_first, self.values_n = array("q", [0]), array("H")
        self.text = bytearray()
        # per row: where its packets' ends begin in ``packet_ends`` (ends into ``blob``)
        self.packets_first, self.packet_ends = array("q", [0]), array("q")
        self.blob = bytearray()
        self.flags, self.abort = array("B"), array("H")
        self._made: weakref.WeakValueDictionary[int, Measurement] = weakref.WeakValueDictionary()

    # -- held by the pass --------------------------------------------------------------
    def add(self, measurements: Iterable[Measurement]) -> None:
        """A window's measurements, in order, after their exchanges were added to the held
        exchanges: held as the objects until :meth:`settle` says they are decided."""
        for m in measurements:
            i = len(self.row)
            self.row.append(-1)
            self.kept[i] = self.pending[i] = m

    def settle(self, watched: Collection[int]) -> None:
        """The measurements added whose ``id`` is not in ``watched`` (their ``aborted_by``
        decided) held as rows where a row says them exactly, their exchanges let go."""
        for i in [i for i, m in self.pending.items() if id(m) not in watched]:
            m = self.pending.pop(i)
            indices = self._row(m)
            if indices is None:
                continue  # held as the object for good
            del self.kept[i]
            self.row[i] = len(self.flags) - 1
            for k in indices:
                self.exchanges.release(k)
            self._made[i] = m

    def _row(self, m: Measurement) -> list[int] | None:
        """``m`` appended as a row, the indices of its exchanges returned; None (nothing
        appended) where a part of it is not plain (see the module's docstring)."""
        if type(m) is not Measurement or not _FIELDS.issuperset(m.__dict__):
            return None
        if m.wait_stall is not None or type(m.packets) is not list:
            return None
        if any(type(p) is not bytes for p in m.packets):
            return None
        if m.command is not m.start.command or type(m.data) is not list:
            return None
        if type(m.values) is not list or len(m.values) > 2**16 - 1:
            return None
        if any(type(v) is not str or _SEP in v for v in m.values):
            return None
        if m.values == [""]:
            return None  # (one empty value reads back as none)
        ints = (m.ttt, m.count, m.binary_value_count)
        if any(v is not None and (type(v) is not int or abs(v) >= _MOST_INT) for v in ints):
            return None
        if m.binary_value_count is None:
            return None
        stamps = (m.reply_end, m.service_request_end)
        if any(v is not None and type(v) is not float for v in stamps):
            return None
        if m.aborted_by is not None and type(m.aborted_by) is not str:
            return None
        waited = self._waited(m.waited_events)
        if waited is None:
            return None
        xs = self.exchanges
        indices = [xs.index_of(x) for x in (m.start, *m.data)]
        if any(k is None for k in indices) or len(set(indices)) != len(indices):
            return None
        at = [k for k in indices if k is not None]
        self.start.append(at[0])
        self.data.extend(at[1:])
        self.data_first.append(len(self.data))
        flags = (_NO_TTT if m.ttt is None else 0) | (_NO_COUNT if m.count is None else 0)
        flags |= _NO_REPLY_END if m.reply_end is None else 0
        flags |= _NO_SR_END if m.service_request_end is None else 0
        self.ttt.append(m.ttt or 0)
        self.count.append(m.count or 0)
        self.binary_count.append(m.binary_value_count)
        self.reply_end.append(m.reply_end or 0.0)
        self.sr_end.append(m.service_request_end or 0.0)
        self.waited.append(waited[0])
        self.waited_n.append(waited[1])
        self.text += _SEP.join(m.values).encode("utf-8", "surrogatepass")
        self.values_first.append(len(self.text))
        self.values_n.append(len(m.values))
        for p in m.packets:
            self.blob += p
            self.packet_ends.append(len(self.blob))
        self.packets_first.append(len(self.packet_ends))
        self.abort.append(self._abort(m.aborted_by))
        self.flags.append(flags)
        return at

    def _waited(self, events: object) -> tuple[int, int] | None:
        if type(events) is list and not events:
            return (0, 0)
        store = self.exchanges.store
        if isinstance(events, StoredEvents) and events.at is None and events.store is store:
            return (events.lo, events.n) if events.n else None
        return None

    def _abort(self, why: str | None) -> int:
        at = self._abort_of.get(why)
        if at is None:
            at = self._abort_of[why] = len(self.aborts)
            self.aborts.append(why)
        return at

    # -- read by the cases -------------------------------------------------------------
    def __len__(self) -> int:
        return len(self.row)

    @overload
    def __getitem__(self, i: int) -> Measurement: ...
    @overload
    def __getitem__(self, i: slice) -> list[Measurement]: ...
    def __getitem__(self, i: int | slice) -> Measurement | list[Measurement]:
        if isinstance(i, slice):
            return [self._measurement(k) for k in range(len(self))[i]]
        n = len(self)
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError("measurement index out of range")
        return self._measurement(i)

    def __iter__(self) -> Iterator[Measurement]:
        return map(self._measurement, range(len(self)))

    def of_kinds(self, kinds: Collection[Kind], whole: bool = False) -> list[Measurement]:
        """The measurements whose command is of ``kinds`` (``whole``: only those whose
        ``aborted_by`` is None), in order (no other one made)."""
        xs, found = self.exchanges, []
        for i, r in enumerate(self.row):
            if r < 0:
                m = self.kept[i]
                if m.command.kind in kinds and not (whole and m.aborted_by is not None):
                    found.append(m)
                continue
            command = xs.shapes[xs.shape[self.start[r]]][1]
            if command.kind not in kinds or (whole and self.abort[r]):  # type: ignore[attr-defined]
                continue
            found.append(self._measurement(i))
        return found

    def resident_nbytes(self) -> int:
        """The rows' bytes (the objects kept apart)."""
        columns = (self.row, self.start, self.data_first, self.data, self.ttt, self.count)
        columns += (self.binary_count, self.reply_end, self.sr_end, self.waited, self.waited_n)
        columns += (self.values_first, self.values_n, self.flags, self.abort)
        columns += (self.packets_first, self.packet_ends)
        return sum(c.itemsize * len(c) for c in columns) + len(self.text) + len(self.blob)

    def _measurement(self, i: int) -> Measurement:
        kept = self.kept.get(i)
        if kept is not None:
            return kept
        made = self._made.get(i)
        if made is None:
            made = self._make(self.row[i])
            self._made[i] = made
        return made

    def _make(self, r: int) -> Measurement:
        xs, flags = self.exchanges, self.flags[r]
        start = xs[self.start[r]]
        data = [xs[k] for k in self.data[self.data_first[r] : self.data_first[r + 1]]]
        n = self.values_n[r]
        text = self.text[self.values_first[r] : self.values_first[r + 1]]
        values = text.decode("utf-8", "surrogatepass").split(_SEP) if n else []
        lo, hi = self.packets_first[r], self.packets_first[r + 1]
        ends = self.packet_ends
        packets = [bytes(self.blob[ends[k - 1] if k else 0 : ends[k]]) for k in range(lo, hi)]
        store = xs.store
        assert store is not None
        return Measurement(
            start.command,  # type: ignore[arg-type]
            start,
            ttt=None if flags & _NO_TTT else self.ttt[r],
            count=None if flags & _NO_COUNT else self.count[r],
            reply_end=None if flags & _NO_REPLY_END else self.reply_end[r],
            waited_events=_events(store, self.waited[r], self.waited_n[r]),  # type: ignore[arg-type]
            service_request_end=None if flags & _NO_SR_END else self.sr_end[r],
            data=data,
            values=values,
            packets=packets,
            binary_value_count=self.binary_count[r],
            aborted_by=self.aborts[self.abort[r]],
        )
