"""The UART decoder of :mod:`.uart` over arrays of edges: the same items, most of them
computed with numpy instead of a Python step each.

:func:`.uart.decode` reads a capture one frame at a time: a Python loop per character over
the edges (a matrix row's capture is 20,000 characters, an hour's a million), which was
most of decoding a capture. Here the edges are held a window at a time as an array and each
window is read in three passes:

1. every falling edge is classified as :func:`.uart._scan` would classify it (a glitch, a
   spacing, or a frame's start bit), and each frame's next start bit is found as if its
   bits were read at the nominal bit time (one ``searchsorted`` each): the chain of start
   bits from the window's first edge is then followed in Python, a list lookup a frame;
2. the frames on that chain are read in bulk at the nominal bit time: bits at their centres
   (``searchsorted``), the sender's bit time fitted edge by edge (the least-squares sums are
   segmented cumulative sums, exact in integers), glitches, parity and framing. A frame is
   *certified* when the fit never moved its bit time off the nominal one, at any edge (then
   every step of :func:`.uart._read_frame` used the nominal bit time, which is what the bulk
   reading assumed);
3. the chain is walked again with the scan's own state (the previous character's bit time,
   the end of the previous frame): a certified frame read at the nominal bit time is taken
   from the arrays, anything else (a sender off the nominal rate, a frame following one,
   the capture's last frame) is read by the scan's own code for one frame
   (:func:`.uart._read_frame` through the kept shapes), and the walk goes on from where that
   frame really ends.

The result is the reference decoder's, item for item, bit for bit: the float operations are
the same ones in the same order (``tests/capture/test_uart_bulk.py`` compares both over
synthesised edge streams with noise, glitches, breaks, off-rate senders, framing errors,
both polarities and cut captures, and over every capture in the shared folder).
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from functools import cache
from math import isnan

import numpy as np

from ..protocol.timing import BREAK_MIN, BREAK_NEVER
from ..transcript import BUS, EventKind, full_event
from .uart import (
    _EXACT_BELOW,
    SYNC_BITS,
    Decoded,
    Framing,
    _capture_end,
    _cut_by_end,
    _Line,
    _read_frame,
    _shapes_for,
    _spacing,
    _spans,
    _start,
    _synchronised,
)

#: Edges held in one window: a capture is read a window at a time, so its edges are never
#: one array. Its arrays and lists are a few MB at this size; a 5-minute 1 MHz capture's
#: decode peaked at 54 / 63 / 83 MB RSS with 2^12 / 2^15 / 2^17 edges (the reference
#: decoder: 53), for the same CPU (a matrix row's capture: 184-194 ms each way)
WINDOW = 1 << 12

_GLITCH, _SPACING, _FRAME, _TAIL = 0, 1, 2, 3


@dataclass
class Batch:
    """One window's items in time order: ``order`` holds, per item, either an index into
    the window's certified frames (an ``int``: their fields in the lists below) or the
    :class:`.uart.Decoded` the scan's own code made (glitches, spacings, frames read one at
    a time). Each certified frame's marking before it is worked out when it is made an item."""

    order: list[int | Decoded]
    start: list[float]
    end: list[float]
    wire: list[int]
    framing_error: list[bool]
    parity_error: list[bool]
    err: list[float | None]
    glitches: list[int]
    #: each certified frame's start tick and the end (tick) of the frame or spacing before
    #: it (None: none), its marking worked out only for a frame made an item (a problem,
    #: or one of the first few, which the synchronisation looks at)
    start_ticks: list[int] = field(default_factory=list)
    before: list[float | None] = field(default_factory=list)
    tick_rate: float = 1.0
    #: the certified frames' starts and wires as arrays, for a stretch of them taken whole
    #: (:func:`~.decode._collect_batches`); None: not kept
    start_array: np.ndarray | None = None
    wire_array: np.ndarray | None = None
    #: the certified frames with a framing or parity error or a glitch, in order
    flagged: list[int] = field(default_factory=list)
    #: ``err`` with NaN for None (the bit-rate errors as a decode lists them)
    err_nan: list[float] = field(default_factory=list)

    def marking(self, p: int) -> float | None:
        """The marking before certified frame ``p``, as the scan works it out (s)."""
        b = self.before[p]
        return None if b is None else max(0.0, (self.start_ticks[p] - b) / self.tick_rate)

    def item(self, p: int, uncertainty: float) -> Decoded:
        """Certified frame ``p`` as the :class:`.uart.Decoded` the reference makes."""
        ev = full_event(
            EventKind.CHAR, BUS, self.start[p], self.end[p], self.wire[p], "", uncertainty, None
        )
        return Decoded(
            "char",
            ev,
            ev.start,
            ev.end,
            self.framing_error[p],
            self.parity_error[p],
            self.err[p],
            self.glitches[p],
            self.marking(p),
        )

    def items(self, uncertainty: float) -> Iterator[Decoded]:
        for x in self.order:
            yield self.item(x, uncertainty) if x.__class__ is int else x  # type: ignore[arg-type]


