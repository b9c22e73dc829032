"""Streaming edges: where one channel of a capture changes level, and nothing else.

Every reader turns its format into an :class:`Edges` and every consumer (the UART decoder, the
writers) works from it, so a new format needs only a reader. A capture is never held whole: a
one-hour capture at 1 MHz is 3.6e9 samples, but a busy SDI-12 bus changes level at most about a
thousand times a second, so edges are a few million integers per hour and arrive chunk by chunk.

Positions are integer *ticks* of the capture's own clock (``tick_rate`` per second): the sample
index for a sampled capture (.sr), the timescale unit for VCD, nanoseconds for a CSV export. An
edge at tick ``k`` means tick ``k`` is the first one at the new level, so the true transition
happened within one sample period before it (``period``).

Transitions in raw sample blocks are found with numpy (:func:`transitions`). Measured on this
project's loaded 2-core machine, per 4 Mi-sample block: on 1200 baud SDI-12 traffic numpy and
a pure-Python ``bytes.translate`` + regex scan are about even (25-33 vs 15-28 ms), but on dense
edges (115200 baud, or a noisy line full of glitches) numpy is 2.5-5x faster (125-240 vs 615
ms), and noisy field captures are what this package is for.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field

import numpy as np

EdgeChunks = Iterable[list[int]]


@dataclass
class Edges:
    """One channel as a starting level plus the ticks at which it toggles.

    ``chunks`` yields lists of strictly increasing ticks and may be consumed once. ``end``
    is the capture's last tick when the format says so (known for .sr only after its chunks were
    read: ``end()`` asks the reader), else the last edge.
    """

    path: str
    channel: str
    channels: list[str]
    tick_rate: float  # ticks per second
    period: float  # seconds: the sample period, i.e. how well one edge's position is known
    initial_level: int  # 0 or 1, as captured (not yet corrected for polarity)
    chunks: EdgeChunks
    t0: float = 0.0  # seconds at tick 0
    end: Callable[[], int | None] = field(default=lambda: None)
    notes: list[str] = field(default_factory=list)
    #: the least distance between two consecutive edges of the whole stream, when the
    #: reader knows it before the chunks are read (a held session: its ticks are one array,
    #: :mod:`.held_sr`); None: not known (the glitch filter searches each chunk)
    min_gap: int | None = None

    def time(self, tick: float) -> float:
        return self.t0 + tick / self.tick_rate

    def __iter__(self) -> Iterator[int]:
        for chunk in self.chunks:
            yield from chunk


def transitions(samples: np.ndarray, previous: int | None) -> tuple[list[int], int]:
    """Indices (in ``samples``) of the samples whose level differs from the one before, given
    the last level of the previous block (``None`` at the capture's start), and this block's
    last level. ``samples`` holds 0/1 values (any integer dtype)."""
    if samples.size == 0:
        return [], -1 if previous is None else previous
    found = np.flatnonzero(samples[1:] != samples[:-1]) + 1
    idx = found.tolist()
    if previous is not None and int(samples[0]) != previous:
        idx.insert(0, 0)
    return idx, int(samples[-1])


def prepend(first: list[int], rest: EdgeChunks) -> Iterator[list[int]]:
    """Chunks with an already read chunk put back in front (used to peek for polarity)."""
    if first:
        yield first
    yield from rest
