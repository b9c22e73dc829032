"""A recorded sensor: the device under test of a saved sensor-role run, played back.

Judging a saved run again means asking the same questions and getting the recorded answers.
The tool runs its cases as it did (same stimuli, in the same order: cases ask for what they
need, and exploration is derandomized), on a simulated bus where the emulator is replaced by
this device. It follows the tool's transmissions through the recording; every recorded reply is
offered once all the tool's recorded transmissions before it have been heard again, shifted by
how late or early the tool is now against the recording (on the sim the shift is zero, so the
replayed transcript is the recorded one). The judges then see what they saw the first time.

When the tool sends something the recording does not have next, the replay has diverged (the
tool changed, or the recording is not of this kind of run): :class:`ReplayDiverged` stops the
run with that said, instead of inventing answers.
"""

from __future__ import annotations

from bisect import bisect_left
from collections.abc import Iterator
from itertools import compress, repeat
from operator import attrgetter, eq, is_
from typing import TYPE_CHECKING

from ..links.base import LinkError
from ..protocol.timing import BIT_TIME, CHAR_TIME
from ..sim.bus import SENSOR_BREAK, BreakFrame, Frame
from ..transcript import DUT, TOOL, Event, EventKind, escape

if TYPE_CHECKING:
    import numpy as np

    from ..capture.columns import WireColumns

#: a frame's start meaning "as soon as the line is free" (the bus starts a frame at the later
#: of its start and the end of what is on the line)
LINE_FREE = float("-inf")


#: a recording's wire events in the order the replay follows them (C-level: 10^4 a run)
_START_END = attrgetter("start", "end")
_ORIGIN, _KIND = attrgetter("origin"), attrgetter("kind")

#: the kinds the replay asks of every tool event, as module constants: an enum member read
#: off its class goes through the metaclass's ``__getattr__`` hook on Python 3.11 (issue 22,
#: matrix25: ~0.13 us a look, some 10^5 looks a fault-matrix row in all)
_CHAR, _BREAK = EventKind.CHAR, EventKind.BREAK

#: how every divergence's message starts (a report's stop reason names it)
DIVERGED = "replay diverged"


class ReplayDiverged(LinkError):
    """The tool's stimuli no longer follow the recording."""


class RecordingEnded(ReplayDiverged):
    """The recording stops before the run it records did (a capture cut short): what it
    holds is judged, the rest is left open (an incomplete run, exit 2, not a tool failure)."""


