"""Where the tool's own transmissions met the DUT's on the wire: collisions, found from stamps.

The tool listens before it talks
(:meth:`~conformance.tool_recorder.engine.ToolRecorder.clear_to_send`), but a DUT may start a
character the tool could not yet see (a real link delivers it up to its timing uncertainty
late), or a case may collide on purpose. Such a collision is never evidence
against the DUT: what it overlapped may be garbled by the tool's own spacing or characters.

A collision is recorded as a NOTE whose text starts with :data:`COLLISION_PREFIX`, not as a new
:class:`~conformance.transcript.EventKind`: every reader of ``transcript.jsonl`` (the view, the
wire judges, replay, capture export, and older versions of this tool) already passes notes by,
so old transcripts still load and new ones load in old readers; a new kind would slip into the
many places that treat "not a note" as "on the wire". The prefix makes the notes findable
(:func:`collision_notes`) and countable for the run's link description.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from operator import attrgetter

from ..protocol.timing import CHAR_TIME
from ..transcript import TOOL, Event, EventKind
from ..view.runs import runs

#: Start of the NOTE text that marks a collision.
COLLISION_PREFIX = "collision: "
#: Start of the NOTE text that marks a transmission that met DUT characters only within the
#: stamps' uncertainty: the engine read them as begun before its command ended, the stamps
#: cannot say whether they overlapped (no :data:`COLLISION_PREFIX` note for it).
MAYBE_PREFIX = "maybe collided: "
#: Start of the NOTE text that says the tool stopped holding for a DUT that kept talking.
HOLD_PREFIX = "listen before talk: "
#: Tool events closer than this belong to one transmission (a break, its marking, the
#: command's back-to-back characters), so one collision is counted once, not per character.
_SAME_TRANSMISSION = 10e-3
_START = attrgetter("start")  # the sort key of events by time


@dataclass(frozen=True)
class Collision:
    """One tool transmission (its break and/or characters) and the DUT characters it met."""

    tool: tuple[Event, ...]
    dut: tuple[Event, ...]

    @property
    def start(self) -> float:
        return self.tool[0].start

    def note_text(self) -> str:
        what = "break" if self.tool[0].kind is EventKind.BREAK else "command"
        first, last = self.dut[0], self.dut[-1]
        return (
            f"{COLLISION_PREFIX}the tool's {what} at t={self.start:.4f} s overlapped "
            f"{len(self.dut)} DUT characters (t={first.start:.4f}..{last.end:.4f} s); "
            "no DUT finding rests on them"
        )


def maybe_note_text(tool: list[Event], dut: list[Event], uncertainty: float) -> str:
    """The NOTE for a transmission whose stamps met ``dut`` only within ``uncertainty``
    (s): whatever answered it, or its silence, may not be the command's."""
    what = "break" if tool[0].kind is EventKind.BREAK else "command"
    first, last = dut[0], dut[-1]
    return (
        f"{MAYBE_PREFIX}the tool's {what} at t={tool[0].start:.4f} s met {len(dut)} DUT "
        f"characters (t={first.start:.4f}..{last.end:.4f} s) within the stamps' "
        f"±{uncertainty * 1e3:.2f} ms: the sensor may not have heard it whole; its reply or "
        "silence is not taken as its answer"
    )


def _overlap(a: Event, b: Event) -> bool:
    """Whether two wire events overlap by more than their stamps' uncertainty."""
    slack = max(a.uncertainty, b.uncertainty)
    return a.start + slack < b.end and b.start + slack < a.end


