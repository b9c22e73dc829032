"""How much bus time a run could not have avoided, from its transcript.

On a real-time link every millisecond the tool spends is a millisecond of the user's bench
time, so the run reports the least time any recorder would have needed for the same
exchanges next to the wall time it took. The lower bound is the union of:

- every frame on the wire (8.33 ms each, either side) and every break as held;
- the 8.33 ms of marking that must follow each break (R-7.0-06);
- every stretch of marking that ended with the DUT starting to talk: its response delays,
  its service-request waits, its gaps inside a reply (the DUT's time, not the tool's);
- after the DUT's last character, the 7.5 ms it may still hold the line (R-7.0-11); after a
  command that got no reply, the 16.67 ms before a retry may start (R-7.2-02);
- the ttt a measurement announced, counted from the end of its ``atttn`` reply up to ttt
  or the tool's choice to end it sooner: for an M-type or V measurement the next break (an
  abort, or giving up), for a concurrent one (C, CC, Cn, CCn, HA, HB) the next command to the
  same sensor. A break does not end a concurrent measurement (R-4.4.7-05): a recorder that
  breaks to talk to other sensors meanwhile still waits for ttt before it reads the data.
- the rest of that ttt after the tool ended it sooner, when the tool's next command to the
  sensor is a data command (``aD0!``, ``aDB0!``...) sent once ttt has run out. That command
  asks whether the measurement the tool aborted (a break, R-4.4.5.1-01/02; a command to the
  sensor, R-4.4.7.1-01) left data: a sensor that had not aborted has them only when ttt has
  passed, and before it a sensor that did abort answers the same, so no recorder can show
  the abort sooner and the wait is the verdict's, not the tool's patience. The grace the
  tool listens past ttt for a late service request is still its own. (Until issue 22's
  fourth round this wait counted as overhead; ``tests/links/test_bus_time.py`` holds the
  rule, ``tests/links/test_bus_time_aborts_on_sim.py`` that the suite's abort cases meet it.)

Anything beyond that (retry spacing, listening windows for silence, patience past limits,
scheduling latency) is the tool's overhead.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from heapq import merge
from itertools import islice
from math import isfinite
from operator import attrgetter, itemgetter

from ..protocol.commands import Command, CommandError, Kind, parse_command
from ..protocol.responses import measurement_digits, parse_measurement_reply
from ..protocol.timing import CHAR_TIME, MARKING_AFTER_BREAK, RELEASE_LINE, RETRY_MIN
from ..transcript import TOOL, Event, EventKind, decode_7e1, in_start_order


@dataclass(frozen=True)
class BusTime:
    """The run's bus time (``run.bus`` in verdicts.json): the least time its exchanges needed
    on the wire, the span from first to last event, and how many frames and breaks."""

    lower_bound: float  # s the exchanges needed at the very least
    span: float  # s from the first to the last event on the wire
    frames: int
    breaks: int

    def to_json(self) -> dict[str, float | int]:
        return {
            "bus_lower_bound_s": round(self.lower_bound, 3),
            "bus_span_s": round(self.span, 3),
            "frames": self.frames,
            "breaks": self.breaks,
        }


def bus_time(events: Iterable[Event]) -> BusTime:
    wire = in_start_order(events)
    if not wire:
        return BusTime(0.0, 0.0, 0, 0)
    brk = EventKind.BREAK
    breaks = sum(1 for e in wire if e.kind is brk)
    frames = len(wire) - breaks
    waits = _announced_waits(wire)
    if _well_formed(wire):
        # each event's own span and the marking before it come in start order: merged as
        # they are made, never held (an hour's capture: 700,000 spans, 40 MB as a list)
        if _ends_after_starts(wire):  # in one loop (heapq.merge: 60% of bus_time's CPU)
            lower = _sweep(_spans_in_order(wire, sorted(waits)))
        else:
            spans = merge(_own_spans(wire), _gaps(wire), sorted(waits), key=itemgetter(0))
            lower = _sweep(spans)
    else:  # a time that is no number, or a break ending before it began: as it always was
        lower = _sweep(sorted([*_own_spans(wire), *_gaps(wire), *waits]))
    return BusTime(lower, wire[-1].end - wire[0].start, frames, breaks)


def bus_time_again(again: Callable[[], Iterable[Event]]) -> BusTime:
    """:func:`bus_time` of the events ``again()`` gives (each call: the same events from the
    first, in recorded order), read twice as they come and never held: a passive run's bus
    time with no list of the recording's events (issue 22). The first read checks what lets
    the events stand for :func:`bus_time`'s own list, counts them and finds the announced
    waits, the second sweeps the spans, each what :func:`bus_time` does with that list;
    events out of start order, or not well formed (a time that is no
    number, a break ending before it began, an event ending before it starts), are read
    into a list and given to :func:`bus_time`. ``tests/links/test_bus_time_again.py``
    holds the two to the same figures."""
    seen = _Seen()
    waits = _announced_waits(seen.watch(again()))  # type: ignore[arg-type]
    if not seen.plain:
        return bus_time(list(again()))
    if seen.first is None or seen.last is None:
        return BusTime(0.0, 0.0, 0, 0)
    lower = _sweep(_spans_in_order(_wire_of(again()), sorted(waits)))  # type: ignore[arg-type]
    return BusTime(lower, seen.last.end - seen.first.start, seen.frames, seen.breaks)


class _Seen:
    """What one read of the events found: whether they are in start order, notes aside,
    well formed and ending no earlier than they start (:func:`in_start_order` then gives
    them as they come, :func:`_well_formed` and :func:`_ends_after_starts` hold), how many
    frames and breaks, the first and the last."""

    def __init__(self) -> None:
        self.plain = True
        self.frames = self.breaks = 0
        self.first: Event | None = None
        self.last: Event | None = None

    def watch(self, events: Iterable[Event]) -> Iterator[Event]:
        """``events`` without their notes, each looked at as it passes."""
        brk = EventKind.BREAK
        last = None
        for e in _wire_of(events):
            start, end = e.start, e.end
            if (
                (last is not None and start < last)
                or not (isfinite(start) and isfinite(end))
                or end < start
            ):
                self.plain = False
            last = start
            if e.kind is brk:
                self.breaks += 1
            else:
                self.frames += 1
            if self.first is None:
                self.first = e
            self.last = e
            yield e


def _wire_of(events: Iterable[Event]) -> Iterator[Event]:
    """``events`` without their notes."""
    note = EventKind.NOTE
    return (e for e in events if e.kind is not note)


def uncounted(events: Iterable[Event]) -> list[tuple[float, float]]:
    """The stretches between the first and the last event on the wire that the lower bound
    does not count: the tool's overhead, where a run's wall time beyond its bound goes
    (``benchmarks/bus_efficiency.py --attribute`` sorts them by what the tool did there).
    Their lengths sum to the span less the part of the bound inside it."""
    wire = sorted((e for e in events if e.kind is not EventKind.NOTE), key=attrgetter("start"))
    if not wire:
        return []
    spans = sorted([*_own_spans(wire), *_gaps(wire), *_announced_waits(wire)])
    first, last = wire[0].start, max(e.end for e in wire)
    holes: list[tuple[float, float]] = []
    covered = first
    for start, end in spans:
        if start > covered:
            holes.append((covered, min(start, last)))
        covered = max(covered, end)
        if covered >= last:
            break
    return [(a, b) for a, b in holes if b > a]


def _own_spans(wire: list[Event]) -> Iterator[tuple[float, float]]:
    """Each event's own span, in the events' (start) order."""
    brk = EventKind.BREAK
    for e in wire:
        start = e.start
        yield (start, e.end + MARKING_AFTER_BREAK) if e.kind is brk else (start, start + CHAR_TIME)


def _gaps(wire: list[Event]) -> Iterator[tuple[float, float]]:
    """The marking before each event, as much of it as was forced: in start order, since
    each starts where the latest end so far lies."""
    previous = wire[0]
    previous_end = previous.end
    for e in islice(wire, 1, None):
        start = e.start
        if start > previous_end:
            yield previous_end, previous_end + _forced_gap(previous, e, start - previous_end)
        if e.end >= previous_end:
            previous, previous_end = e, e.end


def _ends_after_starts(wire: list[Event]) -> bool:
    """Whether no event ends before it starts: then the marking before an event starts at or
    after every earlier event's start (it starts at the latest end so far) and before the
    event's own, which is what lets :func:`_spans_in_order` place it without a merge."""
    return all(e.end >= e.start for e in wire)