class RecordedSensor:
    """A :class:`~conformance.sim.bus.BusDevice` that answers from a recording."""

    name = "recording"

    def __init__(self, events: list[Event]) -> None:
        wire = [e for e in events if e.kind is not EventKind.NOTE]
        self._needs: list[int]
        self._touching: list[tuple[bool, bool]]
        found = _worked_out(wire)
        if found is not None:  # in order and no NaN: worked out over arrays
            tool, replies, self._needs, self._touching, columns = found
        else:
            wire.sort(key=_START_END)
            tool = [e for e in wire if e.origin == TOOL]
            replies = [e for e in wire if e.origin != TOOL and _played(e)]
            # how many tool events the recording has before each reply character starts
            # (the tool's starts never decrease: they are sorted with the rest)
            starts = [e.start for e in tool]
            self._needs = [bisect_left(starts, reply.start) for reply in replies]
            self._touching = _touching_each(tool, replies, self._needs)
            columns = _reply_columns(replies)
        self._tool: list[Event] | None = tool
        self._replies: list[Event] | None = replies
        #: which of the replies are the sensor's breaks (a harness's ``brk``, recorded)
        self._breaks = frozenset(
            compress(range(len(replies)), map(is_, map(_KIND, replies), repeat(EventKind.BREAK)))
        )
        kinds, wires, ends = [e.kind for e in tool], [e.wire for e in tool], [e.end for e in tool]
        self._start((kinds, wires, ends), columns)

    @classmethod
    def of_columns(cls, wire: WireColumns) -> RecordedSensor | None:
        """The recorded sensor of a decoded capture's events kept as columns (in decode
        order, no note among them), the reply characters never made events (issue 22:
        ~2*10^4 a fault-matrix row): what ``RecordedSensor(wire.events())`` is, when the
        columns are in its order with no NaN stamp (:func:`_worked_out`'s condition);
        else None (the caller makes the events)."""
        import numpy as np

        s, e = np.array(wire.start, np.float64), np.array(wire.end, np.float64)
        u, is_char, breaks = _made_columns(wire, len(s))
        is_tool = np.fromiter(map(eq, wire.origin, repeat(TOOL)), bool, len(s))
        with np.errstate(invalid="ignore"):  # inf - inf is NaN, and compares false
            found = _from_arrays(s, e, u, is_tool, is_char)
            if found is None:
                return None
            is_reply, needs, touching = found
            columns = _array_columns(s, e, is_reply, wire.wire)
            tool_mask = is_tool.tolist()
            tool_ends = e[is_tool].tolist()
        sensor = cls.__new__(cls)
        sensor._breaks = frozenset()
        if breaks:
            place = np.cumsum(is_reply) - 1  # each column's index among the replies
            sensor._breaks = frozenset(int(place[i]) for i in breaks if is_reply[i])
        sensor._needs, sensor._touching = needs, touching
        sensor._tool = sensor._replies = None
        sensor._made_of = (wire, tool_mask, is_reply.tolist())
        tool_columns = (
            _tool_kinds(wire, is_tool, len(tool_ends)),
            list(compress(wire.wire, tool_mask)),
            tool_ends,
        )
        sensor._start(tool_columns, columns)
        return sensor

    @property
    def tool(self) -> list[Event]:
        """The recording's tool events, in the replay's order (made from the columns when
        the sensor was built from them: the replay reads a divergence's alone)."""
        if self._tool is None:
            wire, keep, _ = self._made_of
            self._tool = wire.events_at(keep)
        return self._tool

    @property
    def replies(self) -> list[Event]:
        """The recording's reply characters, in the replay's order (made from the columns
        when the sensor was built from them: the replay itself reads only the columns)."""
        if self._replies is None:
            wire, _, keep = self._made_of
            self._replies = wire.events_at(keep)
        return self._replies

    def _start(
        self,
        tool: tuple[list[EventKind], list[int], list[float]],
        replies: tuple[list[float], list[int], list[float]],
    ) -> None:
        """The replay's state at its start; ``tool``: each tool event's kind, byte and end,
        ``replies``: each reply character's start, byte and length (end - start), all the
        replay reads of them."""
        self._tool_kind, self._tool_wire, self._tool_end = tool
        self._reply_start, self._reply_wire, self._reply_length = replies
        self.heard = 0  # tool events matched so far
        self.next_reply = 0
        self.offset = 0.0  # now minus recorded time, at the last matched tool event
        # the frame next_frame offered, by (next_reply, heard): what it depends on moves only
        # with those two (offset with heard), and the bus asks again at every step between
        self._offered: tuple[int, int, Frame | None] = (-1, -1, None)

    # -- what the tool does -------------------------------------------------------------------
    def on_break(self, start: float, end: float) -> None:
        self._match(_BREAK, 0, end, end - start)

    def on_char(self, wire: int, start: float, end: float) -> None:
        heard = self.heard
        # the usual case spelt out: the recording's next tool event is this character
        # (what :meth:`_match` and :func:`_same` decide; a fault-matrix row's replay hears
        # some 5,000 characters, issue 22: ~0.7% of its capture half)
        if (
            heard < len(self._tool_end)
            and self._tool_kind[heard] is _CHAR
            and self._tool_wire[heard] == wire
        ):
            self.heard = heard + 1
            self.offset = end - self._tool_end[heard]
            return
        self._match(_CHAR, wire, end)

    def _match(self, kind: EventKind, wire: int, end: float, length: float = 0.0) -> None:
        heard = self.heard
        if heard >= len(self._tool_end):
            raise RecordingEnded(
                f"the recording ends at {end:.3f} s, before its run did (cut short?): the "
                f"tool sent {_describe(kind, wire)} there and nothing more was recorded"
            )
        if not _same(self._tool_kind[heard], self._tool_wire[heard], kind, wire, length):
            expected = self.tool[heard]
            raise ReplayDiverged(
                f"{DIVERGED} at {end:.3f} s (recorded {expected.start:.3f} s): the tool "
                f"sent {_describe(kind, wire)}, the recording has "
                f"{_describe(expected.kind, expected.wire)}"
            )
        self.heard = heard + 1
        self.offset = end - self._tool_end[heard]

    # -- what the recording says the sensor did -------------------------------------------------
    def next_frame(self) -> Frame | None:
        at, heard, frame = self._offered
        if at == self.next_reply and heard == self.heard:
            return frame
        frame = self._next_frame()
        self._offered = (self.next_reply, self.heard, frame)
        return frame

    def _next_frame(self) -> Frame | None:
        k = self.next_reply
        if k >= len(self._reply_start):
            return None
        need = self._needs[k]
        if need > self.heard:
            return None  # its question has not been asked yet
        if self._touching[k][self.heard > need]:
            # back to back with what was on the line before it, within what the recording can
            # tell (a capture's edges sit on its sample grid): it goes the moment the line is
            # free, so it wins the line against the tool's next frame, as recorded (else the
            # order of frames that touch could turn on a few microseconds of quantization)
            start = LINE_FREE
        else:
            start = self._reply_start[k] + self.offset
        if k in self._breaks:  # the sensor's break, as long as it was recorded
            length = self._reply_length[k]
            return BreakFrame(start, 0, length, 0.0 if start == LINE_FREE else start + length)
        return Frame(start, self._reply_wire[k], self._reply_length[k])

    def pop_frame(self) -> Frame:
        frame = self.next_frame()
        assert frame is not None, "the bus pops only a frame that was offered"
        self.next_reply += 1
        return frame

    # -- sim.bus.PlansFrames: the replies due committed in one run ----------------------------
    def frames_ahead(self) -> Iterator[tuple[float, int, float]] | None:
        """``(start, wire, duration)`` of the replies :meth:`next_frame` would offer one
        after the other while the tool sends nothing: every reply whose question has been
        heard, in order (what one offers depends only on ``heard``, which only the tool's
        events move, and on its own index). None when none is due, as ``next_frame`` says."""
        k = self.next_reply
        if k >= len(self._reply_start) or self._needs[k] > self.heard or k in self._breaks:
            return None
        return self._due(k, self.heard, self.offset)

    def _due(self, k: int, heard: int, offset: float) -> Iterator[tuple[float, int, float]]:
        needs, touching = self._needs, self._touching
        starts, wires, lengths = self._reply_start, self._reply_wire, self._reply_length
        count = len(starts)
        breaks = self._breaks
        while k < count and needs[k] <= heard and k not in breaks:
            start = LINE_FREE if touching[k][heard > needs[k]] else starts[k] + offset
            yield start, wires[k], lengths[k]
            k += 1

    def pop_frames(self, count: int) -> None:
        """Commit the first ``count`` of :meth:`frames_ahead`, as ``count`` :meth:`pop_frame`
        calls would (the offer kept for the bus is keyed by the reply index: it moves on)."""
        self.next_reply += count


