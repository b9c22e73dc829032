"""Transcript events as line levels: the spacing intervals a list of events puts on the wire.

The inverse of :mod:`.uart`: each character is its 10-bit frame (start bit, the 8 ``wire``
bits LSB first, stop bit) spread over the event's own ``start``..``end`` (so a device at the
wrong bit rate stays wrong), each break its spacing from ``start`` to ``end``. Events that
overlap (contention) are merged with spacing winning, as on a wire where any driver pulling to
spacing is seen. Everything is generated lazily, interval by interval.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterable, Iterator

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
    bits = [0] + [(event.wire >> i) & 1 for i in range(8)] + [1]
    i = 0
    while i < FRAME_BITS:
        if bits[i] == 0:
            j = i
            while j < FRAME_BITS and bits[j] == 0:
                j += 1
            yield event.start + i * bit, event.start + j * bit
            i = j
        else:
            i += 1


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
    horizon = round(0.1 * rate)  # events start at most 0.1 s out of order within a frame
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