def _spans_in_order(
    wire: list[Event], waits: list[tuple[float, float]]
) -> Iterator[tuple[float, float]]:
    """``merge(_own_spans(wire), _gaps(wire), waits, key=itemgetter(0))``, the same spans in
    the same order, ties included, made in one loop: for a well-formed ``wire`` in start
    order whose events end no earlier than they start (:func:`_ends_after_starts`), and
    ``waits`` sorted. The marking before an event comes after every earlier event's own
    span (it starts at the latest end so far, on a tie the own span first as merge puts
    its first stream first) and before the event's own (which starts after it); a wait
    goes out before the first span starting later than it, after those starting with it
    (``tests/links/test_bus_time_merged.py`` compares the two on random traffic)."""
    brk = EventKind.BREAK
    rest = iter(waits)
    wait = next(rest, None)
    previous: Event | None = None
    previous_end = 0.0
    for e in wire:
        start = e.start
        if previous is not None and start > previous_end:
            while wait is not None and wait[0] < previous_end:
                yield wait
                wait = next(rest, None)
            yield previous_end, previous_end + _forced_gap(previous, e, start - previous_end)
        while wait is not None and wait[0] < start:
            yield wait
            wait = next(rest, None)
        yield (start, e.end + MARKING_AFTER_BREAK) if e.kind is brk else (start, start + CHAR_TIME)
        if previous is None or e.end >= previous_end:
            previous, previous_end = e, e.end
    if wait is not None:
        yield wait
        yield from rest


