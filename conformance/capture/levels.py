"""Transcript events as line levels: the spacing intervals a list of events puts on the wire.

The inverse of :mod:`.uart`: each character is its 10-bit frame (start bit, the 8 ``wire``
bits LSB first, stop bit) spread over the event's own ``start``..``end`` (so a device at the
wrong bit rate stays wrong), each break its spacing from ``start`` to ``end``. Events that
overlap (contention) are merged with spacing winning, as on a wire where any driver pulling to
spacing is seen. Everything is generated lazily, interval by interval.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from operator import attrgetter

import numpy as np

from ..transcript import Event, EventKind

FRAME_BITS = 10


def spacing_of(event: Event) -> Iterator[tuple[float, float]]:
    """The (start, end) times in seconds at which ``event`` holds the line at spacing."""
    if event.kind is EventKind.BREAK:
        if event.end > event.start:
            yield event.start, event.end
        return
    if event.kind is not EventKind.CHAR:
        return
    bit = (event.end - event.start) / FRAME_BITS
    for i, j in _RUNS[event.wire & 0xFF]:
        yield event.start + i * bit, event.start + j * bit


def _spacing_runs(wire: int) -> tuple[tuple[int, int], ...]:
    """The bit ranges ``[i, j)`` of a 10-bit frame carrying ``wire`` that are spacing."""
    bits = [0] + [(wire >> i) & 1 for i in range(8)] + [1]
    runs = []
    i = 0
    while i < FRAME_BITS:
        if bits[i] == 0:
            j = i
            while j < FRAME_BITS and bits[j] == 0:
                j += 1
            runs.append((i, j))
            i = j
        else:
            i += 1
    return tuple(runs)


_RUNS = tuple(_spacing_runs(w) for w in range(256))


def spacing_ticks(events: Iterable[Event], rate: float, t0: float) -> Iterator[tuple[int, int]]:
    """Merged, non-empty spacing intervals ``[a, b)`` in ticks of ``rate`` from ``t0``, in
    order. ``events`` must be sorted by start (a transcript is)."""

    def intervals() -> Iterator[tuple[int, int]]:
        for ev in events:
            for a, b in spacing_of(ev):
                yield round((a - t0) * rate), round((b - t0) * rate)

    # characters of one event come in order; events by start: a small heap restores order
    # for events whose bits interleave (contention), without holding more than a few
    heap: list[tuple[int, int]] = []
    cur: tuple[int, int] | None = None
    horizon = round(_HORIZON * rate)  # events start at most 0.1 s out of order within a frame
    for iv in intervals():
        heapq.heappush(heap, iv)
        while heap and heap[0][0] < iv[0] - horizon:
            a, b = heapq.heappop(heap)
            cur = yield from _merge(cur, a, b)
    while heap:
        a, b = heapq.heappop(heap)
        cur = yield from _merge(cur, a, b)
    if cur is not None:
        yield cur


def _merge(cur: tuple[int, int] | None, a: int, b: int):
    if b <= a:
        return cur
    if cur is None:
        return (a, b)
    if a <= cur[1]:
        return (cur[0], max(cur[1], b))
    yield cur
    return (a, b)


def edges_of(events: Iterable[Event], rate: float, t0: float) -> Iterator[int]:
    """Ticks where the UART-side level toggles (idle marking = 1): spacing starts and ends."""
    for a, b in spacing_ticks(events, rate, t0):
        yield a
        yield b


#: what :func:`spacing_ticks` holds back to restore the order of interleaved events (s)
_HORIZON = 0.1
#: characters shorter than this keep every interval of a later event after those already
#: merged, whatever :func:`spacing_ticks`'s heap holds back: the bulk union below is then
#: exactly its output
_BULK_CHAR_MAX = _HORIZON / 2


def edge_array(events: Sequence[Event], rate: float, t0: float) -> np.ndarray:
    """:func:`edges_of` as an int64 array, computed in bulk with numpy (the same float
    operations, ``np.rint`` rounding half to even as ``round`` does): a run's export is
    hundreds of thousands of intervals, and one Python generator step each cost most of it.
    Falls back to :func:`edges_of` itself for what the bulk union could order differently
    (events not sorted by start, a character 50 ms long or more, times that are not finite,
    a rate under 1 kHz)."""
    chars = [e for e in events if e.kind is EventKind.CHAR]
    breaks = [e for e in events if e.kind is EventKind.BREAK and e.end > e.start]
    ticks = _bulk_edges(
        np.array([e.start for e in events if e.kind in _WIRE_KINDS], dtype=np.float64),
        np.array([e.start for e in chars], dtype=np.float64),
        np.array([e.end for e in chars], dtype=np.float64),
        np.array([e.wire & 0xFF for e in chars], dtype=np.intp),
        np.array([e.start for e in breaks], dtype=np.float64),
        np.array([e.end for e in breaks], dtype=np.float64),
        rate,
        t0,
    )
    return np.fromiter(edges_of(events, rate, t0), dtype=np.int64) if ticks is None else ticks


@dataclass(frozen=True)
class WireColumns:
    """A transcript's characters and breaks (``events``, stably sorted by start) as the
    columns :func:`edge_array` reads of them, read once for every channel an export
    makes of them (:func:`wire_columns`)."""

    events: list[Event]
    start: np.ndarray
    end: np.ndarray
    wire: np.ndarray
    is_char: np.ndarray
    is_break: np.ndarray

    def edges(self, rate: float, t0: float, among: np.ndarray | None = None) -> np.ndarray:
        """:func:`edge_array` of the events (``among``: of those where it is True), the
        columns masked rather than read again."""
        start, end, is_char, is_break = self.start, self.end, self.is_char, self.is_break
        if among is not None:
            start, end, is_char, is_break = (
                start[among],
                end[among],
                is_char[among],
                is_break[among],
            )
        wire = self.wire if among is None else self.wire[among]
        breaks = is_break & (end > start)
        ticks = _bulk_edges(
            start, start[is_char], end[is_char], wire[is_char], start[breaks], end[breaks], rate, t0
        )
        if ticks is not None:
            return ticks
        events = self.events if among is None else [self.events[i] for i in np.flatnonzero(among)]
        return np.fromiter(edges_of(events, rate, t0), dtype=np.int64)


def wire_columns(events: Iterable[Event]) -> WireColumns | None:
    """The characters and breaks of ``events`` sorted by start as ``sorted(..., key=start)``
    sorts them (stable), with their columns; None (the caller sorts and reads them event
    by event) unless every start and end is a Python float and none is NaN, which Python
    and numpy would order apart."""
    wire = [e for e in events if e.kind in _WIRE_KINDS]
    starts, ends = list(map(_START, wire)), list(map(_END, wire))
    if not wire or set(map(type, starts)) != {float} or set(map(type, ends)) != {float}:
        return None
    start, end = np.array(starts, dtype=np.float64), np.array(ends, dtype=np.float64)
    if np.isnan(start).any() or np.isnan(end).any():
        return None
    if start.size > 1 and (np.diff(start) < 0).any():
        order = np.argsort(start, kind="stable")
        wire = [wire[i] for i in order.tolist()]
        start, end = start[order], end[order]
    kind_list = list(map(_KIND, wire))
    if set(map(type, kind_list)) != {EventKind}:  # == below is then ``is``
        return None
    is_break = _places(kind_list, EventKind.BREAK)
    return WireColumns(
        wire,
        start,
        end,
        np.fromiter(map(_WIRE, wire), np.int64, len(wire)) & 0xFF,
        ~is_break,  # every one is a character or a break
        is_break,
    )


def _places(items: list, value: object) -> np.ndarray:
    """Where ``items`` hold ``value``, as a mask, found by ``list.count`` and ``list.index``
    (C loops) rather than an object array compared item by item (issue 22, replay27: a
    fault-matrix row's ~25,000 wire events and its few hundred breaks; comparing an
    object array of their kinds twice, and making a wire column of Python ints into an
    array, were ~5 of the export's ~25 ms)."""
    mask = np.zeros(len(items), dtype=bool)
    at = -1
    for _ in range(items.count(value)):
        at = items.index(value, at + 1)
        mask[at] = True
    return mask


_START, _END, _KIND, _WIRE = (attrgetter(n) for n in ("start", "end", "kind", "wire"))


def _bulk_edges(
    starts: np.ndarray,
    cs: np.ndarray,
    ce: np.ndarray,
    wires: np.ndarray,
    bs: np.ndarray,
    be: np.ndarray,
    rate: float,
    t0: float,
) -> np.ndarray | None:
    """:func:`edge_array`'s bulk union from the wire events' starts, the characters'
    starts, ends and low wire bytes and the (non-empty) breaks' starts and ends; None
    where it falls back."""
    dur = ce - cs
    if (
        rate < 1000
        or not (np.isfinite(starts).all() and np.isfinite(ce).all() and np.isfinite(be).all())
        or (starts.size and (np.diff(starts) < 0).any())
        or (dur.size and not ((dur >= 0).all() and (dur < _BULK_CHAR_MAX).all()))
    ):
        return None
    counts = _RUN_COUNT[wires]
    owner = np.repeat(np.arange(cs.size), counts)
    first = np.cumsum(counts) - counts  # each character's first interval
    run = np.repeat(_RUN_FIRST[wires], counts) + (np.arange(owner.size) - np.repeat(first, counts))
    bit = dur / FRAME_BITS
    a = np.concatenate((cs[owner] + _RUN_I[run] * bit[owner], bs))
    b = np.concatenate((cs[owner] + _RUN_J[run] * bit[owner], be))
    ta = np.rint((a - t0) * rate).astype(np.int64)
    tb = np.rint((b - t0) * rate).astype(np.int64)
    keep = tb > ta
    ta, tb = ta[keep], tb[keep]
    if not ta.size:
        return np.zeros(0, dtype=np.int64)
    order = np.lexsort((tb, ta))
    ta, tb = ta[order], tb[order]
    reach = np.maximum.accumulate(tb)
    new = np.empty(ta.size, dtype=bool)
    new[0] = True
    new[1:] = ta[1:] > reach[:-1]  # touching intervals merge, as in _merge
    last = np.flatnonzero(np.append(new[1:], True))
    out = np.empty(2 * last.size, dtype=np.int64)
    out[0::2] = ta[new]
    out[1::2] = reach[last]
    return out


_WIRE_KINDS = (EventKind.CHAR, EventKind.BREAK)
_RUN_COUNT = np.array([len(r) for r in _RUNS], dtype=np.intp)
_RUN_FIRST = np.cumsum(_RUN_COUNT) - _RUN_COUNT
_RUN_I = np.array([i for r in _RUNS for i, _ in r], dtype=np.float64)
_RUN_J = np.array([j for r in _RUNS for _, j in r], dtype=np.float64)