def _touching_each(
    tool: list[Event], replies: list[Event], needs: list[int]
) -> list[tuple[bool, bool]]:
    """Per reply ``k``: whether it starts where the recorded event that ended last before it
    ended (within both stamps' uncertainty), when it is offered with the tool's matched
    events exactly those before it (``needs[k]``), and with the tool gone on past its start.
    That event is the tool's last matched one or the previous reply character, whichever
    ends later (the tool's on a tie); the tool's counts only if it started before the reply,
    which the first case's does and the second's does not: so the two cases are all there
    is, worked out once, in one pass, instead of at every step of the bus."""
    out: list[tuple[bool, bool]] = []
    append = out.append
    last: Event | None = None
    for reply, need in zip(replies, needs, strict=True):
        start, u = reply.start, reply.uncertainty
        previous = last if last is not None and last.start < start else None
        before = tool[need - 1] if need else None
        if before is None or (previous is not None and previous.end > before.end):
            before = previous
        append(
            (
                before is not None and abs(start - before.end) <= u + before.uncertainty,
                previous is not None and abs(start - previous.end) <= u + previous.uncertainty,
            )
        )
        last = reply
    return out


def _made_columns(wire: WireColumns, n: int) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """Each of the ``n`` columns' uncertainty and whether the replay plays it as a character,
    and the sensor's breaks among them: a certified character has the columns' common
    uncertainty and is one, so only the decoder's own events (``made``, a few hundred of a
    row's ~2*10^4) are looked at (issue 22, matrix24: the uncertainty and kind of every
    column listed and each read into an array was ~4 ms of a fault-matrix row). A break
    (a decoder makes each one) is played where it is the sensor's (:func:`_played`)."""
    import numpy as np

    u = np.full(n, wire.uncertainty, np.float64)
    is_char = np.ones(n, bool)
    breaks: list[int] = []
    for i, m in wire.made.items():
        u[i] = m.uncertainty
        if m.kind is not EventKind.CHAR:
            played = _played(m)
            is_char[i] = played
            if played:
                breaks.append(i)
    return u, is_char, breaks