def decode_batches(
    chunks: Iterable[list[int]],
    *,
    initial_level: int,
    tick_rate: float,
    invert: bool = False,
    baud: float = 1200,
    framing: Framing | None = None,
    t0: float = 0.0,
    uncertainty: float = 0.0,
    period_ticks: float = 1.0,
    end_tick: Callable[[], int | None] | None = None,
    break_min: float = BREAK_MIN,
    pulse_min: float = BREAK_NEVER,
    window: int | None = None,
) -> Iterator[Batch]:
    """:func:`.uart.decode`'s items before its synchronisation (:func:`decode` adds it), a
    window at a time; the arguments are :func:`.uart.decode`'s, and ``window``: the edges
    held at a time (default :data:`WINDOW`)."""
    framing = framing or Framing.parse("7E1")
    line = _Line(
        tick_rate / baud,
        framing.bits,
        tick_rate,
        t0,
        uncertainty,
        period_ticks,
        framing,
        end_tick,
        break_min,
        pulse_min,
    )
    level = (initial_level & 1) ^ int(invert)
    src = iter(chunks)
    state = _start(src, level)
    if state is None:
        return
    buf, i, more, last_end = state
    pending = buf[i:]
    prior_bt: float | None = None
    size = need = window or WINDOW
    while True:
        while more and len(pending) < need:
            nxt = next(src, None)
            if nxt is None:
                more = False
            else:
                pending.extend(nxt)
        if not pending:
            return
        window = _Window(pending, more, line)
        batch, k, last_end, prior_bt = window.read(last_end, prior_bt)
        if batch.order:
            yield batch
        if not more:
            return
        pending = pending[k:]
        need = size if k else len(pending) + 1  # no progress: hold more edges


def decode(chunks: Iterable[list[int]], **kwargs) -> Iterator[Decoded]:
    """:func:`.uart.decode`, item for item (the same keyword arguments)."""
    uncertainty = kwargs.get("uncertainty", 0.0)
    baud = kwargs.get("baud", 1200)
    tick_rate, t0 = kwargs["tick_rate"], kwargs.get("t0", 0.0)
    items = (d for b in decode_batches(chunks, **kwargs) for d in b.items(uncertainty))
    yield from _synchronised(items, SYNC_BITS * (tick_rate / baud) / tick_rate, t0)