def _well_formed(wire: list[Event]) -> bool:
    """Whether every span starts where it may be merged in start order: finite times, and
    no break ending (with its marking) before it began. Then the union of the spans does
    not depend on how equal starts are ordered, and merging the sorted streams gives the
    sum sorting them all gave, to the bit (``tests/links/test_bus_time_merged.py``)."""
    brk = EventKind.BREAK
    return all(
        isfinite(e.start) and isfinite(e.end)
        and (e.kind is not brk or e.end + MARKING_AFTER_BREAK >= e.start)
        for e in wire
    )  # fmt: skip


def _forced_gap(before: Event, after: Event, gap: float) -> float:
    """How much of the marking between two events no recorder could have skipped."""
    if after.kind is EventKind.CHAR and after.origin != TOOL:
        return gap  # the DUT chose when to talk (response delay, service request, gaps)
    if before.origin != TOOL:
        return min(gap, RELEASE_LINE)  # the DUT may hold the line after its last stop bit
    if before.kind is EventKind.CHAR and before.char7 == ord("!"):
        return min(gap, RETRY_MIN)  # no reply: the earliest a retry may start
    return 0.0


_BANG, _CR, _LF = ord("!"), ord("\r"), ord("\n")


@dataclass
class _Wait:
    """The ttt a measurement announced: from ``start`` (the end of ``atttn``) to ``end``;
    ``ready`` is where ttt runs out, whatever cut the wait."""

    start: float
    end: float
    address: str
    concurrent: bool
    ready: float = 0.0

    def __post_init__(self) -> None:
        self.ready = self.end

    def cut(self, at: float) -> bool:
        """The tool ended the wait at ``at`` (never before it began); True if that was
        before ttt ran out (an abort, or reading early)."""
        self.end = min(self.end, max(self.start, at))
        return self.end < self.ready


@dataclass
class _OpenWaits:
    """The waits a later event may still cut. A wait cut at ``t`` ends by ``t``, and events
    come in start order, so cutting it again later changes nothing: each wait is cut at most
    once by its kind of event (cutting every wait at every break made this quadratic)."""

    every: list[_Wait]
    by_break: list[_Wait]  # M-type and V waits since the last break
    by_command: dict[str, list[_Wait]]  # concurrent waits, by address, until a command to it
    # waits cut before ttt ran out, by address, that the next command to the sensor may show
    # to have been the verdict's (a data command once ttt is over: see the module docstring)
    aborted: dict[str, list[_Wait]] = field(default_factory=dict)
    cut_by_command: dict[str, list[_Wait]] = field(default_factory=dict)  # by the one in hand

    def keep(self, wait: _Wait | None) -> None:
        if wait is None:
            return
        self.every.append(wait)
        if wait.concurrent:
            self.by_command.setdefault(wait.address, []).append(wait)
        else:
            self.by_break.append(wait)

    def break_at(self, at: float) -> None:
        """A break before ttt ran out aborts (or gives up on) an M-type wait: the tool chose
        that; a concurrent measurement runs on through it (R-4.4.7-05)."""
        for wait in self.by_break:
            if wait.cut(at):
                self.aborted.setdefault(wait.address, []).append(wait)
        self.by_break = []

    def command_at(self, address: str, at: float) -> None:
        """A command to a sensor ends its concurrent measurement's wait there: read early,
        or aborted (R-4.4.7.1-01), it is the tool's choice."""
        cut = [wait for wait in self.by_command.pop(address, ()) if wait.cut(at)]
        if cut:
            self.cut_by_command[address] = cut

    def asked(self, address: str, data: bool, at: float) -> None:
        """The tool's command to ``address`` that started at ``at`` is complete (``data``: a
        D or DB command). It is the next command after the aborts before it: a data command
        once ttt ran out counts each aborted wait in full. Waits this command cut wait for
        the next one."""
        for wait in self.aborted.pop(address, ()):
            if data and at >= wait.ready:
                wait.end = wait.ready
        cut = self.cut_by_command.pop(address, None)
        if cut:
            self.aborted.setdefault(address, []).extend(cut)


