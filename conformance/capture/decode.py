"""The capture side's one entry point for judging: a file in, transcript events out.

``decode_capture`` reads any supported capture, picks or is told the polarity, decodes frames
at sample resolution and returns :class:`CaptureDecode`: the events (origin :data:`BUS`, since
one wire does not say who spoke, unless a second channel carries the recorder's TX), the
capture's own uncertainty for the judges, and the diagnostics a UART would have hidden.
Everything a user can get wrong (file, channel, baud, framing) ends as :class:`CaptureError`.
"""

from __future__ import annotations

import os
import statistics
from array import array
from bisect import bisect_left
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from itertools import chain, compress, count, repeat
from operator import is_not

import numpy as np

from ..event_store import Column, CompactEvents, NotCompact
from ..transcript import BUS, DUT, TOOL, Event, EventKind, full_event
from .columns import WireColumns
from .edges import Edges
from .errors import CaptureError
from .formats import read_edges, sniff
from .glitch_filter import DEFAULT_BITS, GlitchFilter
from .heap import give_back_freed_heap
from .uart import HOLD_FRAMES, SYNC_BITS, Decoded, Framing, _synchronised, decode
from .uart_bulk import Batch, decode_batches

PROBE_EDGES = 2000  # edges decoded both ways to choose the polarity
#: Clean characters the short polarity probe (the first :data:`PROBE_EDGES` edges) must read
#: in one polarity, with not one bad frame or glitch, while the other polarity reads worse,
#: before its choice is taken without decoding the rest of the first block both ways
SHORT_PROBE_CLEAN = 64
#: A polarity's lead in clean frames that outweighs the idle level: edges read the wrong way
#: round pass a 7E1 frame's parity and stop bit often enough by chance that on a capture of a
#: handful of characters (two breaks and two characters: the wrong way reads three clean
#: ones, the right way two, the breaks counting for neither) a lead of one frame is chance,
#: and the level the capture starts at (the line's idle) decides instead.
CLEAN_LEAD = 1
MIN_BAD = 8  # fewer bad frames than this are reported, never taken for a wrong bit rate
#: Glitches per decoded frame above which a capture is mostly pulses too short for a bit:
#: with the shortest pulses off the bit rate, a wrong bit rate rather than a noisy line
GLITCHES_PER_FRAME = 4
#: Whether captures are decoded in bulk (:mod:`.uart_bulk`); False: by the reference decoder,
#: a Python step a frame (:func:`.uart.decode`), which gives the same result item for item
#: (``tests/capture/test_uart_bulk.py`` decodes both ways)
BULK = True
RECORDER_ORIGIN = TOOL  # origin of what the recorder's TX channel shows
SENSOR_ORIGIN = DUT  # origin of the rest of the bus


@dataclass
class CaptureDecode:
    """What a capture holds, decoded. ``problems``: every break, pulse, glitch and frame with
    a framing or parity error or glitches, in time order (clean characters are counted, not
    kept twice), or only those frames where :attr:`characters_problems_only`;
    ``baud_error_pct``: each character's measured bit-rate error, in event order
    (NaN where its edges could not tell): a :class:`~conformance.event_store.Column` where
    the events are kept compact (written out a chunk at a time: an hour's 342,000 characters
    are not held in RAM while the capture is judged, issue 22), else an array."""

    path: str
    format: str
    events: list[Event]
    uncertainty_s: float
    inverted: bool
    polarity_detected: bool
    sample_rate: float
    channel: str
    channels: list[str]
    baud: float
    framing: str
    tx_channel: str | None = None
    chars: int = 0
    framing_errors: int = 0
    parity_errors: int = 0
    glitches: int = 0
    breaks: int = 0
    pulses: int = 0
    #: frames the capture cut (begun before it could tell a start bit, or still running
    #: at its end): dropped, never judged
    partial_frames: int = 0
    #: the glitch filter's width (s; 0: off), the pulses it removed, and how many of them
    #: sat beside an edge that stayed (whose stamp is then widened by the width)
    glitch_filter_s: float = 0.0
    filtered: int = 0
    filtered_beside_edges: int = 0
    #: the plausibility check's refusal, overridden by ``force`` (None: not refused)
    forced_past: str | None = None
    #: the events as columns (``decode_capture(..., columns=True)``), ``events`` then empty:
    #: :meth:`event_list` gives them either way
    columns: WireColumns | None = None
    baud_error_pct: array | Column = field(default_factory=lambda: array("f"))
    problems: list[Decoded] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    #: ``problems`` holds the characters' alone (:func:`~.uart.character_problems`, all a
    #: judgement reads of them): a decode kept compact for judging (issue 22). Its breaks,
    #: pulses, glitches and cut frames are counted and, but for the last two, events; none
    #: is held as an item while the capture is decoded: a busy bus's every break was one
    #: (an hour's 14,875, ~4.5 MB with their events and stamps at two hours), the decode's
    #: one transient that grew with the capture, whose pages it left behind
    characters_problems_only: bool = False

    @property
    def polarity(self) -> str:
        """``"uart"`` (idles high: TTL side of a transceiver) or ``"line"`` (the SDI-12 wire
        itself, idles low)."""
        return "line" if self.inverted else "uart"

    def event_list(self) -> list[Event]:
        """The events, made from :attr:`columns` when the decode kept them so."""
        return self.columns.events() if self.columns is not None else self.events

    def baud_error_summary(self) -> tuple[float, float, float] | None:
        """(min, median, max) of the per-frame bit-rate error in %, or None."""
        vals = [v for v in self.baud_error_pct if v == v]
        if not vals:
            return None
        return min(vals), statistics.median(vals), max(vals)


