"""Where a long recording may be cut into windows read one after the other (issue 22).

A windowed judge reads an hour's capture a window at a time and lets each window's events and
view go once it is read. A cut is only safe where the bus is idle in the sense the records
need: the window's first transmission begins with a break (a new sequence: the recorder woke
the line), no sensor frame was still going when it began (nor when its break began: a break
over a reply is known only beside that reply), it is no retry of the transmission
before it (same text: :func:`~.rebuilt_records.rebuild_records` makes both one exchange), and
it falls inside no exchange (its retries) and no measurement, from the measurement command to
its last data command. A measurement's records depend on nothing after its last data
exchange: the one after it either ended it (no data command of it) or is left out of it
either way, so a window that ends there rebuilds it the same. A gap longer than the standby
time alone is no such place: a concurrent measurement's data may come minutes later, after
other sensors' exchanges (R-4.4.7-05).

What a window still needs from before is carried explicitly, not re-read: whether each
address's last measurement asked for a CRC (a data reply read again long after its
measurement is judged by it), :func:`rebuild_windowed` passes it from window to window. The
records need nothing else; the timing judges will (the line's last activity before a window's
first break, the marking a break follows: :meth:`~.segments.TranscriptView.previous_activity`),
and the rules that count over the whole run their compact observations: not done here yet.

The cut is a pure function of the view (:func:`window_starts`); a window's view is
:func:`~.segments.read_view` of that window's events alone (:func:`window_events`), equal to
the whole view's transmissions of the window: the direction inference starts over at every
break (only a service request's announced ttt outlives one, and it changes how sure a
direction is, never which side it gives).
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Callable, Iterable, Iterator, Sequence
from operator import attrgetter
from typing import overload

from ..tool_recorder.policy import Policy
from ..tool_recorder.records import Attempt
from ..transcript import Event, EventKind
from .rebuilt_records import Rebuilt, rebuild_records
from .segments import TranscriptView, Transmission, read_sides, read_view, sided_view

_START = attrgetter("start")  # the view's order (read_view sorts by start, stably)

#: :func:`stream_windows` asks where the held events may be cut at every this many breaks,
#: not at each: a busy bus's window is one sequence, so asking at each break read every
#: window's view and records twice (it and the next one held), in a windowed judge's pass
#: over an hour's capture more than the judges themselves; asked every 16th, each is read
#: about 16/15 times, and the windows given out are the same (where a window may begin
#: depends on nothing after the next window's first transmission, which a later ask holds
#: too), at most 16 windows later and no more events held than 16 sequences
SETTLE_BREAKS = 16


def window_starts(view: TranscriptView, records: Rebuilt | None = None) -> list[int]:
    """The indices of ``view``'s transmissions where a window may begin (the first, 0,
    always when there is one): see the module's docstring for what makes a place safe.
    ``records``: ``view``'s (:func:`~.rebuilt_records.rebuild_records`; made if not given),
    which say where each exchange and measurement begins and ends."""
    if not view.transmissions:
        return []
    records = records if records is not None else rebuild_records(view)
    index = {id(t.chars[0]): i for i, t in enumerate(view.transmissions)}
    spans = [_span(x.attempts, x.attempts, index) for x in records.exchanges]
    spans += [_span(m.start.attempts, (m.data or [m.start])[-1].attempts, index)
              for m in records.measurements]  # fmt: skip
    inside = bytearray(len(view.transmissions) + 1)  # 1: no window begins at that index
    for first, last in spans:
        inside[first + 1 : last + 1] = b"\1" * max(0, last - first)
    before = view.transmissions[0]
    starts = [0]
    for i, t in enumerate(view.transmissions[1:], 1):
        if not inside[i] and _opens(before, t):
            starts.append(i)
        before = t
    return starts


def _span(
    first: Sequence[Attempt], last: Sequence[Attempt], index: dict[int, int]
) -> tuple[int, int]:
    """The transmissions from ``first``'s first attempt to ``last``'s last one."""
    return index[id(first[0].command_events[0])], index[id(last[-1].command_events[0])]


def _opens(before: Transmission, t: Transmission) -> bool:
    """``t`` begins a new sequence that nothing of ``before`` runs into: nor does ``t``'s
    break cut into ``before``'s reply (:attr:`Transmission.cut_by`): a window that began
    there would leave ``before``'s view without the break, its reply read as the sensor's
    invalid one instead of one the recorder cut (``judges.recorder.replies.cut_off``)."""
    return (
        t.break_event is not None
        and t.cut is None
        and before.cut_by is None
        and t.text != before.text
    )


def window_events(
    events: Sequence[Event], view: TranscriptView, starts: Sequence[int]
) -> Iterator[list[Event]]:
    """``events`` (one recording; notes are left out) in the order the view reads them (by
    start), cut before the break of each window's first transmission: each window's events.
    What comes before the first transmission stays in the first window."""
    breaks = iter([view.transmissions[i].break_event for i in starts[1:]] + [None])
    cut = next(breaks)
    window: list[Event] = []
    for e in sorted([e for e in events if e.kind is not EventKind.NOTE], key=_START):
        if e is cut:
            yield window
            window = []
            cut = next(breaks)
        window.append(e)
    if window or not starts:
        yield window


def stream_windows(
    events: Iterable[Event], policy: Policy | None = None, *, uncertainty: float = 0.0
) -> Iterator[list[Event]]:
    """The windows :func:`window_starts` finds in the whole recording, cut from ``events``
    as they come (by start, as a capture's decoder gives them), holding only the events not
    yet given out: what comes after a window's last transmission stays held until a break
    shows where the next may begin, and a measurement whose data may still come (its
    concurrent measurement's next data command, minutes later) holds everything from its
    command on until something ends it. Each break asks the held events' view and records
    again: a long open stretch costs a rebuild a break, the price of a bounded hold. The CRC
    expectations the windows before leave (:func:`rebuild_windowed`) move no cut: they judge
    only data replies of measurements begun before the held events, none of the held ones'
    data, and two transmissions of one text in a row are never cut apart anyway. The held
    events are asked where they may be cut at every :data:`SETTLE_BREAKS`-th break."""
    return (window for window, _codes in _cut_windows(events, policy, uncertainty))


def stream_window_views(
    events: Iterable[Event], policy: Policy | None = None, *, uncertainty: float = 0.0
) -> Iterator[tuple[list[Event], TranscriptView]]:
    """:func:`stream_windows`' windows, each with its view, the one
    :func:`~.segments.read_view` reads of the window alone, which a windowed judge reads.
    Where the directions were inferred (origin ``bus``), the cut inferred them once over
    the held events it read, and since the inference starts over at every window's first
    break, a window's sides are those: its view is cut with them
    (:func:`~.segments.sided_view`), not inferred a second time."""
    for window, codes in _cut_windows(events, policy, uncertainty):
        yield window, window_view(window, codes)


def stream_window_sides(
    events: Iterable[Event], policy: Policy | None = None, *, uncertainty: float = 0.0
) -> Iterator[tuple[list[Event], bytearray | None]]:
    """:func:`stream_windows`' windows, each with its events' sides as the cut inferred them
    (None: the origins gave them): what a judge that reads some windows again later keeps
    (one byte an event) to read each one's view again (:func:`window_view`) the same."""
    return _cut_windows(events, policy, uncertainty)


def window_view(window: list[Event], codes: bytearray | None) -> TranscriptView:
    """The view of ``window`` (one of :func:`stream_window_sides`'), cut with the sides
    ``codes`` gives where the directions were inferred: :func:`stream_window_views`' view."""
    return read_view(window) if codes is None else sided_view(window, codes)


def _cut_windows(
    events: Iterable[Event], policy: Policy | None, uncertainty: float
) -> Iterator[tuple[list[Event], bytearray | None]]:
    """:func:`stream_windows`' windows, each with its events' inferred sides (None: the
    origins gave them)."""
    held: list[Event] = []
    breaks = 0  # the breaks held since the held events were last settled
    due = SETTLE_BREAKS  # how many before they are asked again (:func:`_next_ask`)
    for e in events:
        if e.kind is EventKind.NOTE:
            continue
        if held and e.start < held[-1].start:
            raise ValueError(f"events out of order at {e.start!r}: windows need them by start")
        if e.kind is EventKind.BREAK and held:  # the transmission before it is complete
            breaks += 1
            if breaks >= due:
                yield from _settled(held, policy, uncertainty, final=False)
                breaks, due = 0, _next_ask(held)
        held.append(e)
    if held:
        yield from _settled(held, policy, uncertainty, final=True)


def _next_ask(held: list[Event]) -> int:
    """After a settling left ``held`` (what no window could be given out of yet): how many
    breaks before the held events are asked again, :data:`SETTLE_BREAKS` or half the breaks
    still held if more. A stretch where no window may begin (no command opened by a break:
    a sim run's sensor, 54,000 events and 420 breaks of ``wrong-crc``'s run) was read again
    every 16 breaks, quadratic (2.3 s of CPU to cut that run's 95,000 events); asked at
    geometric steps it is read a few times over. The windows given out are the same (where
    one may begin depends on nothing after the next one's first transmission), later."""
    kept = sum(1 for e in held if e.kind is EventKind.BREAK)
    return max(SETTLE_BREAKS, kept // 2)


def _settled(
    held: list[Event],
    policy: Policy | None,
    uncertainty: float,
    *,
    final: bool,
) -> Iterator[tuple[list[Event], bytearray | None]]:
    """The windows of ``held`` that nothing to come can change, taken out of it (all of
    them when ``final``), each with its events' sides as the held events' view inferred
    them (None: the origins gave them)."""
    view, codes = read_sides(held)
    if final and not view.transmissions:  # nothing the recorder sent: one window
        yield held[:], codes
        held.clear()
        return
    records = rebuild_records(view, policy, uncertainty=uncertainty)
    starts = window_starts(view, records)
    if not final and records.open:  # no window begins after an open measurement's command
        index = {id(t.chars[0]): i for i, t in enumerate(view.transmissions)}
        first = min(index[id(m.start.attempts[0].command_events[0])] for m in records.open)
        starts = [i for i in starts if i <= first]
    if final:
        starts.append(len(view.transmissions))  # the rest is the last window
    taken = 0
    for i in starts[1:]:
        end = len(held) if i == len(view.transmissions) else _position(held, view, i, taken)
        yield held[taken:end], None if codes is None else codes[taken:end]
        taken = end
    del held[:taken]


def _position(held: list[Event], view: TranscriptView, i: int, after: int) -> int:
    """Where in ``held`` transmission ``i``'s break is (past index ``after``)."""
    brk = view.transmissions[i].break_event
    return next(j for j in range(after, len(held)) if held[j] is brk)


def rebuild_windowed(
    events: Sequence[Event],
    view: TranscriptView,
    policy: Policy | None = None,
    *,
    uncertainty: float = 0.0,
    only: str | None = None,
) -> Iterator[Rebuilt]:
    """Each window's records, read from its own events alone (a view of its own), with what
    the windows before it left carried in: together the records
    :func:`~.rebuilt_records.rebuild_records` gives the whole ``view``, in order. ``view``
    and its records only say where the windows are (:func:`window_starts`)."""
    whole = rebuild_records(view, policy, uncertainty=uncertainty)
    carried: dict[str, bool] = {}
    for window in window_events(events, view, window_starts(view, whole)):
        part = read_view(window)
        yield rebuild_records(part, policy, uncertainty=uncertainty, only=only, carried=carried)


__all__ = [
    "SETTLE_BREAKS",
    "rebuild_windowed",
    "stream_window_sides",
    "stream_window_views",
    "stream_windows",
    "window_events",
    "window_starts",
    "window_view",
]


class WindowedTransmissions(Sequence[Transmission]):
    """The transmissions of a whole recording's view, read from its windows' views (each
    window's view its own, read again when asked: ``view_of(w)``), none held but the last
    window read: what a report's search of the whole run reads
    (:func:`~.runs.whole_cut`, issue 22: the whole view held every event of an hour's
    capture through every run). A window's transmissions are the whole view's of that
    window (see the module's docstring), so item ``i`` equals the whole view's
    (``tests/offline/test_windowed_transmissions.py``). ``before``: how many of them come
    before each window (one more item than windows: the last is the count);
    ``chars_only``: only those with characters (a command's, what the reports search)."""

    def __init__(
        self,
        view_of: Callable[[int], TranscriptView],
        before: Sequence[int],
        chars_before: Sequence[int],
        *,
        chars_only: bool = False,
    ) -> None:
        self.view_of, self.before, self.chars_before = view_of, before, chars_before
        self.chars_only = chars_only
        self._last: tuple[int, list[Transmission]] | None = None

    def with_chars(self) -> WindowedTransmissions:
        """The same, with characters only (``[t for t in self if t.chars]``)."""
        return WindowedTransmissions(self.view_of, self.before, self.chars_before, chars_only=True)

    def _counts(self) -> Sequence[int]:
        return self.chars_before if self.chars_only else self.before

    def __len__(self) -> int:
        return self._counts()[-1]

    def _window(self, w: int) -> list[Transmission]:
        if self._last is None or self._last[0] != w:
            ts = self.view_of(w).transmissions
            self._last = (w, [t for t in ts if t.chars] if self.chars_only else list(ts))
        return self._last[1]

    @overload
    def __getitem__(self, i: int) -> Transmission: ...
    @overload
    def __getitem__(self, i: slice) -> list[Transmission]: ...
    def __getitem__(self, i: int | slice) -> Transmission | list[Transmission]:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        if i < 0:
            i += len(self)
        if not 0 <= i < len(self):
            raise IndexError("transmission index out of range")
        counts = self._counts()
        w = bisect_right(counts, i) - 1
        return self._window(w)[i - counts[w]]

    def __iter__(self) -> Iterator[Transmission]:
        counts = self._counts()
        for w in range(len(counts) - 1):
            if counts[w + 1] > counts[w]:
                yield from self._window(w)