class _Window:
    """One window of edges, starting at a falling edge (falling edges at even indices)."""

    def __init__(self, edges: list[int], more: bool, line: _Line) -> None:
        self.edges = edges
        self.more = more
        self.line = line
        self.n = len(edges)
        self.shapes = _shapes_for(line.T, line.nbits, line.period_ticks, line.framing)

    def read(self, last_end: float | None, prior_bt: float | None) -> tuple:
        """The window's items up to the first start bit it cannot settle without later edges
        (all of them in the last window), the index of that start bit, and the scan's state
        there: the end of the last frame or spacing, the last clean character's bit time."""
        line = self.line
        T, nbits = line.T, line.nbits
        half, stop_centre, frame_span = _spans(T, nbits)
        W = np.asarray(self.edges, dtype=np.int64)
        n = self.n
        F = np.arange(0, n, 2)
        s = W[F]
        has_r = n > F + 1
        r = np.where(has_r, W[np.minimum(F + 1, n - 1)], s)
        length = r - s
        kind = np.full(F.size, _FRAME, dtype=np.int8)
        spacing = (length > stop_centre) & (length / line.tick_rate >= line.pulse_min)
        kind[spacing] = _SPACING
        kind[length < half] = _GLITCH
        kind[~has_r] = _TAIL
        Wf = W.astype(np.float64)
        sf = Wf[F]
        # a frame's next start bit, its bits read at the nominal bit time
        stop_off = (nbits - 0.5) * T
        after = np.searchsorted(Wf, sf + stop_off, "right")
        low_stop = (after - F - 1) % 2 == 0
        nxt = np.where(kind == _FRAME, after + (low_stop & (after < n)), F + 2)
        if self.more:  # a start bit needs edges past its frame's window (and its r)
            safe = has_r & (Wf[-1] > sf + frame_span)
            settled = int(np.argmin(safe)) if not safe.all() else F.size
        else:
            settled = F.size
        nxt_l = nxt.tolist()
        chain = []
        k = 0
        while k < n and (k >> 1) < settled:
            chain.append(k)
            k = nxt_l[k >> 1]
        frames = np.array(chain, dtype=np.int64)
        frames = frames[kind[frames >> 1] == _FRAME]
        cert = _Certified(W, Wf, frames, line, after[frames >> 1], n, settled)
        return self._walk(kind, cert, settled, last_end, prior_bt)

    def _walk(self, kind: np.ndarray, cert: _Certified, settled: int, last_end, prior_bt) -> tuple:
        """Pass 3 (see the module): the scan's state carried item by item."""
        line = self.line
        T, nbits, tick_rate, t0 = line.T, line.nbits, line.tick_rate, line.t0
        edges, n = self.edges, self.n
        kinds = kind.tolist()
        pos = cert.position
        ok, nxt, end, fe = cert.ok, cert.next, cert.end_ticks, cert.framing_error
        run_end = cert.run_end
        order: list = []
        add, add_run = order.append, order.extend
        before = cert.before  # each certified frame's last_end (Batch.marking)
        span = nbits * T
        k = 0
        while k < n:
            c = k >> 1
            if c >= settled:
                break
            what = kinds[c] if not k & 1 else _TAIL
            s = edges[k]
            if what == _FRAME:
                follows = prior_bt is not None and last_end is not None and s - last_end < span
                used = prior_bt if follows and prior_bt is not None else T
                p = pos[c]
                if p >= 0 and ok[p] and used == T:
                    before[p] = last_end
                    q = run_end[p]
                    if q > p:  # frames p..q, each reached from the one before it as here
                        add_run(range(p, q + 1))
                        before[p + 1 : q + 1] = end[p:q]
                        p = q
                    else:
                        add(p)
                    last_end = end[p]
                    prior_bt = None if fe[p] else T
                    k = nxt[p]
                    continue
                step = self._frame(k, used, last_end)
                if step is None:
                    break  # needs edges past the window
                d, k, last_end, prior_bt = step
                add(d)
                if k < 0:
                    k = n  # the capture ended inside this frame
                continue
            if what == _GLITCH:
                add(Decoded("glitch", None, t0 + s / tick_rate, t0 + edges[k + 1] / tick_rate))
                k += 2
                continue
            if what == _SPACING:
                r = edges[k + 1]
                add(_spacing(s, r, last_end, line))
                prior_bt, last_end = None, r
                k += 2
                continue
            # the last edge, or a start bit at an odd index (the scan went on past a frame's
            # window for a slow sender's stop bit and its edges: every kind is the scan's)
            step = self._step(k, last_end, prior_bt)
            if step is None:
                break  # needs edges past the window
            d, k, last_end, prior_bt = step
            if d is not None:
                add(d)
        batch = cert.batch
        batch.order = order
        batch.before, batch.start_ticks, batch.tick_rate = before, cert.start_ticks, tick_rate
        return batch, k, last_end, prior_bt

    def _step(self, k: int, last_end, prior_bt) -> tuple | None:
        """:func:`.uart._scan`'s step at the edge of index ``k`` taken as a start bit: the
        item (None: none), the next index, the end of the last frame or spacing and the last
        clean character's bit time; None when it needs edges past the window."""
        line = self.line
        T, nbits, tick_rate, t0 = line.T, line.nbits, line.tick_rate, line.t0
        half, stop_centre, frame_span = _spans(T, nbits)
        edges, n = self.edges, self.n
        s = edges[k]
        r = edges[k + 1] if k + 1 < n else None
        if self.more and (r is None or edges[-1] <= s + frame_span):
            return None
        r_end = r if r is not None else _capture_end(s, line.end_tick)
        length = r_end - s
        if length < half:
            if r is None:
                return None, n, last_end, prior_bt
            return (
                Decoded("glitch", None, t0 + s / tick_rate, t0 + r / tick_rate),
                k + 2,
                last_end,
                prior_bt,
            )
        if length > stop_centre and length / tick_rate >= line.pulse_min:
            d = _spacing(s, r_end, last_end, line)
            return (d, n, last_end, None) if r is None else (d, k + 2, r, None)
        follows = prior_bt is not None and last_end is not None and s - last_end < nbits * T
        used = prior_bt if follows and prior_bt is not None else T
        step = self._frame(k, used, last_end)
        if step is not None and step[1] < 0:
            return step[0], n, step[2], step[3]  # the capture ended inside this frame
        return step

    def _frame(self, k: int, used: float, last_end) -> tuple | None:
        """:func:`.uart._scan`'s frame step for the start bit at index ``k`` read from bit
        time ``used``: the item, the next edge's index (-1: the capture ended inside the
        frame), the new end of the last frame and bit time; None when the frame needs
        edges past the window."""
        line = self.line
        T, nbits, tick_rate, t0 = line.T, line.nbits, line.tick_rate, line.t0
        _, _, frame_span = _spans(T, nbits)
        edges, n, more = self.edges, self.n, self.more
        s = edges[k]
        i = k + 1
        frame_end = s + frame_span
        j = bisect_left(edges, frame_end, i)
        inner = edges[i:j]
        reading = self.shapes[(used, *[e - s for e in inner])] if s < _EXACT_BELOW else None
        if reading is None:
            reading = _read_frame(s, inner, used, T, nbits, line.period_ticks, line.framing)
        used, framing_error = reading.used, reading.framing_error
        end = s + nbits * used
        stop = s + (nbits - 0.5) * used
        if stop < frame_end:
            i = bisect_right(edges, stop, i, j)
        else:
            if more and edges[-1] <= stop:
                return None
            i = bisect_right(edges, stop, i)
        e = edges[i] if i < n else None
        if framing_error and e is not None:
            i += 1
            end = max(end, e)
        elif e is not None and e < end:
            end = e
        start = t0 + s / tick_rate
        if e is None and not more and _cut_by_end(framing_error, stop, edges, line.end_tick):
            return Decoded("partial", None, start, t0 + end / tick_rate), -1, last_end, None
        unc, stamp = line.uncertainty, t0 + end / tick_rate
        ev = full_event(EventKind.CHAR, BUS, start, stamp, reading.wire, "", unc, None)
        marking = None if last_end is None else max(0.0, (s - last_end) / tick_rate)
        d = Decoded(
            "char",
            ev,
            start,
            ev.end,
            framing_error,
            reading.parity_error,
            reading.err,
            reading.glitches,
            marking,
        )
        return d, i, end, None if framing_error else used