def collisions(events: Iterable[Event]) -> list[Collision]:
    """Every tool transmission that overlaps DUT characters, oldest first (pure: stamps only).

    A tool character read back as an echo is the tool's; characters of any other origin
    (``dut``, a named sim device, ``bus``) count as the DUT's. The engine asks this before
    every transmission (about a thousand times a run), nearly always to find none: the pass
    that splits the window also looks for any tool event and DUT character whose spans meet
    at all (with no slack: every overlap counted below is one of those), and without one
    there is nothing to group."""
    events = events if isinstance(events, list) else list(events)
    if _apart_in_order(events):
        return []
    wire = sorted([e for e in events if e.kind is not _NOTE], key=_START)
    tool: list[Event] = []
    dut: list[Event] = []
    tool_end = dut_end = float("-inf")  # the latest end of each side so far (by start)
    touching = False  # an event starts before the other side's latest end so far
    char = _CHAR
    for e in wire:
        if e.origin == TOOL:
            tool.append(e)
            touching = touching or e.start < dut_end
            if e.end > tool_end:
                tool_end = e.end
        elif e.kind is char:
            dut.append(e)
            touching = touching or e.start < tool_end
            if e.end > dut_end:
                dut_end = e.end
    if not touching:  # _overlap needs d.start < t.end and t.start < d.end (slack >= 0)
        return []
    found: list[Collision] = []
    k = 0
    for group in runs(tool, _SAME_TRANSMISSION):
        begin, end = group[0].start, max(e.end for e in group)
        while k < len(dut) and dut[k].end <= begin - CHAR_TIME:
            k += 1
        met = []
        for i in range(k, len(dut)):
            d = dut[i]
            if d.start >= end:
                break
            if any(_overlap(d, t) for t in group):
                met.append(d)
        if met:
            found.append(Collision(tuple(group), tuple(met)))
    return found


#: the kinds read per event, as module constants: a member read off the enum goes through its
#: metaclass's ``__getattr__`` hook on Python 3.11 (issue 22, matrix25: ~0.13 us a look)
_NOTE, _CHAR = EventKind.NOTE, EventKind.CHAR


def _apart_in_order(events: list[Event]) -> bool:
    """True when the wire events are already in start order (as a sim bus or a link's
    reader appends them) and no tool event meets a DUT character: the pass of
    :func:`collisions` before its grouping, without the copy and sort it needs for events
    out of order. False: not known (the full pass decides)."""
    return _read_apart(events, 0, _NOTHING) is not None


#: what :func:`_read_apart` has seen before its first event: the tool's latest end, the
#: DUT's latest character end, the latest start
_NOTHING = (float("-inf"), float("-inf"), float("-inf"))


def _read_apart(
    events: list[Event], first: int, seen: tuple[float, float, float]
) -> tuple[float, float, float] | None:
    """:func:`_apart_in_order`'s pass over ``events[first:]`` after events that left ``seen``
    (tool end, DUT end, last start): what it leaves, or None at the first event out of order
    or where a tool event and a DUT character meet. Each side's latest end before an event
    can only grow as more is read, so a pass may stop and go on later from what it left."""
    tool_end, dut_end, last = seen
    note, char = _NOTE, _CHAR
    for k in range(first, len(events)):
        e = events[k]
        kind = e.kind
        if kind is note:
            continue
        start = e.start
        if start < last:
            return None
        last = start
        if e.origin == TOOL:
            if start < dut_end:
                return None
            if e.end > tool_end:
                tool_end = e.end
        elif kind is char:
            if start < tool_end:
                return None
            if e.end > dut_end:
                dut_end = e.end
    return tool_end, dut_end, last


class ApartSoFar:
    """:func:`_apart_in_order` kept up as a transcript grows, read on from where the last look
    stopped: the engine asks before every transmission about the last 64 events and what
    came since, nearly always to find them apart. What it has read covers a window from
    ``base`` on; a window that starts there or later is a suffix of it, and a suffix of
    events in order, apart, is in order and apart (each side's latest end before an event
    can only be smaller in it). Where it cannot tell (a meeting read, a transcript not only
    appended to) it starts again at the window asked about."""

    def __init__(self) -> None:
        self._restart(0)
        self._last: Event | None = None  # the event at ``seen - 1`` when last looked

    def _restart(self, base: int) -> None:
        self.ok = True
        self.base = self.seen = base
        self.state = _NOTHING  # what _read_apart left at ``seen``

    def holds(self, events: list[Event], first: int) -> bool:
        """True when ``events[first:]`` are surely what :func:`_apart_in_order` says apart
        (so :func:`collisions` finds nothing in them); False: not known."""
        n = len(events)
        seen = self.seen
        if (
            not self.ok
            or first < self.base
            or n < seen
            or (seen > self.base and events[seen - 1] is not self._last)
        ):
            self._restart(first)
            seen = first
        state = _read_apart(events, seen, self.state)
        if state is None:
            self.ok = False
            return False
        self.state = state
        self.seen = n
        self._last = events[n - 1] if n else None
        return True


def collision_notes(events: Iterable[Event]) -> list[Event]:
    """The collision NOTEs of a transcript (old transcripts simply have none)."""
    return [e for e in events if e.kind is EventKind.NOTE and e.text.startswith(COLLISION_PREFIX)]