def _announced_waits(wire: list[Event]) -> list[tuple[float, float]]:
    """[end of ``atttn``, end + ttt] for each measurement the DUT started, cut where the tool
    chose to end it sooner (see the module docstring)."""
    waits = _OpenWaits([], [], {})
    command: list[Event] = []
    reply: list[Event] = []
    # whether the command ends in '!' and the reply in CR LF, kept as the two grow (asked
    # per event: from the last characters, never decoding the whole command or reply)
    commanded = replied = False
    brk = EventKind.BREAK
    for e in wire:  # breaks and characters only
        if e.kind is brk or (e.origin == TOOL and (reply or commanded)):
            _exchange_ended(waits, command, reply)
            command, reply = [], []
            commanded = replied = False
        if e.kind is brk:
            waits.break_at(e.start)
        elif e.origin == TOOL:
            if not command:  # the first character of a command: its address
                waits.command_at(chr(e.char7), e.start)
            command.append(e)
            commanded = e.wire & 0x7F == _BANG
        elif commanded and not replied:
            reply.append(e)
            replied = e.wire & 0x7F == _LF and len(reply) >= 2 and reply[-2].wire & 0x7F == _CR
    _exchange_ended(waits, command, reply)  # the last exchange
    return [(w.start, w.end) for w in waits.every]


def _exchange_ended(waits: _OpenWaits, command: list[Event], reply: list[Event]) -> None:
    """One exchange is over: the wait its reply announced, and what its command shows of the
    aborted waits before it (:meth:`_OpenWaits.asked`)."""
    if not command:
        return
    try:
        cmd: Command | None = parse_command(decode_7e1(command))
    except CommandError:  # no data command, yet the next one to its address all the same
        cmd = None
    if cmd is None:
        waits.asked(chr(command[0].char7), False, command[0].start)
        return
    waits.asked(cmd.address, cmd.kind in _DATA_KINDS, command[0].start)
    if reply:
        waits.keep(_announced_wait(cmd, reply))


_DATA_KINDS = frozenset({Kind.DATA, Kind.BINARY_DATA})


def _announced_wait(cmd: Command, reply: list[Event]) -> _Wait | None:
    if not cmd.starts_measurement:
        return None
    ttt = announced_time(decode_7e1(reply), measurement_digits(cmd))
    if not ttt:
        return None
    end = reply[-1].end
    return _Wait(end, end + ttt, cmd.address, cmd.is_concurrent)


def announced_time(text: str, digits: int) -> int | None:
    """ttt of a well-formed ``atttn<CR><LF>`` (nn, nnn by ``digits``), else None."""
    body = text.removesuffix("\r\n")
    if body == text or len(body) != 4 + digits:
        return None
    shape = parse_measurement_reply(body, digits)
    return shape.ttt if shape.count is not None else None


def _sweep(spans: Iterable[tuple[float, float]]) -> float:
    """The length of the union of ``spans``, given in start order."""
    total = 0.0
    current_start = current_end = None
    for start, end in spans:
        if current_end is None or start > current_end:
            if current_end is not None:
                total += current_end - current_start
            current_start, current_end = start, end
        else:
            current_end = max(current_end, end)
    if current_end is not None:
        total += current_end - current_start
    return total