class _Certified:
    """Pass 2 (see the module): the chain's frames read in bulk at the nominal bit time.
    ``ok[p]``: frame ``p`` reads exactly so (the fit never left the nominal bit time, and an
    edge follows it: the capture's last frame is the scan's own to read)."""

    def __init__(
        self,
        W: np.ndarray,
        Wf: np.ndarray,
        starts: np.ndarray,
        line: _Line,
        after: np.ndarray,
        n: int,
        settled: int | None = None,
    ) -> None:
        T, nbits = line.T, line.nbits
        half, _, frame_span = _spans(T, nbits)
        m_frames = starts.size
        s = W[starts]
        sf = Wf[starts]
        j = np.searchsorted(Wf, sf + frame_span, "left")
        m = j - starts - 1  # edges inside each frame
        owner = np.repeat(np.arange(m_frames), m)
        first = np.cumsum(m) - m
        at = np.arange(owner.size) - first[owner] + starts[owner] + 1  # the edge's index
        e = W[at]
        gap = e - W[at - 1]  # from the edge before (the start bit's for the first)
        inner_next = (at - starts[owner]) < m[owner]  # an inner edge follows this one
        gap_next = np.where(inner_next, W[np.minimum(at + 1, W.size - 1)] - e, 0)
        glitch_edge = (gap < half) | (inner_next & (gap_next < half))
        moved, err = _fitted(e - s[owner], ~glitch_edge, owner, first, m_frames, line)
        ok = ~moved & (after < n)  # an edge after the stop bit: not the capture's last frame
        # bits at their centres
        bits = _centre_levels(Wf[at], sf, owner, m_frames, T, nbits)
        wire = _BYTE_WEIGHTS @ bits[:, 1:9].T if m_frames else np.zeros(0, dtype=np.int64)
        framing_error = bits[:, nbits - 1] == 0
        parity_error = _parity_errors(line.framing)[wire & 0xFF]
        short = gap < half
        short_before = np.zeros(owner.size, dtype=bool)
        if owner.size:
            short_before[1:] = short[:-1] & (owner[1:] == owner[:-1])
        glitches = np.bincount(owner[short & ~short_before], minlength=m_frames)
        # where the frame ends and the next start bit (the scan's consuming rule)
        end = sf + nbits * T
        e_after = Wf[np.minimum(after, n - 1)]
        end = np.where(framing_error, np.maximum(end, e_after), np.minimum(end, e_after))
        nxt = after + framing_error
        position = np.full(W.size // 2 + 1, -1, dtype=np.int64)
        position[starts >> 1] = np.arange(m_frames)
        self.position = position.tolist()  # by start bit (its edge index // 2)
        self.run_end = _run_ends(starts, position, ok, nxt, n if settled is None else settled)
        self.start_ticks = s.tolist()
        self.before: list[float | None] = [None] * m_frames
        self.ok = ok.tolist()
        self.next = nxt.tolist()
        self.end_ticks = end.tolist()
        self.framing_error = framing_error.tolist()
        tick_rate, t0 = line.tick_rate, line.t0
        start_s = t0 + s / tick_rate
        self.batch = Batch(
            [],
            *_stamps(start_s, t0 + end / tick_rate),
            wire.tolist(),
            self.framing_error,
            parity_error.tolist(),
            _nan_as_none(err_nan := err.tolist()),
            glitches.tolist(),
            start_array=start_s,
            wire_array=wire,
            flagged=np.flatnonzero(framing_error | parity_error | (glitches > 0)).tolist(),
            err_nan=err_nan,
        )


def _run_ends(
    starts: np.ndarray, position: np.ndarray, ok: np.ndarray, nxt: np.ndarray, settled: int
) -> list[int]:
    """Per certified frame ``p``, the last frame ``q >= p`` such that every frame after
    ``p`` up to ``q`` is where pass 3 goes next from the frame before it and takes it from
    the arrays: that frame's next edge is the next frame's start bit, at an even index (a
    falling edge), settled in this window, the frame there is that one, and it reads
    exactly at the nominal bit time. Past a certified frame the scan's bit time is the
    nominal one or none (so the next is read at the nominal one too), which is why these
    are all the walk checks; it then takes the run in one step instead of a Python step a
    frame (~10^4 a fault-matrix row, issue 22), the same order, markings and state."""
    m = starts.size
    if m == 0:
        return []
    nb = starts[1:]
    link = (nxt[:-1] == nb) & ((nb & 1) == 0) & ((nb >> 1) < settled) & ok[1:]
    link &= position[nb >> 1] == np.arange(1, m)
    breaks = np.flatnonzero(~np.append(link, False))
    return breaks[np.searchsorted(breaks, np.arange(m), "left")].tolist()


#: a frame's eight bits between start and stop (bits 1..8), least significant first, as the
#: wire byte's weights
_BYTE_WEIGHTS = 1 << np.arange(8, dtype=np.int64)


@cache
def _parity_errors(framing: Framing) -> np.ndarray:
    """Per wire byte, whether ``framing``'s parity check fails it (a table of 256, made once
    per framing: it was made again for every window, 256 Python calls each)."""
    return np.array([not framing.parity_ok(w) for w in range(256)])


def _centre_levels(
    edge_at: np.ndarray,
    sf: np.ndarray,
    owner: np.ndarray,
    m_frames: int,
    T: float,
    nbits: int,
) -> np.ndarray:
    """Each frame's ``nbits`` bits as read at their centres (``sf + (k + 0.5) * T``): the
    parity of the count of its inner edges (``edge_at``: their ticks as floats, ``owner``:
    their frame) at or before each centre, which is what a ``searchsorted`` of every centre
    in the window's edges counts (the frame's window, 1.1 frames, holds every edge up to the
    stop bit's centre). Each edge's first centre at or past it is estimated by a division
    and settled by comparing with the centres themselves, computed as those are; the counts
    are then cumulative sums of a per-frame histogram (one pass over the inner edges instead
    of a binary search per bit: ~10^5 searches a fault-matrix row)."""
    base = sf[owner]
    k = np.clip(np.floor((edge_at - base) / T - 0.5).astype(np.int64) + 1, 0, nbits)
    while True:  # the estimate is off by at most one, by the division's rounding
        down = (k > 0) & (edge_at <= base + ((k - 1) + 0.5) * T)
        up = (k < nbits) & (edge_at > base + (k + 0.5) * T)
        if not (down.any() or up.any()):
            break
        k = k - down + up
    width = nbits + 1  # the last column: edges past the stop bit's centre
    hist = np.bincount(owner * width + k, minlength=m_frames * width).reshape(m_frames, width)
    return np.cumsum(hist[:, :nbits], axis=1) & 1


def _nan_as_none(values: list[float]) -> list[float | None]:
    """``values`` with None for each NaN (the reference's "no fit"), found by a C loop
    (``map``) rather than a Python comparison of every frame's value; a new list."""
    out: list[float | None] = list(values)
    if set(map(isnan, values)) != {False}:
        for i, v in enumerate(values):
            if v != v:
                out[i] = None
    return out


def _stamps(starts: np.ndarray, ends: np.ndarray) -> tuple[list[float], list[float]]:
    """The frames' start and end stamps as lists of floats, a start equal to the end before
    it (back-to-back characters: most of a reply's) the same float object as that end, not
    a second one: an event holds 24 bytes less, the same values (an hour of a busy bus:
    about 200,000 of its 357,000 events)."""
    first, last = starts.tolist(), ends.tolist()
    for i in np.flatnonzero((starts[1:] == ends[:-1]) & (starts[1:] != 0.0)).tolist():
        first[i + 1] = last[i]
    return first, last


def _fitted(
    d: np.ndarray,
    usable: np.ndarray,
    owner: np.ndarray,
    first: np.ndarray,
    m_frames: int,
    line: _Line,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`.uart._read_frame`'s fit of the sender's bit time at the nominal one, for the
    inner edges of many frames at once (``d``: each edge's distance from its frame's start
    bit, ``usable``: not a glitch's edge, ``owner``: its frame, ``first``: each frame's first
    edge): per frame, whether the fit would have moved the bit time off the nominal one at
    any edge, and the measured error in % (NaN: no edge fitted). The sums are integers,
    summed exactly as the reference's floats are."""
    T, nbits, period = line.T, line.nbits, line.period_ticks
    kk = np.rint(d / T)
    valid = usable & (kk >= 1) & (kk < nbits) & (np.abs(d - kk * T) < T / 2)
    kkv = np.where(valid, kk, 0.0).astype(np.int64)
    kk2 = np.cumsum(kkv * kkv)
    kd = np.cumsum(kkv * d)
    base = np.maximum(first - 1, 0)
    before = first >= 1
    skk = kk2 - np.where(before, kk2[base] if kk2.size else 0, 0)[owner]
    sdk = kd - np.where(before, kd[base] if kd.size else 0, 0)[owner]
    kmax = np.maximum.accumulate(kkv + owner * 16) - owner * 16  # per frame (kk < 16)
    with np.errstate(divide="ignore", invalid="ignore"):
        bt = sdk.astype(np.float64) / skk.astype(np.float64)
        off = valid & (np.abs(bt - T) * kmax.astype(np.float64) > 2 * period)
    moved = np.zeros(m_frames, dtype=bool)
    moved[owner[off]] = True
    vidx = np.flatnonzero(valid)  # the fit's final bit time: its frame's last valid edge's
    of = owner[vidx]  # non-decreasing
    last = np.searchsorted(of, np.arange(m_frames), "right") - 1
    has_fit = last >= 0
    has_fit[has_fit] = of[last[has_fit]] == np.flatnonzero(has_fit)
    err = np.full(m_frames, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        err[has_fit] = (T / bt[vidx[last[has_fit]]] - 1) * 100
    return moved, err