def _tool_kinds(wire: WireColumns, is_tool: np.ndarray, count: int) -> list[EventKind]:
    """The kinds of the ``count`` tool events among the columns (``is_tool``), in order:
    ``compress(wire.kinds(), is_tool)`` without every column's kind listed first (a
    certified character's is CHAR; only the decoder's own events, a few hundred of a
    fault-matrix row's ~2*10^4 columns, have another: issue 22, replay27)."""
    import numpy as np

    kinds = [EventKind.CHAR] * count
    if wire.made:
        place = np.cumsum(is_tool) - 1  # each column's index among the tool's
        for i, m in wire.made.items():
            if is_tool[i]:
                kinds[place[i]] = m.kind
    return kinds


def _column(events: list[Event], name: str) -> np.ndarray:
    import numpy as np

    return np.fromiter(map(attrgetter(name), events), np.float64, len(events))


def _reply_columns(replies: list[Event]) -> tuple[list[float], list[int], list[float]]:
    """Each reply character's start, byte and length (end - start)."""
    return [r.start for r in replies], [r.wire for r in replies], [r.end - r.start for r in replies]


def _array_columns(
    s: np.ndarray, e: np.ndarray, is_reply: np.ndarray, wire: list[int]
) -> tuple[list[float], list[int], list[float]]:
    """:func:`_reply_columns` from the recording's columns (the same floats: float64
    subtraction is Python's)."""
    rs, re = s[is_reply], e[is_reply]
    return rs.tolist(), list(compress(wire, is_reply.tolist())), (re - rs).tolist()


#: what :func:`_worked_out` gives: the tool's events, the reply characters, the needs, the
#: back-to-back flags and the reply columns (:func:`_reply_columns`)
WorkedOut = tuple[
    list[Event], list[Event], list[int], list[tuple[bool, bool]],
    tuple[list[float], list[int], list[float]],
]  # fmt: skip


def _worked_out(wire: list[Event]) -> WorkedOut | None:
    """The tool's events, the reply characters, the replay's ``_needs`` (``bisect_left`` of
    each reply's start among the tool's starts) and :func:`_touching_each`, over arrays (the
    same comparisons and sums of the same floats), when ``wire`` is already in the replay's
    order (by start, then end: sorting would leave it as it is) with no NaN stamp (whose
    comparisons sorting and the arrays would read apart); else None. A decoded capture's
    events come in order (one channel's frames follow each other), and building its
    replay event by event was ~16 ms of a fault-matrix row (issue 22). numpy is imported
    here: a sensor run loads this module (the plugin names its errors), not numpy."""
    import numpy as np

    with np.errstate(invalid="ignore"):  # inf - inf is NaN, and compares false
        return _in_arrays(wire, *(_column(wire, k) for k in ("start", "end", "uncertainty")))


def _in_arrays(wire: list[Event], s: np.ndarray, e: np.ndarray, u: np.ndarray) -> WorkedOut | None:
    """:func:`_worked_out` given the events' starts, ends and uncertainties."""
    import numpy as np

    n = len(wire)
    is_tool = np.fromiter(map(eq, map(_ORIGIN, wire), repeat(TOOL)), bool, n)
    is_char = np.fromiter(map(is_, map(_KIND, wire), repeat(EventKind.CHAR)), bool, n)
    for i in np.flatnonzero(~(is_tool | is_char)).tolist():
        is_char[i] = _played(wire[i])  # a sensor's break is played as its replies are
    found = _from_arrays(s, e, u, is_tool, is_char)
    if found is None:
        return None
    is_reply, needs, touching = found
    tool = list(compress(wire, is_tool.tolist()))
    replies = list(compress(wire, is_reply.tolist()))
    wires = [r.wire for r in replies]
    rs, re = s[is_reply], e[is_reply]
    return tool, replies, needs, touching, (rs.tolist(), wires, (re - rs).tolist())