#: what a probe needs of each decoded item: a clean character, a character with a framing or
#: parity error, a glitch, or anything else (a break, a spacing pulse, a partial frame)
OTHER, CLEAN, BAD_CHAR, GLITCH = 0, 1, 2, 3


def _code(d: Decoded) -> int:
    """``d``'s probe code (:data:`CLEAN`, :data:`BAD_CHAR`, :data:`GLITCH`, :data:`OTHER`)."""
    if d.kind == "char":
        return BAD_CHAR if d.framing_error or d.parity_error else CLEAN
    return GLITCH if d.kind == "glitch" else OTHER


def _score(codes: list[int]) -> int:
    """Clean characters less bad ones and glitches, of items given by their probe codes."""
    return codes.count(CLEAN) - codes.count(BAD_CHAR) - codes.count(GLITCH)


def _clean_winner(decoded: dict[bool, list[int]]) -> bool | None:
    """The polarity whose decode of the short probe (its items' probe codes) is beyond
    doubt: at least :data:`SHORT_PROBE_CLEAN` clean characters and no bad frame or glitch
    (the last item aside: the probe's cut may fall inside a frame), while the other scores
    lower. None: not decisive, the whole first block decides."""
    for inv, codes in decoded.items():
        body = codes[:-1]
        clean = body.count(CLEAN) + body.count(BAD_CHAR)
        bad = BAD_CHAR in body or GLITCH in body
        if clean >= SHORT_PROBE_CLEAN and not bad and _score(body) > _score(decoded[not inv][:-1]):
            return inv
    return None


def _probe_codes(
    edges: list[int],
    *,
    initial_level: int,
    tick_rate: float,
    baud: float,
    invert: bool,
    framing: Framing,
) -> list[int]:
    """The probe codes of what ``decode([edges], ...)`` gives (t0 0, no uncertainty), item
    for item, without making an event or item of each certified frame: the bulk decoder's
    batches, their first :data:`~.uart.HOLD_FRAMES` items synchronised as
    :func:`_collect_batches` does, each certified frame's code read from its batch's
    lists (the probe decodes 2,000 edges both ways on each channel of a capture)."""
    kw = dict(initial_level=initial_level, tick_rate=tick_rate, baud=baud, invert=invert)
    if not BULK:
        return [_code(d) for d in decode([edges], framing=framing, **kw)]
    batches = list(decode_batches([edges], framing=framing, **kw))
    _synchronise_head(batches, 0.0, SYNC_BITS * (tick_rate / baud) / tick_rate, 0.0)
    codes: list[int] = []
    add = codes.append
    for b in batches:
        fe, pe = b.framing_error, b.parity_error
        for x in b.order:
            if x.__class__ is int:
                add(BAD_CHAR if fe[x] or pe[x] else CLEAN)  # type: ignore[index]
            else:
                add(_code(x))  # type: ignore[arg-type]
    return codes


def _choose_polarity(
    edges: Edges, prefix: list[int], baud: float, framing: Framing
) -> tuple[bool, str]:
    """Decode the first edges both ways; the polarity that gives more clean frames (by more
    than :data:`CLEAN_LEAD`) wins, the starting level (idle) decides a closer call.

    The first :data:`PROBE_EDGES` edges are tried first (a sigrok block holds tens of
    thousands: decoding all of them twice was most of a short capture's probe); only when
    they read cleanly one way (:func:`_clean_winner`) is that taken, anything less clear is
    decided on the whole ``prefix`` as before (``tests/capture/test_polarity_probe.py``
    holds a capture whose first edges alone would pick the wrong polarity). Each way's
    items are read as probe codes (:func:`_probe_codes`), none made."""
    kw = dict(initial_level=edges.initial_level, tick_rate=edges.tick_rate, baud=baud)
    if len(prefix) > PROBE_EDGES:
        short = prefix[:PROBE_EDGES]
        tried = {
            inv: _probe_codes(short, invert=inv, framing=framing, **kw) for inv in (False, True)
        }
        inv = _clean_winner(tried)
        if inv is not None:
            return (
                inv,
                f"polarity {'line (inverted)' if inv else 'UART'} detected from clean frames",
            )
    scores = {
        inv: _score(_probe_codes(prefix, invert=inv, framing=framing, **kw))
        for inv in (False, True)
    }
    if abs(scores[False] - scores[True]) > CLEAN_LEAD:
        inv = scores[True] > scores[False]
        return inv, f"polarity {'line (inverted)' if inv else 'UART'} detected from clean frames"
    inv = edges.initial_level == 0
    return inv, f"polarity {'line (inverted)' if inv else 'UART'} assumed from the idle level"


