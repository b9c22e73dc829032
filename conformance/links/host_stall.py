"""The tool's own host stalling, as the link measured it and the transcript says it.

When the tool's process is held up (a loaded host, a paused process, a USB stall of the
host's own making) every thread of it stops together: the link's reader thread comes back
from a read with a timeout of ``READ_POLL`` much later than that timeout allows, and what
arrived meanwhile is delivered at once. The engine's read of a reply then ends at the idle
window although the device never idled, and the late burst's stamps show a gap the wire
never had (truth25: 6 FAIL + 1 WARN for a clean emulator under 80-200 ms pauses).

The link (I/O) writes what it measured as a NOTE (:func:`note_text`); whoever judges a
stimulus reads the stalls back from the transcript's events alone (:func:`stalls`), so a
saved transcript tells the same story as the live run.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from operator import attrgetter

from ..transcript import Event, EventKind

#: the start of the NOTE a link leaves where its reader thread came back late
HOST_STALL_NOTE = "the tool's host stalled "
#: below this (s) a late reader is ordinary scheduling, covered by the stamps' measured worth
#: (:mod:`.meter`); above it a read may have been cut by the stall and its stamps moved
STALL_MIN = 0.03

_MS = re.compile(re.escape(HOST_STALL_NOTE) + r"(\d+(?:\.\d+)?) ms")
_NOTE = EventKind.NOTE
_KIND = attrgetter("kind")


def note_text(stall: float) -> str:
    """The NOTE for a stall of ``stall`` s (its length first, so :func:`stalls` reads it)."""
    return (
        f"{HOST_STALL_NOTE}{stall * 1e3:.1f} ms (the link's reader thread came back that much "
        "later than its read's timeout): reads and stamps around it are the host's, not the DUT's"
    )


#: how far (s) before a stall's measured length a read it held up may have begun: the
#: reader's own poll and the engine's idle window, after which a held-up read ends cut
REACH = 0.05
#: how long (s) after a stall's NOTE what it held back may still be arriving, and what the
#: tool did meanwhile was decided without it (truth30): the reader's first turn after the
#: pause may come back empty, the port's own thread (RFC 2217's) not yet having queued the
#: bytes; the engine, resumed with it, saw a quiet line, sent its retry's break 0.4 ms
#: after the NOTE into the rest of the reply, and the reply to the retry read as the text
#: the break talked over, its tail '5<CR><LF>' as a line of its own: R-4.3-01 FAILed a clean
#: emulator (base-s67, the tool paused 80-200 ms every 0.3-0.9 s)
AFTER = 0.03
#: how many events before a stimulus :func:`stalls_since` looks at for such a NOTE
LOOK_BACK = 8


@dataclass(frozen=True)
class Stall:
    """A host stall read back from its NOTE: the reads ``start``..``end`` (s) may have been
    held up by it (its measured length, reached back by :data:`REACH`, and on by
    :data:`AFTER` past the NOTE)."""

    start: float
    end: float
    ms: float

    def overlaps(self, start: float, end: float) -> bool:
        return start <= self.end and end >= self.start

    def why(self) -> str:
        return f"the tool's host stalled {self.ms:.0f} ms during this read"


def stalls(events: Iterable[Event]) -> list[Stall]:
    """Every host stall the NOTEs among ``events`` report, in their order."""
    found = []
    for event in events:
        if event.kind is _NOTE and event.text.startswith(HOST_STALL_NOTE):
            got = _MS.match(event.text)
            if got is not None:
                ms = float(got.group(1))
                found.append(Stall(event.start - ms / 1e3 - REACH, event.start + AFTER, ms))
    return found


def stalls_since(events: list[Event], first: int) -> list[Stall]:
    """:func:`stalls` of ``events[first:]``: the stalls that may have held up a stimulus
    begun at event ``first`` (each is noted after the burst it held back, so a stall
    overlapping it is noted after it began; or just before it: a stimulus begun within
    :data:`AFTER` of a stall's NOTE may have been sent into what it still held back, so the
    few events before ``first`` are looked at too). Looked for in C first: most stimuli
    hold no NOTE at all, and a run makes a thousand of them."""
    if first and first < len(events):
        began = events[first].start - AFTER
        for i in range(max(0, first - LOOK_BACK), first):
            if events[i].kind is _NOTE and events[i].start >= began:
                first = i  # the earliest such NOTE
                break
    new = events[first:] if first else events
    if _NOTE not in map(_KIND, new):
        return []
    return stalls(new)


def settled_at(events: Sequence[Event]) -> float | None:
    """When what the latest stall among the last :data:`LOOK_BACK` of ``events`` held back
    has surely arrived (its NOTE and :data:`AFTER`), or None where none is among them: the
    tool's next transmission waits for it, not to talk into a reply the stall cut whose
    rest is still on its way (truth30)."""
    for event in reversed(events[-LOOK_BACK:]):
        if event.kind is _NOTE and event.text.startswith(HOST_STALL_NOTE):
            return event.start + AFTER
    return None


def noted_since_activity(events: Sequence[Event]) -> bool:
    """Whether the NOTE of a host stall follows the line's last activity (a character or a
    break) among ``events``: that activity's stamp may be the late burst's that delivered
    it (the link notes the stall after the burst), so the marking since it may be longer
    than the stamps say (truth30). Only the NOTEs after it are looked at: a few at most."""
    for event in reversed(events):
        if event.kind is not _NOTE:
            return False
        if event.text.startswith(HOST_STALL_NOTE):
            return True
    return False


def stalled_over(found: Iterable[Stall], start: float, end: float) -> Stall | None:
    """The first of ``found`` that may have held up a read between ``start`` and ``end``."""
    for stall in found:
        if stall.overlaps(start, end):
            return stall
    return None