def _from_arrays(
    s: np.ndarray, e: np.ndarray, u: np.ndarray, is_tool: np.ndarray, is_char: np.ndarray
) -> tuple[np.ndarray, list[int], list[tuple[bool, bool]]] | None:
    """The reply characters (a mask), the needs and the back-to-back flags of events in
    the replay's order given as columns (starts, ends, uncertainties, which are the
    tool's, which are characters); None when they are not in that order or a stamp is
    NaN (:func:`_worked_out`)."""
    import numpy as np

    if np.isnan(s).any() or np.isnan(e).any():
        return None
    if not ((s[1:] > s[:-1]) | ((s[1:] == s[:-1]) & (e[1:] >= e[:-1]))).all():
        return None
    is_reply = ~is_tool & is_char
    if not is_reply.any():
        return is_reply, [], []
    ts, te, tu = s[is_tool], e[is_tool], u[is_tool]
    rs, re, ru = s[is_reply], e[is_reply], u[is_reply]
    need = np.searchsorted(ts, rs, "left")
    # the tool's last matched event before each reply (need - 1), padded for need == 0
    has_tool = need > 0
    te_before = np.concatenate(([0.0], te))[need]
    tu_before = np.concatenate(([0.0], tu))[need]
    # the previous reply character, if it started before this one
    has_prev = np.zeros(rs.size, dtype=bool)
    has_prev[1:] = rs[:-1] < rs[1:]
    re_prev = np.concatenate(([0.0], re[:-1]))
    ru_prev = np.concatenate(([0.0], ru[:-1]))
    use_prev = has_prev & (~has_tool | (re_prev > te_before))
    before_end = np.where(use_prev, re_prev, te_before)
    before_u = np.where(use_prev, ru_prev, tu_before)
    first = (use_prev | has_tool) & (np.abs(rs - before_end) <= ru + before_u)
    second = has_prev & (np.abs(rs - re_prev) <= ru + ru_prev)
    return is_reply, need.tolist(), _pairs(first, second)


#: the four back-to-back flag pairs, shared by every reply (:func:`_pairs`)
_PAIRS = ((False, False), (False, True), (True, False), (True, True))


def _pairs(first: np.ndarray, second: np.ndarray) -> list[tuple[bool, bool]]:
    """``list(zip(first, second))`` as Python bools, each pair one of :data:`_PAIRS`
    rather than a tuple of its own: a decoded capture has ~2*10^4 replies (issue 22, replay27:
    making and later freeing a tuple each was ~1% of a fault-matrix row's capture half)."""
    import numpy as np

    return [_PAIRS[i] for i in (first.astype(np.intp) * 2 + second).tolist()]


def _played(e: Event) -> bool:
    """Whether the sensor's event ``e`` is one the replay plays: a character, or its break
    (:data:`~conformance.sim.bus.SENSOR_BREAK`, a harness's ``brk`` or an emulator's
    ``break-before-reply``; in a decoded capture, spacing on the bus its recorder's TX
    channel does not show, origin :data:`~conformance.transcript.DUT`, whatever its length
    made its text: a capture of such a run replayed without it PASSed R-7.0-09 on a reply
    20.5 ms after the command that the live run FAILed at 0.00 ms)."""
    return e.kind is EventKind.CHAR or (
        e.kind is EventKind.BREAK and (e.text == SENSOR_BREAK or e.origin == DUT)
    )


def same_action(recorded: Event, kind: EventKind, wire: int, length: float) -> bool:
    """Whether the tool's break or character is the recorded one. A spacing shorter than a
    frame (a probe below the break threshold) is, on a captured wire, indistinguishable from
    a character whose low bits are the spacing: a capture decoder reports it as one."""
    return _same(recorded.kind, recorded.wire, kind, wire, length)


def _same(
    recorded_kind: EventKind, recorded_wire: int, kind: EventKind, wire: int, length: float
) -> bool:
    """:func:`same_action` given the recorded event's kind and byte."""
    if kind is _CHAR:
        return recorded_kind is _CHAR and recorded_wire == wire
    if recorded_kind is _BREAK:
        return True
    if length >= CHAR_TIME:
        return False
    low = recorded_wire & 0xFF
    spacing_bits = 1 + ((low & -low).bit_length() - 1 if low else 8)  # start bit + zeros
    return abs(spacing_bits - length / BIT_TIME) <= 1.0


def _describe(kind: EventKind, wire: int) -> str:
    if kind is EventKind.BREAK:
        return "a break"
    return f"'{escape(chr(wire & 0x7F))}'"
