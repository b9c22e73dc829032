"""Asynchronous serial frames from edges, at the capture's own resolution.

The decoder works as a UART does, but with the whole edge history at hand: every start bit's
leading edge re-synchronises it, bits are read at their centres from there, and the edges that
fall inside a frame also say how long its bits really were (the sender's bit rate), which a
UART cannot report. Spacing longer than a frame is not a character: SDI-12 gives it a meaning
by length (section 7, R-7.0-02..04): at least 12 ms is a break, 6.5-12 ms a pulse a sensor may
or may not take for one, so both are reported with their exact length and kept apart.

Levels are handled on the UART side (marking = 1). The SDI-12 line itself idles at 0 V
(marking = low), so a probe on the bus sees inverted levels: ``invert`` selects which.
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass

from ..protocol.timing import BREAK_MIN, BREAK_NEVER
from ..transcript import BUS, Event, EventKind, full_event

SPACING_PULSE = "spacing pulse"  # text of a BREAK event 6.5-12 ms long (R-7.0-03/04)


@dataclass(frozen=True)
class Framing:
    """Data bits, parity (``"E"``, ``"O"``, ``"N"``), one stop bit; 8 bits between start and
    stop (the transcript's ``wire``)."""

    data_bits: int
    parity: str

    @classmethod
    def parse(cls, text: str) -> Framing:
        t = text.upper()
        if len(t) != 3 or not t[0].isdigit() or t[1] not in "EON" or t[2] != "1":
            raise ValueError(f"framing {text!r}: expected e.g. 7E1, 7O1, 8N1")
        framing = cls(int(t[0]), t[1])
        if framing.data_bits + (framing.parity != "N") != 8:
            raise ValueError(f"framing {text!r}: the wire model holds 8 bits (7E1, 7O1, 8N1)")
        return framing

    @property
    def bits(self) -> int:
        """Bits per frame: start, data, parity, stop."""
        return 10

    def parity_ok(self, wire: int) -> bool:
        if self.parity == "N":
            return True
        ones = bin(wire & 0xFF).count("1") & 1
        return ones == (0 if self.parity == "E" else 1)

    def __str__(self) -> str:
        return f"{self.data_bits}{self.parity}1"


@dataclass(slots=True)
class Decoded:
    """One thing the decoder found. ``kind``: ``char``, ``break``, ``pulse`` (spacing 6.5-12
    ms), ``glitch`` (a pulse shorter than half a bit outside any frame; ``event`` None), or
    ``partial`` (a frame the capture cut: begun before the decoder could tell a start bit from
    a data bit, or still running when the capture ended; ``event`` None, never judged).

    ``marking_before``: marking (s) since the previous frame's stop bit or break ended (None
    for the first); ``baud_error_pct``: the frame's own bit rate against the nominal one, from
    its edges (None when not a char); ``glitches``: pulses shorter than half a bit in it."""

    kind: str
    event: Event | None
    start: float
    end: float
    framing_error: bool = False
    parity_error: bool = False
    baud_error_pct: float | None = None
    glitches: int = 0
    marking_before: float | None = None


def character_problems(problems: Iterable[Decoded]) -> list[Decoded]:
    """The problems of characters among ``problems`` (a decode's: a framing or parity
    error, a glitch inside), all a judgement reads of them (the decode-quality notes); the
    breaks and pulses among them are counted apart and are events too."""
    return [p for p in problems if p.kind == "char" and p.event is not None]


#: Frame shapes (a frame's edges relative to its start bit, and the bit time it is read with)
#: whose reading is kept: a bus repeats the same few hundred shapes, and reading one again is
#: most of a decode's time (an hour at 1 MHz: millions of frames). Kept per line and process
#: (:func:`_shapes_for`), dropped whole when full, so a noisy capture of endless distinct
#: shapes stays bounded.
FRAME_SHAPES = 1 << 14

#: A shape read relative to its start gives the same bits at any start below this tick, as
#: long as no edge lies within ``_MARGIN`` ticks of a bit centre: ``s + centre`` stays below
#: 2**40 and is rounded by at most 2**-14 ticks, so no comparison of an edge with a centre
#: can turn (the fit itself only sees edge differences, which are exact integers).
_EXACT_BELOW = 2**39
_MARGIN = 2.0**-12


@dataclass(frozen=True, slots=True)
class _Reading:
    """What one frame's edges say: its 8 wire bits, whether the stop bit was low, parity,
    glitches, the measured bit-rate error and the bit time its bits were read with."""

    wire: int
    framing_error: bool
    parity_error: bool
    glitches: int
    err: float | None
    used: float


def _read_frame(
    s: int,
    inner: list[int] | tuple[int, ...],
    used: float,
    T: float,
    nbits: int,
    period_ticks: float,
    framing: Framing,
) -> _Reading:
    """Read the frame whose start bit falls at ``s`` from the edges inside it, starting from
    bit time ``used`` (the nominal one, or the sender's seen a character earlier)."""
    half = T / 2
    # the sender's bit time, fitted edge by edge (least squares through the start edge):
    # early edges barely drift, so the fit follows a sender several % off the nominal
    # rate and the bits are then read where that sender put them
    # (a fit is trusted only where it differs from the nominal bit by more than the edges'
    # own quantisation allows: at 8 samples a bit, one sample is 12 % of a bit)
    bt = used
    skk = sdk = 0.0
    kmax = 0
    bounds = [s, *inner]
    for n, e in enumerate(inner, 1):
        if e - bounds[n - 1] < half or (n < len(inner) and inner[n] - e < half):
            continue  # an edge of a glitch: no bit boundary
        d = e - s
        kk = round(d / used)
        if 1 <= kk < nbits and abs(d - kk * used) < used / 2:
            skk += kk * kk
            sdk += kk * d
            kmax = max(kmax, kk)
            bt = sdk / skk
            used = bt if abs(bt - T) * kmax > 2 * period_ticks else T
    bits = []
    j = 0
    lvl = 0
    for b in range(nbits):
        centre = s + (b + 0.5) * used
        while j < len(inner) and inner[j] <= centre:
            lvl ^= 1
            j += 1
        bits.append(lvl)
    wire = 0
    for b in range(8):
        wire |= bits[1 + b] << b
    # glitches: pulses inside the frame shorter than half a bit. A pulse also cuts the
    # bit it lands in into short pieces, so a run of consecutive short runs is one glitch
    glitches = 0
    short_before = False
    for a, b2 in zip(bounds, bounds[1:], strict=False):
        short = b2 - a < half
        if short and not short_before:
            glitches += 1
        short_before = short
    err = (T / bt - 1) * 100 if skk else None
    return _Reading(wire, bits[-1] == 0, not framing.parity_ok(wire), glitches, err, used)


def _shape_reading(
    shape: tuple[int, ...], used: float, T: float, nbits: int, period_ticks: float, framing: Framing
) -> _Reading | None:
    """:func:`_read_frame` of a frame starting at tick 0, or None when an edge lies so near
    a bit centre that the same edges at another start might read differently."""
    got = _read_frame(0, shape, used, T, nbits, period_ticks, framing)
    if nbits * got.used >= _EXACT_BELOW / 2:
        return None  # centres this far out could round differently past _EXACT_BELOW
    for b in range(nbits):
        centre = (b + 0.5) * got.used
        for e in shape:
            if abs(e - centre) <= _MARGIN:
                return None
    return got


class _Shapes(dict):
    """Frame readings by shape, ``(bit time, *edges relative to the start bit)``: a miss
    reads the shape (:func:`_shape_reading`, None when too near a bit centre) and keeps it,
    after dropping them all once :data:`FRAME_SHAPES` are kept; a hit, the usual case, costs
    the decoder's loop one dict lookup and no call."""

    __slots__ = ("args",)

    def __init__(self, T: float, nbits: int, period_ticks: float, framing: Framing) -> None:
        super().__init__()
        self.args = (T, nbits, period_ticks, framing)

    def __missing__(self, key: tuple) -> _Reading | None:
        if len(self) >= FRAME_SHAPES:
            self.clear()
        reading = self[key] = _shape_reading(key[1:], key[0], *self.args)
        return reading


#: How many lines' kept shapes a process holds (a line: bit time, bits, sample period and
#: framing, which a shape's reading depends on besides its edges).
KEPT_LINES = 8
_KEPT: dict[tuple[float, int, float, Framing], _Shapes] = {}


def _shapes_for(T: float, nbits: int, period_ticks: float, framing: Framing) -> _Shapes:
    """The kept shapes of this line, shared by every decode of it in this process: a reading
    is a pure function of the shape and the line, and a matrix worker decodes the same line
    hundreds of times (each channel of each row twice for its polarity, then whole), so each
    shape is read once per process instead of once per decode. Bounded as :class:`_Shapes`
    is, and to :data:`KEPT_LINES` lines (the oldest dropped)."""
    key = (T, nbits, period_ticks, framing)
    shapes = _KEPT.get(key)
    if shapes is None:
        if len(_KEPT) >= KEPT_LINES:
            _KEPT.pop(next(iter(_KEPT)))
        shapes = _KEPT[key] = _Shapes(T, nbits, period_ticks, framing)
    return shapes


def _refill(src: Iterator[list[int]], buf: list[int], i: int, above: float) -> tuple[list, bool]:
    """``buf[i:]`` with chunks appended until it holds two edges and its last is above
    ``above``; and whether chunks may be left. Edges are non-decreasing (every reader's)."""
    rest = buf[i:]
    while len(rest) < 2 or rest[-1] <= above:
        nxt = next(src, None)
        if nxt is None:
            return rest, False
        rest.extend(nxt)
    return rest, True


@dataclass(frozen=True, slots=True)
class _Line:
    """What :func:`decode` is told about the line, fixed for a whole decode: handed to the
    scanning loop as one value, which takes the few it uses per frame into locals."""

    T: float  # ticks per bit
    nbits: int
    tick_rate: float
    t0: float
    uncertainty: float
    period_ticks: float
    framing: Framing
    end_tick: Callable[[], int | None] | None
    break_min: float
    pulse_min: float


def decode(
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
) -> Iterator[Decoded]:
    """Frames, breaks, pulses and glitches in time order, from edge ticks (non-decreasing).

    ``period_ticks``: how many ticks one sample period spans (the edge position error), used
    to tell a measured bit rate from rounding. ``end_tick``: asked, once the edges are
    exhausted, where the capture ends, to measure a spacing still running there (a break the
    capture cut); without it such a spacing is dropped.

    The edges are held a chunk or two at a time in one list scanned by index (``bisect`` for
    the edges inside a frame), and each frame shape is read once a process (:func:`_shapes_for`).

    A character that follows the previous one within a frame's time is read from the bit
    time that one was read with, when it read cleanly: it is the same sender's (a reply's
    characters), and a frame whose only inner edge comes late (0xC0: seven spacing bits,
    then marking) fits a fast and a slow sender equally well (6.46 bits at 1300 baud is 6
    bits at 1114): the sender's rate seen a character earlier settles it."""
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
    yield from _synchronised(_scan(iter(chunks), level, line), SYNC_BITS * line.T / tick_rate, t0)


def _capture_end(s: int, end_tick: Callable[[], int | None] | None) -> int:
    """Where a spacing from ``s`` still running when the edges run out ends: at the
    capture's end when the reader can say, else at ``s`` (no length: it is dropped)."""
    last = end_tick() if end_tick is not None else None
    return s if last is None else max(s, last)


def _spacing(s: int, r_end: int, last_end: float | None, line: _Line) -> Decoded:
    """The break or spacing pulse from tick ``s`` to ``r_end`` (kept apart by length,
    R-7.0-02..04); rare next to frames, so built outside the scanning loop."""
    tick_rate, t0 = line.tick_rate, line.t0
    kind = "break" if (r_end - s) / tick_rate >= line.break_min else "pulse"
    ev = Event(
        EventKind.BREAK,
        BUS,
        t0 + s / tick_rate,
        t0 + r_end / tick_rate,
        text="" if kind == "break" else SPACING_PULSE,
        uncertainty=line.uncertainty,
    )
    marking = None if last_end is None else (s - last_end) / tick_rate
    return Decoded(kind, ev, ev.start, ev.end, marking_before=marking)


def _start(
    src: Iterator[list[int]], level: int
) -> tuple[list[int], int, bool, float | None] | None:
    """The scan's starting state: the edges held, the next one not consumed, whether chunks
    may be left in ``src``, and the tick where the previous frame or break ended. A capture
    that starts inside spacing (``level`` 0) has that spacing's start unknown: it is
    skipped, up to its first edge (None: there is none)."""
    if level != 0:
        return [], 0, True, None
    buf, more = _refill(src, [], 0, float("-inf"))
    if not buf:
        return None
    return buf, 1, more, buf[0]


def _consume_to(
    src: Iterator[list[int]], buf: list[int], i: int, more: bool, stop: float
) -> tuple[list[int], bool, int]:
    """``buf``, ``more`` and the first edge after ``stop`` (a bit centre past the frame's
    window the scan holds edges for), chunks appended as needed: a rare case, off the
    scan's own path."""
    if more and buf[-1] <= stop:
        buf, more = _refill(src, buf, i, stop)
        i = 0
    return buf, more, bisect_right(buf, stop, i)


#: Marking (in bits) before a falling edge that makes it a start bit for certain: inside a
#: 7E1 or 8N1 frame the line marks at most 9 bits in a row (bit 1 to the stop bit), so after
#: a longer run the next fall starts a frame. A capture that begins on a busy line is read
#: from the first such run (or the first spacing too long for a frame) on.
SYNC_BITS = 9.5


#: Frames the decoder holds while the capture has not yet proven where start bits are. A
#: stream that never pauses long enough (a UART test pattern) is read as a plain UART reads
#: it, from the first falling edge, once this many frames came without a proof.
HOLD_FRAMES = 64


def _synchronised(items: Iterator[Decoded], sync_s: float, t0: float) -> Iterator[Decoded]:
    """``items`` from the first start bit the capture proves on: a frame after at least
    :data:`SYNC_BITS` of marking, or a spacing too long for a frame (a break). The frames
    before the proof are marked ``partial``: a capture begun inside traffic reads them from
    a data bit. Without a proof within :data:`HOLD_FRAMES` frames, or in the whole capture,
    the frames are taken as they read."""
    held: list[Decoded] = []
    for d in items:
        if d.kind in ("break", "pulse") or (d.kind == "char" and _proves(d, sync_s, t0)):
            yield from _cut(held)
            held = []
            yield d
            break
        held.append(d)
        if len(held) >= HOLD_FRAMES:
            break
    yield from held  # no proof (within HOLD_FRAMES frames, or at all): as they read
    yield from items


def _proves(d: Decoded, sync_s: float, t0: float) -> bool:
    """Whether the marking before frame ``d`` proves its start bit (before the first frame
    of a capture that begins marking: since the capture began)."""
    marking = d.start - t0 if d.marking_before is None else d.marking_before
    return marking >= sync_s - 1e-9


def _cut(held: list[Decoded]) -> Iterator[Decoded]:
    """``held`` with every frame marked ``partial`` (glitches stay what they were)."""
    for d in held:
        yield Decoded("partial", None, d.start, d.end) if d.kind == "char" else d


def _cut_by_end(
    framing_error: bool, stop: float, buf: list[int], end_tick: Callable[[], int | None] | None
) -> bool:
    """Whether the last frame of a capture is one the capture cut: its stop bit still low
    when the edges ran out, or the capture's end before the stop bit's centre, so that bits
    read as marking were never sampled. Only a reader that knows where the capture ended
    (a sigrok session's sample count, a VCD's last timestamp) can show the second; one whose
    end is its last edge (a CSV of transitions) cannot, and its last frame is read."""
    if framing_error:
        return True
    last = end_tick() if end_tick is not None else None
    return last is not None and bool(buf) and last > buf[-1] and last < stop


def _spans(T: float, nbits: int) -> tuple[float, float, float]:
    """The scan's lengths in ticks: half a bit (shorter is a glitch), the stop bit's centre
    (a longer spacing is no frame) and a frame's window (a slow sender's run a little past
    the nominal end)."""
    return T / 2, (nbits - 0.5) * T, nbits * T * 1.1


def _scan(src: Iterator[list[int]], level: int, line: _Line) -> Iterator[Decoded]:
    """:func:`decode`'s loop, one frame, break, pulse or glitch a turn from the falling edge
    that starts it (``level``: the UART-side level the capture starts at). The hot path:
    per frame it calls nothing it can do inline, nor looks a global up; helpers do the rest."""
    T, nbits, tick_rate, t0 = line.T, line.nbits, line.tick_rate, line.t0
    uncertainty = line.uncertainty
    half, stop_centre, frame_span = _spans(T, nbits)
    shapes = _shapes_for(T, nbits, line.period_ticks, line.framing)
    state = _start(src, level)
    if state is None:
        return
    buf, i, more, last_end = state
    prior_bt: float | None = None  # the previous clean character's bit time (see decode)
    exact_below, char, bus, event, decoded = _EXACT_BELOW, EventKind.CHAR, BUS, full_event, Decoded
    while True:
        if more and len(buf) - i < 2:
            buf, more = _refill(src, buf, i, float("-inf"))
            i = 0
        n_buf = len(buf)
        if i >= n_buf:
            return
        s = buf[i]
        r = buf[i + 1] if i + 1 < n_buf else None
        i += 1  # the falling edge is consumed; r (if any) is still ahead
        r_end = r if r is not None else _capture_end(s, line.end_tick)
        length = r_end - s
        if length < half:
            if r is None:
                return  # the capture ends right after a falling edge: nothing to decode
            i += 1
            yield Decoded("glitch", None, t0 + s / tick_rate, t0 + r / tick_rate)
            continue
        if length > stop_centre and length / tick_rate >= line.pulse_min:
            yield _spacing(s, r_end, last_end, line)
            prior_bt = None
            if r is None:
                return
            i += 1
            last_end = r
            continue
        # a frame: the edges inside it (bisect in a window first: a frame holds a few)
        frame_end = s + frame_span
        if more and buf[-1] <= frame_end:
            buf, more = _refill(src, buf, i, frame_end)
            i = 0
        hi, n_buf = i + 16, len(buf)
        j = bisect_left(buf, frame_end, i, hi if hi < n_buf else n_buf)
        if j == hi:
            j = bisect_left(buf, frame_end, hi)
        follows = prior_bt is not None and last_end is not None and s - last_end < nbits * T
        used = prior_bt if follows and prior_bt is not None else T
        reading = shapes[(used, *map(s.__rsub__, buf[i:j]))] if s < exact_below else None
        if reading is None:  # an edge on a bit centre, or a tick too far for the shapes
            reading = _read_frame(s, buf[i:j], used, T, nbits, line.period_ticks, line.framing)
        used, framing_error = reading.used, reading.framing_error
        end = s + nbits * used
        # consume the edges up to the stop bit's centre; a low stop bit runs on to its rise
        stop = s + (nbits - 0.5) * used
        if stop < frame_end:  # every edge from j on is later
            i = bisect_right(buf, stop, i, j)
        else:  # a slow sender's stop bit, past the frame's window
            buf, more, i = _consume_to(src, buf, i, more, stop)
        e = buf[i] if i < len(buf) else None
        if framing_error and e is not None:
            i += 1
            end = max(end, e)
        elif e is not None and e < end:
            end = e  # the next start bit came first: this stop bit ended there (back to back)
        start = t0 + s / tick_rate
        if e is None and not more and _cut_by_end(framing_error, stop, buf, line.end_tick):
            # the capture ended in its low stop bit, or before the stop bit's centre while
            # the line marked: the bits after the end are unknown, not marking
            yield Decoded("partial", None, start, t0 + end / tick_rate)
            return
        ev = event(char, bus, start, t0 + end / tick_rate, reading.wire, "", uncertainty, None)
        marking = None if last_end is None else max(0.0, (s - last_end) / tick_rate)
        last_end = end
        prior_bt = None if framing_error else used  # 8N1 binary bytes fail 7E1 parity
        pe, err, glitches = reading.parity_error, reading.err, reading.glitches
        yield decoded("char", ev, start, ev.end, framing_error, pe, err, glitches, marking)