def _estimated_baud(prefix: list[int], tick_rate: float) -> float | None:
    """The bit rate the shortest pulses of ``prefix`` suggest: a low percentile of the
    rising gaps between edges (one bit, not a glitch), the element ``sorted`` would put at
    ``len // 20``, found by a partial sort in numpy (a row's two channels sorted ~8,000 gaps
    each in Python, ~3 ms of a fault-matrix row); :func:`_estimated_baud_sorted` for ticks
    numpy does not hold as int64 (floats, or ints past its range)."""
    ticks = np.array(prefix)
    if ticks.dtype != np.int64:
        return _estimated_baud_sorted(prefix, tick_rate)
    gaps = np.diff(ticks)
    runs = gaps[gaps > 0]
    if runs.size < 8:
        return None
    k = runs.size // 20
    return tick_rate / int(np.partition(runs, k)[k])


def _estimated_baud_sorted(prefix: list[int], tick_rate: float) -> float | None:
    """:func:`_estimated_baud` by a full sort in Python (any int)."""
    runs = sorted(b - a for a, b in zip(prefix, prefix[1:], strict=False) if b > a)
    if len(runs) < 8:
        return None
    return tick_rate / runs[len(runs) // 20]  # a low percentile: one bit, not a glitch


@dataclass(frozen=True)
class DecodeSettings:
    """How a channel is decoded beyond its format: the line's bit rate and framing, an extra
    edge error of the analyzer's input (s), the glitch filter's width (s; 0: off) and
    whether a decode the plausibility check refuses is judged anyway (``force``);
    ``compact``: the bus's events kept in a :class:`~conformance.event_store.CompactEvents`
    as they are made (a recording loaded for judging: issue 22), not a list."""

    baud: float
    framing: Framing
    edge_error: float = 0.0
    glitch_filter: float = 0.0
    force: bool = False
    compact: bool = False


def _events_of(how: DecodeSettings, made: bool) -> list[Event]:
    """A channel's decode's events: a :class:`~conformance.event_store.CompactEvents` where
    ``how.compact`` asks for one and the channel's events are ``made`` (not a TX channel's
    marks, nor columns), else a list."""
    return CompactEvents() if how.compact and made else []  # type: ignore[return-value]


def _rates_of(how: DecodeSettings, made: bool) -> array | Column:
    """A channel's decode's bit-rate errors: a :class:`~conformance.event_store.Column`
    (its full chunks written out, not held) beside a compact store of its events
    (:func:`_events_of`), else an array."""
    return Column("f") if how.compact and made else array("f")


def _decode_channel(
    path: str,
    fmt: str,
    channel: str | None,
    invert: bool | None,
    how: DecodeSettings,
    origin: str = BUS,
    marks: Marks | None = None,
    into: Marks | None = None,
    columns: bool = False,
) -> CaptureDecode:
    """One channel decoded. ``marks``: the recorder's TX channel, its characters and breaks
    giving the events they match :data:`RECORDER_ORIGIN` as they are made (the others get
    ``origin``); ``into``: this is that TX channel, its characters and breaks put there,
    no event made (BULK only); ``columns``: the events kept as :class:`.WireColumns`
    (BULK only), none made."""
    baud, framing, edge_error = how.baud, how.framing, how.edge_error
    edges = read_edges(path, channel, fmt)
    glitch = GlitchFilter(how.glitch_filter * edges.tick_rate)
    chunks = iter(glitch(edges.chunks, edges.min_gap))
    prefix: list[int] = []
    taken: list[list[int]] = []
    while len(prefix) < PROBE_EDGES and (chunk := next(chunks, None)) is not None:
        taken.append(chunk)
        prefix.extend(chunk)
    if not prefix:
        raise CaptureError(
            path, f"channel {edges.channel!r} never changes level: no traffic to decode"
        )
    notes = list(edges.notes)
    if invert is None:
        inverted, why = _choose_polarity(edges, prefix, baud, framing)
        notes.append(why)
    else:
        inverted = invert
        notes.append(f"polarity {'line (inverted)' if invert else 'UART'} forced")
    uncertainty = edges.period + edge_error
    out = CaptureDecode(
        path=path,
        format=fmt,
        events=_events_of(how, into is None and not columns),
        baud_error_pct=_rates_of(how, into is None and not columns),
        uncertainty_s=uncertainty,
        inverted=inverted,
        polarity_detected=invert is None,
        sample_rate=1.0 / edges.period,
        channel=edges.channel,
        channels=edges.channels,
        baud=baud,
        framing=str(framing),
        notes=notes,
        characters_problems_only=how.compact,
    )
    line = dict(
        initial_level=edges.initial_level,
        tick_rate=edges.tick_rate,
        invert=inverted,
        baud=baud,
        framing=framing,
        t0=edges.t0,
        uncertainty=uncertainty,
        period_ticks=edges.period * edges.tick_rate,
        end_tick=edges.end,
    )
    if BULK:
        sync_s = SYNC_BITS * (edges.tick_rate / baud) / edges.tick_rate  # as uart.decode has it
        batches = decode_batches(chain(taken, chunks), **line)
        if marks is not None:
            marks.tolerance = 0.5 / baud + 2 * uncertainty  # merge_tx's, if not widened
        if columns and into is None:
            out.columns = WireColumns(uncertainty)
        _collect_batches(batches, out, sync_s, edges.t0, origin, marks, into)
    else:
        _collect(decode(chain(taken, chunks), **line), out)
    _filtered(out, glitch, how.glitch_filter)
    held = into is not None and bool(into.start)
    est = _estimated_baud(prefix, edges.tick_rate)
    _check_plausible(out, est, framing, force=how.force, held=held)
    return out


def _filtered(out: CaptureDecode, glitch: GlitchFilter, width: float) -> None:
    """What the glitch filter took out, in ``out``; where a removed pulse sat beside an edge
    that stayed (a chattering transition), that edge is known only to the filter's width,
    so every stamp is widened by it (a rare case: a clean capture's stamps stay as sampled)."""
    out.glitch_filter_s, out.filtered = width, glitch.removed
    out.filtered_beside_edges = glitch.beside_edges
    if glitch.beside_edges:
        if out.columns is not None:  # rare: the events made, and widened as before
            out.events, out.columns = out.columns.events(), None
        out.uncertainty_s += width
        out.events = [replace(e, uncertainty=e.uncertainty + width) for e in out.events]


def _collect(decoded: Iterator[Decoded], out: CaptureDecode) -> None:
    """Every decoded item into ``out``: its events, problems, per-character bit-rate errors
    and counts (the reference path, ``BULK`` off: :func:`_collect_batches` is the fast one)."""
    tally = _Tally(out)
    for d in decoded:
        if d.event is not None:
            out.events.append(d.event)
        tally.item(d)
    tally.store(out)


class _Tally:
    """The counts of a capture's decoded items, and its problems and bit-rate errors, as
    :func:`_collect` and the rare items of :func:`_collect_batches` (problems, the first
    frames) add them; the bulk loop adds its certified frames to the counters directly."""

    def __init__(self, out: CaptureDecode) -> None:
        self.problems, self.baud_error = out.problems, out.baud_error_pct.append
        self.every = not out.characters_problems_only  # else the characters' problems alone
        self.chars = self.framing_errors = self.parity_errors = self.glitches = 0
        self.breaks = self.pulses = self.partial = 0

    def item(self, d: Decoded) -> None:
        """Count one item (its event is the caller's: origins differ)."""
        if d.kind == "char":
            self.chars += 1
            self.framing_errors += d.framing_error
            self.parity_errors += d.parity_error
            self.glitches += d.glitches
            self.baud_error(float("nan") if d.baud_error_pct is None else d.baud_error_pct)
            if d.framing_error or d.parity_error or d.glitches:
                self.problems.append(d)
            return
        if self.every:
            self.problems.append(d)
        self.breaks += d.kind == "break"
        self.pulses += d.kind == "pulse"
        self.glitches += d.kind == "glitch"
        self.partial += d.kind == "partial"

    def certified(self, chars: int, framing: int, parity: int, glitches: int) -> None:
        """Add the counts the bulk loop kept for its certified frames."""
        self.chars += chars
        self.framing_errors += framing
        self.parity_errors += parity
        self.glitches += glitches

    def store(self, out: CaptureDecode) -> None:
        out.chars, out.breaks, out.pulses, out.glitches = (
            self.chars, self.breaks, self.pulses, self.glitches,
        )  # fmt: skip
        out.partial_frames = self.partial
        out.framing_errors, out.parity_errors = self.framing_errors, self.parity_errors


def _collect_batches(
    batches: Iterator[Batch],
    out: CaptureDecode,
    sync_s: float,
    t0: float,
    origin: str = BUS,
    marks: Marks | None = None,
    into: Marks | None = None,
) -> None:
    """:func:`_collect` of :func:`~.uart_bulk.decode_batches`' items (the first
    :data:`~.uart.HOLD_FRAMES` :func:`~.uart._synchronised`); origin ``origin``, or
    :data:`RECORDER_ORIGIN` where ``marks`` matches; ``into`` or ``out.columns``: no event
    made, the fields go there (:func:`_stretch`: a stretch of certified frames whole)."""
    unc, nan = out.uncertainty_s, float("nan")
    head = _synchronised_head(batches, unc, sync_s, t0)
    problems, tally = out.problems, _Tally(out)
    add, baud_error = out.events.append, out.baud_error_pct.append
    # the certified frames' counts; TX events matched since Marks was last told
    chars = framing_errors = parity_errors = glitches = matched = 0
    char, bus, event = EventKind.CHAR, origin, full_event
    mark = marks.origin if marks is not None and marks.start else None
    tx_start, tx_kind, tx_wire = (marks.start, marks.kind, marks.wire) if mark else ([], [], [])
    n_tx, tol, j, recorder = len(tx_start), marks.tolerance if mark else 0.0, 0, RECORDER_ORIGIN
    add = into.add if into is not None else add
    if (cols := out.columns) is not None:
        add, (put_s, put_e, put_w, put_o) = cols.add_made, cols.appenders()
    stretched = cols is not None or into is not None
    tx = _TxArrays.of(marks) if stretched and n_tx else None
    for b in chain(head, batches):
        st, en, wi, err = b.start, b.end, b.wire, b.err
        fe, pe, gl = b.framing_error, b.parity_error, b.glitches
        for part in _stretches(b.order) if stretched else (b.order,):
            taken = _stretch(b, part, out, tally, into, tx, n_tx > 0, j, tol, bus)
            if taken is not None:  # a stretch of certified frames, taken whole
                j, matched = taken[0], matched + taken[1]
                continue
            for x in part:
                if x.__class__ is int:
                    s, w = st[x], wi[x]  # type: ignore[index]
                    if into is not None:
                        add(char, s, w)
                    else:
                        o = bus
                        if n_tx:
                            while j < n_tx and tx_start[j] < s - tol:
                                j += 1
                            hit = j < n_tx and abs(tx_start[j] - s) <= tol and tx_wire[j] == w
                            if hit and tx_kind[j] is char:
                                o, j, matched = recorder, j + 1, matched + 1
                        if cols is None:
                            add(event(char, o, s, en[x], w, "", unc, None))  # type: ignore[index]
                        else:  # four columns, no event
                            put_s(s), put_e(en[x]), put_w(w), put_o(o)  # type: ignore[index]
                    chars += 1
                    e = err[x]  # type: ignore[index]
                    baud_error(nan if e is None else e)
                    if fe[x] or pe[x] or gl[x]:  # type: ignore[index]
                        framing_errors += fe[x]  # type: ignore[index]
                        parity_errors += pe[x]  # type: ignore[index]
                        glitches += gl[x]  # type: ignore[index]
                        problems.append(b.item(x, unc))  # type: ignore[arg-type]
                    continue
                d: Decoded = x  # type: ignore[assignment]
                if (ev := d.event) is not None:
                    if into is not None:
                        add(ev.kind, ev.start, ev.wire)
                        tally.item(d)
                        continue
                    o = bus
                    if marks is not None and mark is not None:
                        o, j, matched = marks.resumed(j, matched, ev.kind, ev.start, ev.wire, bus)
                    if o != BUS:
                        u, du = ev.uncertainty, ev.duration_uncertainty
                        ev = event(ev.kind, o, ev.start, ev.end, ev.wire, ev.text, u, du)
                    add(ev)
                tally.item(d)
    if mark is not None:
        marks.at, marks.matched = j, marks.matched + matched  # type: ignore[union-attr]
    tally.certified(chars, framing_errors, parity_errors, glitches)
    tally.store(out)


def _stretch(
    b: Batch,
    part: range | list,
    out: CaptureDecode,
    tally: _Tally,
    into: Marks | None,
    tx: _TxArrays | None,
    matching: bool,
    j: int,
    tol: float,
    other: str,
) -> tuple[int, int] | None:
    """Certified frames ``part`` of ``b`` taken whole by :func:`_collect_batches`: into
    ``into`` (the TX channel's marks) or ``out.columns`` (``matching``: their origins by
    :func:`_origins` from ``tx``, the TX's arrays; else all ``other``), their bit-rate
    errors and problems into ``out``, their counts into ``tally``. Gives the TX place
    after them and the TX events they matched; None when the TX matching must walk them
    one by one (nothing taken)."""
    if part.__class__ is not range:
        return None  # items one by one
    p, q = part.start, part.stop
    st, en, wi, cols = b.start, b.end, b.wire, out.columns
    hits = 0
    if into is not None:
        into.start.extend(st[p:q])
        into.kind.extend([EventKind.CHAR] * (q - p))
        into.wire.extend(wi[p:q])
    elif cols is not None:
        found = _origins(tx, b, p, q, j, tol, other) if matching else ([other] * (q - p), j, 0)
        if found is None:
            return None
        origins, j, hits = found
        cols.start.extend(st[p:q])
        cols.end.extend(en[p:q])
        cols.wire.extend(wi[p:q])
        cols.origin.extend(origins)
    out.baud_error_pct.extend(b.err_nan[p:q])
    fe, pe, gl, flagged = b.framing_error, b.parity_error, b.glitches, b.flagged
    f = pa = g = 0
    for x in flagged[bisect_left(flagged, p) : bisect_left(flagged, q)]:
        f, pa, g = f + fe[x], pa + pe[x], g + gl[x]
        out.problems.append(b.item(x, out.uncertainty_s))
    tally.certified(q - p, f, pa, g)
    return j, hits


#: certified frames in a row, at least, that are taken whole (:func:`_stretches`): below
#: it numpy's fixed cost per call is more than a step per frame
STRETCH_MIN = 16


def _stretches(order: list) -> Iterator[list | range]:
    """A batch's items in order as stretches: each run of at least :data:`STRETCH_MIN`
    certified frames with consecutive indices as the ``range`` of them, everything else
    as lists of items (a certified frame's index or a decoder's item)."""
    # the decoder's own items' places, found in C: most of a batch is certified frames
    made = list(compress(count(), map(is_not, map(type, order), repeat(int))))
    at = 0
    for k in [*made, len(order)]:
        if k - at >= STRETCH_MIN and order[k - 1] - order[at] == k - 1 - at:
            yield range(order[at], order[k - 1] + 1)  # indices rise by one from order[at]
        elif k > at:
            yield order[at:k]
        if k < len(order):
            yield order[k : k + 1]
        at = k + 1


@dataclass(frozen=True)
class _TxArrays:
    """The TX channel's marks as arrays (starts, wires, whether a character), for a
    stretch of bus frames matched at once (:func:`_origins`); None of a TX channel whose
    starts are not in order (a search needs them so)."""

    start: np.ndarray
    wire: np.ndarray
    char: np.ndarray

    @classmethod
    def of(cls, marks: Marks | None) -> _TxArrays | None:
        if marks is None or not marks.start:
            return None
        start = np.array(marks.start, dtype=np.float64)
        if start.size > 1 and not (start[1:] >= start[:-1]).all():
            return None
        char = EventKind.CHAR
        return cls(
            start, np.array(marks.wire, dtype=np.int64), np.array([k is char for k in marks.kind])
        )


def _origins(
    tx: _TxArrays | None, b: Batch, p: int, q: int, j: int, tol: float, other: str
) -> tuple[list[str], int, int] | None:
    """The origins :meth:`Marks.origin`'s walk gives certified frames ``p..q-1`` of ``b``
    from TX place ``j``, the place after and the matches, found by one search: each frame's
    place is the first TX start not before its own start less ``tol`` (what the walk passes
    to), unless the place after the frame before is past it; None when that happens (a TX
    event within reach of two frames) or there are no arrays: the caller walks."""
    if tx is None or b.start_array is None or b.wire_array is None:
        return None
    starts, n = b.start_array[p:q], tx.start.size
    at = np.searchsorted(tx.start, starts - tol, "left")
    if at[0] < j:
        return None
    near = np.minimum(at, n - 1)
    hit = (
        (at < n)
        & (np.abs(tx.start[near] - starts) <= tol)
        & (tx.wire[near] == b.wire_array[p:q])
        & tx.char[near]
    )
    if at.size > 1 and not (at[1:] >= at[:-1] + hit[:-1]).all():
        return None
    origins = [other] * (q - p)
    hits = np.flatnonzero(hit).tolist()
    for i in hits:
        origins[i] = RECORDER_ORIGIN
    return origins, int(at[-1] + hit[-1]), len(hits)


def _synchronised_head(
    batches: Iterator[Batch], unc: float, sync_s: float, t0: float
) -> list[Batch]:
    """The batches holding the first :data:`~.uart.HOLD_FRAMES` items, taken from
    ``batches`` and :func:`_synchronise_head`-ed."""
    head: list[Batch] = []
    while sum(len(b.order) for b in head) < HOLD_FRAMES and (b := next(batches, None)):
        head.append(b)
    _synchronise_head(head, unc, sync_s, t0)
    return head


def _synchronise_head(batches: list[Batch], unc: float, sync_s: float, t0: float) -> None:
    """The first :data:`~.uart.HOLD_FRAMES` items of ``batches`` made items and passed
    through :func:`~.uart._synchronised` in place: it decides on those alone (a frame that
    proves a start bit among them, or none), and gives back as many as it takes."""
    head: list[tuple[Batch, int]] = []
    for b in batches:
        for k in range(min(len(b.order), HOLD_FRAMES - len(head))):
            head.append((b, k))
        if len(head) >= HOLD_FRAMES:
            break
    items = [b.order[k] for b, k in head]
    made = [
        x if x.__class__ is not int else b.item(x, unc)  # type: ignore[arg-type]
        for x, (b, _) in zip(items, head, strict=True)
    ]
    for (b, k), d in zip(head, _synchronised(iter(made), sync_s, t0), strict=True):
        b.order[k] = d


def _check_plausible(
    out: CaptureDecode,
    est: float | None,
    framing: Framing,
    *,
    force: bool = False,
    held: bool = False,
) -> None:
    """Refuse a decode that is mostly errors (a wrong bit rate, framing or channel, rather
    than a noisy line: ``est`` is the bit rate the shortest pulses suggest) or holds no
    event at all, since judging it would only report the user's mistake as the device's.
    ``force``: a decode that is mostly errors is judged anyway, the refusal kept in
    ``out.forced_past`` for the notes (one with no event at all still cannot be).
    ``held``: its events were held as :class:`Marks`, not made (some were)."""
    path, baud = out.path, out.baud
    # spikes on an idle field cable are noise, not a sign of a wrong bit rate: what tells is
    # frames that do not read, or a capture that is mostly pulses too short for a bit
    bad = out.framing_errors + out.parity_errors
    spiky = out.glitches > GLITCHES_PER_FRAME * max(out.chars, 1)
    off = est is not None and not 0.8 < est / baud < 1.25
    if spiky and off and out.glitches >= MIN_BAD:
        bad += out.glitches
    if out.chars and bad >= MIN_BAD and bad * 5 >= out.chars and (off or 2 * bad > out.chars):
        hint = f"; the shortest pulses suggest about {est:.0f} baud" if est else ""
        why = (
            f"{bad} framing/parity errors and glitches in {out.chars} frames on "
            f"{out.channel!r} at {baud:g} baud {framing}: wrong bit rate, framing or "
            f"channel?{hint}"
        )
        if not force:
            raise CaptureError(path, why + " (--force judges it anyway)")
        out.forced_past = why
    if not out.events and not out.columns and not held:
        raise CaptureError(
            path, f"channel {out.channel!r} holds only glitches: no frame or break to decode"
        )


def merge_tx(bus: list[Event], tx: list[Event], tolerance: float) -> tuple[list[Event], int]:
    """The bus events with origin :data:`RECORDER_ORIGIN` where the recorder's TX channel shows the
    same character or break starting within ``tolerance`` seconds, else :data:`SENSOR_ORIGIN`; and
    how many TX events were not seen on the bus."""
    marks = Marks.of(tx, tolerance)
    origin, event = marks.origin, full_event
    out = [
        event(e.kind, origin(e.kind, e.start, e.wire, SENSOR_ORIGIN), e.start, e.end, e.wire,
              e.text, e.uncertainty, e.duration_uncertainty)
        for e in bus
    ]  # fmt: skip
    return out, marks.unseen()


@dataclass
class Marks:
    """The recorder's TX channel as the bus is matched against it (:func:`merge_tx`'s one
    rule): its characters' and breaks' starts, kinds and wires in order, the tolerance, and
    the matching's place. A bus decode with a TX channel decodes the TX first into one
    (no event made of it) and gives each bus event its origin as it is made: each event
    made once, where the TX channel's events were made too, and the recorder's bus events
    made again after a second pass over the bus (~10^4 events a fault-matrix row, issue 22)."""

    start: list[float] = field(default_factory=list)
    kind: list[EventKind] = field(default_factory=list)
    wire: list[int] = field(default_factory=list)
    tolerance: float = 0.0
    at: int = 0  # the first TX event neither matched nor passed
    matched: int = 0

    @classmethod
    def of(cls, events: list[Event], tolerance: float) -> Marks:
        marks = cls(tolerance=tolerance)
        for e in events:
            marks.add(e.kind, e.start, e.wire)
        return marks

    def add(self, kind: EventKind, start: float, wire: int) -> None:
        self.start.append(start)
        self.kind.append(kind)
        self.wire.append(wire)

    def origin(self, kind: EventKind, start: float, wire: int, other: str) -> str:
        """The origin of the next bus event (in bus order): :data:`RECORDER_ORIGIN` if the
        first TX event not yet matched or passed starts within the tolerance of it and is
        the same character or break (it is then matched), else ``other``; TX events that
        start more than the tolerance before it are passed."""
        starts, j, n, tol = self.start, self.at, len(self.start), self.tolerance
        while j < n and starts[j] < start - tol:
            j += 1
        if (
            j < n
            and abs(starts[j] - start) <= tol
            and self.kind[j] is kind
            and (kind is not EventKind.CHAR or self.wire[j] == wire)
        ):
            self.at, self.matched = j + 1, self.matched + 1
            return RECORDER_ORIGIN
        self.at = j
        return other

    def resumed(
        self, at: int, matched: int, kind: EventKind, start: float, wire: int, other: str
    ) -> tuple[str, int, int]:
        """:meth:`origin` from a loop that keeps the place (``at``) and the matches since it
        last told (``matched``) itself: the origin, the place after, no match untold."""
        self.at, self.matched = at, self.matched + matched
        return self.origin(kind, start, wire, other), self.at, 0

    def unseen(self) -> int:
        """How many TX events were not seen on the bus."""
        return len(self.start) - self.matched

    def again(self, bus: list[Event], tolerance: float) -> list[Event]:
        """``bus`` matched anew at ``tolerance`` (the bus's stamps were widened after it was
        matched: a rare glitch-filtered capture): :func:`merge_tx` of it."""
        self.tolerance, self.at, self.matched = tolerance, 0, 0
        origin, event = self.origin, full_event
        return [
            event(e.kind, origin(e.kind, e.start, e.wire, SENSOR_ORIGIN), e.start, e.end,
                  e.wire, e.text, e.uncertainty, e.duration_uncertainty)
            for e in bus
        ]  # fmt: skip


#: the last capture decoded, by file identity and settings: ``judge`` decodes a capture to
#: decide whether it can be replayed, and passive judging reads the same decode again (an
#: hour of 1 MHz samples is tens of seconds to decode; one decode is kept, not a history)
_LAST: tuple[tuple, CaptureDecode] | None = None


def decode_capture(
    path: str,
    *,
    channel: str | None = None,
    tx_channel: str | None = None,
    invert: bool | None = None,
    baud: float = 1200,
    framing: str = "7E1",
    edge_error: float = 0.0,
    glitch_filter: float | None = None,
    force: bool = False,
    keep: bool = True,
    columns: bool = False,
    compact: bool = False,
) -> CaptureDecode:
    """Decode ``channel`` of the capture at ``path`` (format detected by content).

    ``invert``: None detects the polarity, True/False forces line/UART levels. ``tx_channel``:
    the recorder's TX on a second channel; its characters on the bus become origin
    :data:`RECORDER_ORIGIN`, all others :data:`SENSOR_ORIGIN` (without it every event is origin
    :data:`BUS`). ``edge_error``: any extra edge position error (s) of the analyzer's input
    stage, added to the one-sample-period uncertainty. ``glitch_filter``: pulses shorter than
    this (s) are removed before decoding (None: 1/16 of a bit, :data:`DEFAULT_BITS`; 0: off).
    ``force``: judge a decode the plausibility check would refuse (the refusal is kept).
    ``keep`` False: the caller holds the decode for as long as it is needed (a recording
    loaded for judging), so the one kept is handed over, not copied, and no longer kept (an
    hour's capture: two lists of 357,000 events fewer held while it is judged).
    ``columns``: with ``tx_channel``, the events are kept as :attr:`CaptureDecode.columns`
    (no event made; ``events`` empty), for a caller that reads them so (a fault-matrix
    row's replay); such a decode is neither kept nor taken from the one kept. ``compact``:
    the events kept in a :class:`~conformance.event_store.CompactEvents` as they are made
    (a list where one cannot be: decoded again so), and of its problems the characters'
    alone (:attr:`CaptureDecode.characters_problems_only`); the one kept shares it (nothing
    appends to a decode's events once made), and one kept as a list is given as it is. A
    kept decode with its characters' problems alone is given to a compact caller alone
    (another decodes again: it may read every problem)."""
    global _LAST
    path = str(path)
    if glitch_filter is None:
        glitch_filter = DEFAULT_BITS / baud if baud > 0 else 0.0
    try:
        st = os.stat(path)
        key: tuple | None = (
            os.path.realpath(path), st.st_mtime_ns, st.st_size,
            channel, tx_channel, invert, baud, framing, edge_error, glitch_filter, force,
        )  # fmt: skip
    except OSError:
        key = None  # the decoding below says what is wrong with the file
    if columns:
        key = None
    # a decode that kept its characters' problems alone serves a compact caller alone
    if (
        key is not None
        and _LAST is not None
        and _LAST[0] == key
        and (compact or not _LAST[1].characters_problems_only)
    ):
        kept = _LAST[1]
        if not keep:
            _LAST = None
            return kept
        return replace(kept, events=_copied(kept.events, compact), notes=list(kept.notes))
    try:
        frame_format = Framing.parse(framing)
    except ValueError as exc:
        raise CaptureError(path, str(exc)) from None
    how = DecodeSettings(baud, frame_format, edge_error, glitch_filter, force, compact)
    try:
        out = _decode_capture(path, channel, tx_channel, invert, how, columns)
    except NotCompact:  # an event the store cannot hold (rare): the events as a list
        out = _decode_capture(path, channel, tx_channel, invert, replace(how, compact=False))
    give_back_freed_heap()  # the decoder's transients, whatever pages they were left on
    if key is not None and keep:
        _LAST = (key, replace(out, events=_copied(out.events, compact), notes=list(out.notes)))
    return out


def _copied(events: list[Event], compact: bool) -> list[Event]:
    """A decode's events for a second holder: a compact store shared where ``compact`` (a
    store is not appended to once its decode is made), else a list of them."""
    if compact and isinstance(events, CompactEvents):
        return events
    return list(events)


def _decode_capture(
    path: str,
    channel: str | None,
    tx_channel: str | None,
    invert: bool | None,
    how: DecodeSettings,
    columns: bool = False,
) -> CaptureDecode:
    baud = how.baud
    if baud <= 0:
        raise CaptureError(path, f"baud {baud} is not a bit rate")
    fmt = sniff(path)
    if fmt == "jsonl":
        raise CaptureError(path, "a transcript, not a capture: read it with read_transcript_jsonl")
    if tx_channel is not None and BULK:
        out, tx, unseen = _decode_merged(path, fmt, channel, tx_channel, invert, how, columns)
    else:
        out = _decode_channel(path, fmt, channel, invert, how)
        if tx_channel is None:
            return out
        if tx_channel == out.channel:
            raise CaptureError(path, f"the TX channel {tx_channel!r} is the bus channel itself")
        tx = _decode_channel(path, fmt, tx_channel, None, how)
        tolerance = 0.5 / baud + 2 * out.uncertainty_s
        out.events, unseen = merge_tx(out.events, tx.events, tolerance)
    out.tx_channel = tx.channel
    out.notes.append(f"TX channel {tx.channel!r}: {tx.polarity} polarity")
    if unseen:
        out.notes.append(f"{unseen} events on the TX channel were not seen on the bus")
    return out


def _decode_merged(
    path: str,
    fmt: str,
    channel: str | None,
    tx_channel: str,
    invert: bool | None,
    how: DecodeSettings,
    columns: bool = False,
) -> tuple[CaptureDecode, CaptureDecode, int]:
    """The bus decoded with the recorder's TX channel in bulk: the TX first, into
    :class:`Marks` (no event made of it), then the bus, each event made once with its
    origin (:data:`SENSOR_ORIGIN`, :data:`RECORDER_ORIGIN` where the TX matches it). What
    :func:`merge_tx` of the two decodes gives, and the same errors first: the bus's, that
    the TX channel is the bus's, then the TX's. Also how many TX events the bus lacks.
    ``columns``: the bus's events kept as columns (:class:`.WireColumns`)."""
    marks = Marks()
    try:
        tx: CaptureDecode | None = _decode_channel(path, fmt, tx_channel, None, how, into=marks)
        failed: CaptureError | None = None
    except CaptureError as exc:
        tx, failed = None, exc
    out = _decode_channel(
        path, fmt, channel, invert, how, SENSOR_ORIGIN, marks=marks, columns=columns
    )
    if tx_channel == out.channel:
        raise CaptureError(path, f"the TX channel {tx_channel!r} is the bus channel itself")
    if failed is not None or tx is None:
        raise failed or CaptureError(path, f"TX channel {tx_channel!r} not decoded")
    tolerance = 0.5 / how.baud + 2 * out.uncertainty_s
    if tolerance != marks.tolerance:  # the bus's stamps were widened (_filtered)
        if out.columns is not None:
            out.events, out.columns = out.columns.events(), None
        out.events = marks.again(out.events, tolerance)
    return out, tx, marks.unseen()
