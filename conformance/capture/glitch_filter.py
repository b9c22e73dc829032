"""A glitch filter for captured edges: pulses shorter than a stated width are not the line.

A logic analyzer on a field cable sees what a UART never would: one-sample spikes on the idle
line, and edges that chatter for a microsecond or two as they cross the threshold. A UART's
receiver samples each bit in its middle and never notices them; the decoder reads every edge,
so each spike became a "glitch" and each chattering edge several, enough for the plausibility
check to take a clean capture for one at the wrong bit rate (issue 23). The filter removes
every pulse (either level) shorter than its width before the decoder sees the edges, and
counts what it removed. Removing a pair of edges keeps the levels alternating, so the
decoder's view of the line stays consistent.

A removed pulse beside a kept edge (a chattering transition) leaves that edge where its last
bounce was: its position is then known only to the width, and :attr:`GlitchFilter.beside_edges`
says the capture's stamps must be widened by it. Spikes on a marking or spacing stretch move
no edge.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from operator import sub

#: The default width, in bit times: 1/16 of a bit (52 µs at 1200 baud), what a 16x
#: oversampling UART cannot resolve either; a real SDI-12 bit is 16 times longer.
DEFAULT_BITS = 1 / 16


@dataclass
class GlitchFilter:
    """Removes pulses shorter than ``width`` ticks from a stream of edge ticks (non-decreasing,
    levels alternating). ``removed``: pulses taken out; ``beside_edges``: how many times the
    edge kept after a removed pulse came within ``width`` of it (a chattering transition,
    or a spike just before an edge: where that edge really was is known to ``width``)."""

    width: float
    removed: int = 0
    beside_edges: int = 0

    def __call__(
        self, chunks: Iterable[list[int]], min_gap: int | None = None
    ) -> Iterator[list[int]]:
        """The edges of ``chunks`` with every short pulse taken out, in chunks again. An edge
        is held until one ``width`` later has been seen: only then can no later edge pair up
        with it. ``min_gap``: the least distance between two consecutive edges of the whole
        stream, when the reader knows it before the chunks are read
        (:attr:`~.edges.Edges.min_gap`); at least ``width``, no pulse can be too short, and
        the chunks are only re-cut as the usual chunk below re-cuts them, none searched."""
        width = self.width
        if width <= 0:
            yield from chunks
            return
        if min_gap is not None and min_gap >= width:
            yield from _held_back(chunks)
            return
        held: deque[int] = deque()
        last_removed = float("-inf")  # where the latest removed pulse ended, until placed
        for chunk in chunks:
            if not chunk:
                continue
            first = chunk[0]
            if (
                (not held or first - held[-1] >= width)
                and first - last_removed >= width
                and (len(chunk) < 2 or min(map(sub, chunk[1:], chunk[:-1])) >= width)
            ):
                # the usual chunk: no pulse in it too short, none across its start. All held
                # edges and all of its own but the last are settled (map/sub run in C: the
                # per-edge loop below cost a sixth of a decode)
                out = [*held, *chunk[:-1]]
                held.clear()
                held.append(chunk[-1])
                last_removed = float("-inf")
                if out:
                    yield out
                continue
            for e in chunk:
                if held and e - held[-1] < width:
                    held.pop()  # this edge and the one before it: a pulse too short
                    self.removed += 1
                    last_removed = e
                    continue
                if e - last_removed < width:
                    self.beside_edges += 1  # the removed pulse was a bounce of this edge
                last_removed = float("-inf")
                held.append(e)
            horizon = chunk[-1] - width
            out = []
            while len(held) > 1 and held[0] < horizon:
                out.append(held.popleft())
            if out:
                yield out
        if held:
            yield list(held)


def _held_back(chunks: Iterable[list[int]]) -> Iterator[list[int]]:
    """:class:`GlitchFilter`'s chunks where no pulse is too short, which every chunk then
    is to its usual-chunk test: all of a chunk's edges but its last, after the one held
    from the chunk before; the last edge held to the end. The test's scan of every gap
    (a ``map`` over each chunk, ~40 ns an edge: ~10 ms of a fault-matrix row's two
    channels, issue 22) is what a known least gap spares."""
    held: list[int] = []
    for chunk in chunks:
        if not chunk:
            continue
        out = [*held, *chunk[:-1]]
        held = chunk[-1:]
        if out:
            yield out
    if held:
        yield held
